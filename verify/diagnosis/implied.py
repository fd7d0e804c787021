"""What a hand model's M, C·q̇ and H fix of the robot's inertial parameters: the regressor fit.

The equations of motion of a kinematic tree are linear in each body's ten dynamic
parameters (Pinocchio's order, about the body's joint frame origin)

    π_b = [m, m·c_x, m·c_y, m·c_z, I_xx, I_xy, I_yy, I_xz, I_yz, I_zz],   I = I_c + m(|c|²𝟙 − ccᵀ),

τ_q(q, v, a) = Y(q, v, a)·π (``pin.computeJointTorqueRegressor``).  In the hand model's
coordinates θ (``CoordinateMap``: q = T(θ − θ0), v = Tθ̇, τ_θ = Tᵀτ_q) the rows are, at each
state of the batch,

    M e_j = Tᵀ Y₀(q, 0, T e_j) π     (gravity off; one row per entry M[i, j])
    C·q̇   = Tᵀ Y₀(q, v, 0) π        (gravity off)
    H     = Tᵀ Y(q, 0, 0) π         (gravity on),

stacked against the hand model's M, C·q̇ (friction excluded) and H at the same states.

Weights and the rounding level
------------------------------
Each row is divided by the scale its check judges it against (``pendverify.checks.quantities``:
M̃ = diag(weights) M diag(weights) with weights = 1/√S for M, max weights·g_scale for H, (rate +
damping rate)·Σ|q̇/weights| for C·q̇) and by the state's rounding growth f = (1 + |θ|max)·c_T +
(A − 1) (``pendverify.checks.catalogue``), so that a correct model's row differs from the URDF's
by at most K·ε, K = 16 the largest constant of the checks of these quantities (crba 8, rnea 16,
gravity 16).  Rows with a zero scale carry nothing (C·q̇ at rest, H without gravity) and are
left out.  Over R rows the rounding is then ‖e‖₂ ≤ √R·K·ε = ``tolerance``, and a least squares
residual is the data projected on the complement of the regressor's range, which does not
enlarge it: a fit whose residual is within ``tolerance`` reproduces the hand model's equations
to rounding on every sampled state.  Householder QR adds a backward error of order ε·‖b‖ ≤ ε·√R
(each row is at most one after the scaling), well inside it.

Identifiable combinations
-------------------------
Columns are scaled to unit norm; a column of the (row-compressed) regressor whose distance
from the span of the columns chosen before it is within √R·K·ε (the most rounding of K·ε per
row can move a unit column) is *dependent*: its parameter only enters through the chosen
ones.  Columns are taken link by link from the root, each link's inertia, then first moment,
then mass, so that a dependent parameter is folded into its parent's: a double pendulum's
link-2 mass enters as I_xx(link1) + l1²·m(link2) and m·c_y(link1) + l1·m(link2).  The chosen
columns' combinations (``Combination``) are what the equations fix; the fit solves for them
(``ImpliedParameters``).  A combination's rounding is ‖(R_b⁻¹)_k‖·√R·K·ε (R_b the chosen
columns' triangular factor).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import pinocchio as pin

from pendverify.analytic.interface import BiasOnlyModel
from pendverify.checks.scaling import mv, total
from pendverify.checks.trust import EPS
from pendverify.display import REPR_LIMIT, html_table, listed, shortened

K = 16  # the largest constant of the checks whose quantities the rows are (crba 8, rnea 16, gravity 16)
PARAMETERS = ("m", "m·c_x", "m·c_y", "m·c_z", "I_xx", "I_xy", "I_yy", "I_xz", "I_yz", "I_zz")
UNITS = ("kg",) + ("kg·m",) * 3 + ("kg·m²",) * 6
#: each link's columns in the order they are chosen: inertia, first moment, mass
CHOICE_ORDER = (4, 5, 6, 7, 8, 9, 1, 2, 3, 0)
AXES = "xyz"
#: the inertia components in Pinocchio's order, and their entries of the 3×3 matrix
COMPONENTS = (("xx", 0, 0), ("xy", 0, 1), ("yy", 1, 1), ("xz", 0, 2), ("yz", 1, 2), ("zz", 2, 2))
GAUSS_NEWTON_STEPS = 30
QUANTITIES = ("M", "C·q̇", "H")  # the rows' quantities, in their order


# --- the stacked rows --------------------------------------------------------------------------
def link_names(model: pin.Model) -> list[str]:
    """The URDF link each joint moves (its first body frame), in joint order."""
    names = []
    for j in range(1, model.njoints):
        bodies = [f.name for f in model.frames if f.type == pin.FrameType.BODY and f.parentJoint == j]
        names.append(bodies[0] if bodies else model.names[j])
    return names


def urdf_parameters(model: pin.Model) -> np.ndarray:
    """π_urdf: every joint's body, ten dynamic parameters each (``Inertia.toDynamicParameters``)."""
    return np.concatenate([model.inertias[j].toDynamicParameters() for j in range(1, model.njoints)])


def _regressors(system, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(N, n + 2, n, P): Tᵀ·Y at each state for H, for M's columns 1..n and for C·q̇ (module docstring)."""
    pm, data = system.model, system.data
    m0, d0 = system.model_without_gravity, system.data_without_gravity
    T = system.cmap.T
    N, n = len(q), pm.nv
    regressor = pin.computeJointTorqueRegressor
    zero = np.zeros(n)
    columns = [np.ascontiguousarray(T[:, j]) for j in range(n)]
    out = np.empty((N, n + 2, n, 10 * (pm.njoints - 1)))
    for i in range(N):
        out[i, 0] = regressor(pm, data, q[i], zero, zero)
        for j in range(n):
            out[i, 1 + j] = regressor(m0, d0, q[i], zero, columns[j])
        out[i, n + 1] = regressor(m0, d0, q[i], v[i], zero)
    return np.einsum("ba,ikbp->ikap", T, out)


@dataclass(frozen=True)
class Rows:
    """The weighted rows: Y (R, P) and the hand model's b (R,), each row's entry label."""

    Y: np.ndarray
    b: np.ndarray
    labels: tuple[str, ...]

    @property
    def tolerance(self) -> float:
        """√R·K·ε: the most rounding leaves in a residual of these rows (module docstring)."""
        return float(np.sqrt(len(self.b)) * K * EPS)


def _hand_coriolis_force(batch) -> np.ndarray:
    """The hand model's C·q̇ as its bias reads it (``pendverify.checks.closed_forms``)."""
    forms = batch.forms
    if isinstance(batch.model, BiasOnlyModel):
        return forms.value("coriolis_force")
    return mv(forms.value("coriolis_matrix"), batch.V)


def stacked_rows(batch) -> Rows:
    """The hand model's M, C·q̇, H and the regressor at ``batch``'s states, weighted (module docstring)."""
    t, pinb = batch.terms, batch.pin
    n = batch.model.nv
    Y = _regressors(batch.system, pinb.q, pinb.v)
    weights = np.broadcast_to(t.weights, (len(batch), n))
    growth = (1.0 + batch.angle) * batch.c_T + (batch.lever - 1.0)
    g_scale = np.max(weights * t.g_scale, axis=-1)
    c_scale = (t.rate + t.d_rate) * total(np.abs(batch.V / weights))
    # per state: M's n² rows (row i, column j), then C·q̇'s n, then H's n
    Y_rows = np.concatenate(
        [np.swapaxes(Y[:, 1 : n + 1], 1, 2).reshape(len(batch), n * n, -1), Y[:, n + 1], Y[:, 0]], 1
    )
    b_rows = np.concatenate([t.M_hand.reshape(len(batch), n * n), _hand_coriolis_force(batch), t.H_hand], 1)
    weight_M = (weights[:, :, None] * weights[:, None, :]).reshape(len(batch), n * n)
    with np.errstate(divide="ignore", invalid="ignore"):
        weight = (
            np.concatenate([weight_M, weights / c_scale[:, None], weights / g_scale[:, None]], 1)
            / growth[:, None]
        )
    labels = [f"M[{i + 1},{j + 1}]" for i in range(n) for j in range(n)]
    labels += [f"C·q̇[{i + 1}]" for i in range(n)] + [f"H[{i + 1}]" for i in range(n)]
    keep = np.isfinite(weight) & (weight > 0) & np.isfinite(b_rows) & np.all(np.isfinite(Y_rows), axis=-1)
    return Rows(
        Y_rows[keep] * weight[keep][:, None],
        b_rows[keep] * weight[keep],
        tuple(np.broadcast_to(np.array(labels), keep.shape)[keep]),
    )


# --- the fit over the identifiable combinations ------------------------------------------------
@dataclass(frozen=True)
class Combination:
    """One identifiable combination: Σ coefficient·parameter over (link, parameter), its values."""

    terms: tuple[tuple[float, str, str], ...]  # (coefficient, link, parameter), the chosen one first
    unit: str
    model_value: float
    urdf_value: float
    rounding: float

    @property
    def name(self) -> str:
        (_, link, parameter), *rest = self.terms
        text = f"{parameter}({link})"
        for coefficient, link, parameter in rest:
            sign = "−" if coefficient < 0 else "+"
            size = f"{abs(coefficient):.6g}"
            text += f" {sign} {'' if size == '1' else size + '·'}{parameter}({link})"
        return text

    @property
    def differs(self) -> bool:
        return abs(self.model_value - self.urdf_value) > self.rounding

    def __repr__(self) -> str:
        values = f"model {self.model_value:.6g}, URDF {self.urdf_value:.6g} [{self.unit}]"
        return f"<Combination {shortened(self.name, REPR_LIMIT - len(values) - 20)}: {values}>"

    def _repr_html_(self) -> str:
        row = (f"{self.model_value:.6g}", f"{self.urdf_value:.6g}", self.unit, f"{self.rounding:.2g}")
        return html_table(("model", "URDF", "unit", "rounding"), [row], self.name, [self.differs])


@dataclass
class ImpliedParameters:
    """What the hand model's M, C·q̇, H fix of the URDF tree's inertial parameters.

    ``exact``: some parameters reproduce the equations to rounding (``residual`` ≤
    ``tolerance``, both ‖·‖₂ of the weighted rows); ``combinations`` the identifiable
    combinations with the model's and the URDF's values; ``phi`` maps a parameter
    vector π (P,) to its image in the range's coordinates, where ``target`` is the hand
    model's data less the URDF's (so ‖phi·Δπ − target‖² + residual² is the squared
    residual of π_urdf + Δπ).
    """

    links: list[str]
    urdf: np.ndarray
    rows: Rows
    phi: np.ndarray
    target: np.ndarray
    residual: float
    urdf_residual: float
    combinations: list[Combination]
    rank_tolerance: float
    norms: np.ndarray  # each parameter's column norm in the weighted rows

    def __repr__(self) -> str:
        differ = [c.name for c in self.combinations if c.differs]
        head = (
            f"<ImpliedParameters {'exact' if self.exact else 'not exact'}, the URDF's own "
            f"{'agree' if self.agrees else 'differ'}: {len(self.combinations)} combinations, "
            f"{len(differ)} differ"
        )
        if differ:
            head += f" ({listed(differ, 120)})"
        if not self.exact:
            head += f"; unexplained: {listed(self.unexplained, 60)}"
        return f"{head}>"

    def _repr_html_(self) -> str:
        """The identifiable combinations, model against URDF, those that differ in red."""
        verdict = (
            "some inertial parameters reproduce the hand model"
            if self.exact
            else (
                f"no inertial parameters reproduce the hand model: unexplained {', '.join(self.unexplained)}"
            )
        )
        caption = f"{verdict}; the URDF's own {'agree' if self.agrees else 'differ'}"
        rows = [
            (c.name, c.unit, f"{c.model_value:.6g}", f"{c.urdf_value:.6g}", f"{c.rounding:.2g}",
             "differs" if c.differs else "agrees")
            for c in self.combinations
        ]  # fmt: skip
        header = ("combination", "unit", "model", "URDF", "rounding", "")
        return html_table(header, rows, caption, [c.differs for c in self.combinations])

    @property
    def tolerance(self) -> float:
        return self.rows.tolerance

    @property
    def exact(self) -> bool:
        return self.residual <= self.tolerance

    @property
    def agrees(self) -> bool:
        """The URDF's own parameters reproduce the hand model's rows to rounding."""
        return self.urdf_residual <= self.tolerance

    @cached_property
    def _unit_columns(self) -> np.ndarray:
        return self.rows.Y[:, self.norms > 0] / self.norms[self.norms > 0]

    def fit_residual(self, keep: np.ndarray) -> float:
        """‖b − Y·π‖₂ of the best π over the rows ``keep`` (a boolean mask)."""
        Y, b = self._unit_columns[keep], self.rows.b[keep]
        x, *_ = np.linalg.lstsq(Y, b, rcond=None)
        return float(np.linalg.norm(b - Y @ x))

    def fits(self, keep: np.ndarray) -> bool:
        """Some parameters reproduce the rows ``keep`` to rounding (√R'·K·ε over their R' rows)."""
        return self.fit_residual(keep) <= np.sqrt(np.count_nonzero(keep)) * K * EPS

    @cached_property
    def quantities(self) -> list[str]:
        """The quantities the rows hold (``M``, ``C·q̇``, ``H``), in that order."""
        present = {label.split("[")[0] for label in self.rows.labels}
        return [q for q in QUANTITIES if q in present]

    def rows_of(self, *quantities: str) -> np.ndarray:
        return np.array([label.split("[")[0] in quantities for label in self.rows.labels])

    @cached_property
    def unexplained(self) -> list[str]:
        """An irreducible set of entries whose rows, left out, let parameters reproduce the rest.

        Entries (M[i,j] with M[j,i], C·q̇[i], H[i]) are put back one by one and stay out only
        when the rows kept with them no longer ``fits``: no single entry of the set can be put
        back.  The set starts from the entries that differ from the URDF's own (left out, the
        rest is the URDF's, which fits), the worst first put back last, so that the entries named
        are ones that differ; when every entry differs, from all of them, the best-fitted first.
        """
        labels = np.array([_entry(label) for label in self.rows.labels])
        Y, b = self._unit_columns, self.rows.b
        scaled = self.urdf[self.norms > 0] * self.norms[self.norms > 0]
        off = np.abs(b - Y @ scaled)  # each row's difference from the URDF's own parameters
        differing = [e for e in dict.fromkeys(labels) if np.max(off[labels == e]) > K * EPS]
        if len(differing) == len(set(labels)):
            x, *_ = np.linalg.lstsq(Y, b, rcond=None)
            r = np.abs(b - Y @ x)
            differing = sorted(differing, key=lambda e: float(np.max(r[labels == e])))
        else:
            differing = sorted(differing, key=lambda e: float(np.max(off[labels == e])))
        out = set(differing)
        for entry in differing:
            if self.fits(~np.isin(labels, list(out - {entry}))):
                out.discard(entry)
        return [e for e in dict.fromkeys(labels) if e in out]


def _entry(label: str) -> str:
    """A row's entry: M[j,i] below the diagonal is M[i,j]'s."""
    if label.startswith("M["):
        i, j = sorted(int(k) for k in label[2:-1].split(","))
        return f"M[{i},{j}]"
    return label


def _chosen_columns(R0: np.ndarray, order: list[int], tol: float) -> tuple[list[int], list[int]]:
    """The columns of R0 (unit columns) independent of those before them in ``order``, and the rest."""
    chosen: list[int] = []
    for k in order:
        column = R0[:, k]
        if chosen:
            coefficients, *_ = np.linalg.lstsq(R0[:, chosen], column, rcond=None)
            column = column - R0[:, chosen] @ coefficients
        if np.linalg.norm(column) > tol:
            chosen.append(k)
    return chosen, [k for k in order if k not in chosen]


def implied_parameters(batch) -> ImpliedParameters:
    """The identifiable combinations of inertial parameters the hand model's M, C·q̇, H imply."""
    pm = batch.system.model
    rows = stacked_rows(batch)
    links, urdf = link_names(pm), urdf_parameters(pm)
    Y, P = rows.Y, rows.Y.shape[1]
    d = rows.b - Y @ urdf
    norms = np.linalg.norm(Y, axis=0)
    nonzero = [p for p in range(P) if norms[p] > 0]
    order = [10 * j + k for j in range(len(links)) for k in CHOICE_ORDER if 10 * j + k in nonzero]
    Q0, R0 = np.linalg.qr(Y[:, order] / norms[order])
    tol = rows.tolerance
    chosen, dependent = _chosen_columns(R0, list(range(len(order))), tol)
    beta = np.linalg.lstsq(R0[:, chosen], R0[:, dependent], rcond=None)[0] if dependent else None
    # E: scaled π (in ``order``) → the chosen combinations; dependent columns fold in by β
    E = np.zeros((len(chosen), len(order)))
    E[np.arange(len(chosen)), chosen] = 1.0
    if dependent:
        E[:, dependent] = np.where(np.abs(beta) > tol, beta, 0.0)
    Q1, R_b = np.linalg.qr(R0[:, chosen])
    phi = np.zeros((len(chosen), P))
    phi[:, order] = R_b @ E * norms[order]
    projected = Q0.T @ d
    target = Q1.T @ projected
    residual = float(np.linalg.norm(d - Q0 @ (Q1 @ target)))
    # the combinations: physical units of their chosen parameter
    R_inv = np.linalg.inv(R_b)
    delta_scaled = R_inv @ target
    urdf_scaled = E @ (urdf[order] * norms[order])
    rounding = np.linalg.norm(R_inv, axis=1) * tol
    combinations = []
    for k, c in enumerate(chosen):
        lead = order[c]
        terms = [(1.0, links[lead // 10], PARAMETERS[lead % 10])]
        for col in np.flatnonzero(E[k]):
            if col != c:
                p = order[col]
                terms.append((E[k, col] * norms[p] / norms[lead], links[p // 10], PARAMETERS[p % 10]))
        scale = norms[lead]
        combinations.append(
            Combination(
                tuple(terms),
                UNITS[lead % 10],
                float((urdf_scaled[k] + delta_scaled[k]) / scale),
                float(urdf_scaled[k] / scale),
                float(rounding[k] / scale),
            )
        )
    return ImpliedParameters(
        links, urdf, rows, phi, target, residual, float(np.linalg.norm(d)), combinations, tol, norms
    )
