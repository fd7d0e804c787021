"""The inertial parameters a hand model implies: is it this robot with other masses, and which?

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
Each row is divided by the scale its check judges it against (``pendverify.checks.
quantities``: M̃ = W M W with w = 1/√S for M, max w·g_scale for H, (rate + damping rate)·Σ|q̇/w|
for C·q̇) and by the state's rounding growth f = (1 + |θ|max)·c_T + (A − 1)
(``pendverify.checks.catalogue``), so that a correct model's row differs from the URDF's by
at most K·ε, K = 16 the largest constant of the checks of these quantities (crba 8, rnea 16,
gravity 16).  Rows with a zero scale carry nothing (C·q̇ at rest, H without gravity) and
are left out.  Over R rows the rounding is then ‖e‖₂ ≤ √R·K·ε = ``tolerance``, and a least
squares residual is the data projected on the complement of the regressor's range, which
does not enlarge it: a fit whose residual is within ``tolerance`` reproduces the hand
model's equations to rounding on every sampled state.  Householder QR adds a backward error
of order ε·‖b‖ ≤ ε·√R (each row is at most one after the scaling), well inside it.

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

Hypotheses
----------
Δπ = π_model − π_urdf is explained per link by physical changes, each Δπ(x) = x·u + x²·w in
its unknown x (built with ``pin.Inertia`` from the URDF body's m, c, I_c):

* ``mass``: m → m + x, c and I_c kept (linear: u = [1, c, |c|²𝟙 − ccᵀ]);
* ``first moment`` along an axis: m·c_a → m·c_a + x, m and the inertia about the joint kept;
* ``centre of mass`` along an axis: c_a → c_a + x, m and I_c kept (quadratic: I = I_c + m(...));
* ``inertia about the centre of mass``, one component: I_c,k → I_c,k + x;
* ``inertia about the pivot``: I_c → I_c ± m(|c|²𝟙 − ccᵀ), no unknown (+: the model's I_c is
  the URDF's inertia about the joint; −: the URDF's I_c is the model's inertia about the joint).

A hypothesis whose direction lies in the null space (its data-space image within the rank
tolerance of zero) says nothing and is skipped.  Single hypotheses are tried first, then
pairs; the unknowns are solved by Gauss–Newton from the linear fit (exact for the linear
ones), and an explanation is accepted only when Y·(π_urdf + Δπ(x)) reproduces the hand
model's rows within ``tolerance``; a solved value's rounding (a finding's ``rounding``) is
‖row of J⁺‖·``tolerance``, J the image of ∂Δπ/∂x at the solution.  Among the accepted,
the fewest hypotheses, then the fewest unknowns win; when several remain the equations
cannot tell them apart and every one is reported, saying so and naming the combinations the
equations fix.  An explanation
without unknowns (an inertia about the pivot) predicts the difference rather than fitting it,
so it is preferred to a one-unknown one that also fits (any change of I_xx fits what m·r² on
I_xx does).  When no one or two hypotheses fit, the combinations that differ beyond their
rounding are listed instead.

Structural differences
----------------------
When no parameters reproduce the rows, each quantity (M, C·q̇, H) is fitted on its own and
the pairs together, to say which are this robot's for some parameters; and entries are left
out, an irreducible set (``ImpliedParameters.unexplained``), until parameters reproduce the
rest: every sentence of the ``structural`` finding is such a fit, within ``tolerance`` of its
own rows.  Rows the hand model gives no finite value for are left out (the checks report them).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import pinocchio as pin

from pendverify.analytic.interface import BiasOnlyModel
from pendverify.checks.scaling import mv, total
from pendverify.checks.trust import EPS
from pendverify.diagnosis.finding import Finding

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
    w = np.broadcast_to(t.w, (len(batch), n))
    growth = (1.0 + batch.angle) * batch.c_T + (batch.lever - 1.0)
    g_scale = np.max(w * t.g_scale, axis=-1)
    c_scale = (t.rate + t.d_rate) * total(np.abs(batch.V / w))
    # per state: M's n² rows (row i, column j), then C·q̇'s n, then H's n
    Y_rows = np.concatenate(
        [np.swapaxes(Y[:, 1 : n + 1], 1, 2).reshape(len(batch), n * n, -1), Y[:, n + 1], Y[:, 0]], 1
    )
    b_rows = np.concatenate([t.M_hand.reshape(len(batch), n * n), _hand_coriolis_force(batch), t.H_hand], 1)
    weight_M = (w[:, :, None] * w[:, None, :]).reshape(len(batch), n * n)
    with np.errstate(divide="ignore", invalid="ignore"):
        weight = np.concatenate([weight_M, w / c_scale[:, None], w / g_scale[:, None]], 1) / growth[:, None]
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


# --- the physical hypotheses -------------------------------------------------------------------
@dataclass(frozen=True)
class Hypothesis:
    """One physical change of one link: Δπ(x) = x·u + x²·w (u alone when it has no unknown)."""

    joint: int  # 0-based joint index (the link's block of ten parameters)
    link: str
    parameter: str  # the Finding's "parameter"
    label: str  # axis or component ("y", "xx"), sign ("+", "−") or ""
    unknowns: int
    u: np.ndarray  # (10,)
    w: np.ndarray  # (10,)


def _dynamic(inertia: pin.Inertia) -> np.ndarray:
    return inertia.toDynamicParameters()


def _quadratic(f) -> tuple[np.ndarray, np.ndarray]:
    """u, w of a change Δπ(x) quadratic in x (exact: from x = ±1)."""
    plus, minus = f(1.0), f(-1.0)
    return (plus - minus) / 2.0, (plus + minus) / 2.0


def link_hypotheses(model: pin.Model, joint: int, link: str) -> list[Hypothesis]:
    """Every hypothesis of one link (module docstring), built from its URDF body with ``pin.Inertia``."""
    body = model.inertias[joint + 1]
    m, c, I_c = body.mass, np.array(body.lever), np.array(body.inertia)
    pi0 = _dynamic(body)
    out = []

    def add(parameter, label, f, unknowns=1):
        u, w = _quadratic(f) if unknowns else (f(), np.zeros(10))
        out.append(Hypothesis(joint, link, parameter, label, unknowns, u, w))

    add("mass", "", lambda x: _dynamic(pin.Inertia(m + x, c, I_c)) - pi0)
    for a, axis in enumerate(AXES):
        add("first moment", axis, lambda x, a=a: x * np.eye(10)[1 + a])
    for a, axis in enumerate(AXES):
        add("centre of mass", axis, lambda x, a=a: _dynamic(pin.Inertia(m, c + x * np.eye(3)[a], I_c)) - pi0)
    for k, (name, _, _) in enumerate(COMPONENTS):
        add("inertia about the centre of mass", name, lambda x, k=k: x * np.eye(10)[4 + k])
    shift = body.matrix()[3:, 3:] - I_c  # m(|c|²𝟙 − ccᵀ): the joint-origin inertia less I_c
    if np.any(shift != 0):
        for sign, label in ((1.0, "+"), (-1.0, "−")):
            add(
                "inertia about the pivot",
                label,
                lambda s=sign: s * _dynamic(pin.Inertia(0.0, np.zeros(3), shift)),
                0,
            )
    return out


@dataclass(frozen=True)
class Explanation:
    """Hypotheses with their solved unknowns, and the residual of π_urdf + Δπ."""

    hypotheses: tuple[Hypothesis, ...]
    values: tuple[float, ...]  # one per hypothesis (0 for one without an unknown)
    residual: float
    #: each value's rounding: ‖row of J⁺‖·tolerance, J the image of ∂Δπ/∂x (0 without an unknown)
    roundings: tuple[float, ...]

    @property
    def unknowns(self) -> int:
        return sum(h.unknowns for h in self.hypotheses)


def _delta(hypotheses, x, P):
    out = np.zeros(P)
    for h, xi in zip(hypotheses, x, strict=True):
        block = h.u * xi + h.w * xi**2 if h.unknowns else h.u
        out[10 * h.joint : 10 * h.joint + 10] += block
    return out


def _directions(hypotheses, x, P):
    """∂Δπ/∂x for the hypotheses with an unknown (P, k)."""
    cols = []
    for h, xi in zip(hypotheses, x, strict=True):
        if h.unknowns:
            col = np.zeros(P)
            col[10 * h.joint : 10 * h.joint + 10] = h.u + 2.0 * xi * h.w
            cols.append(col)
    return np.array(cols).reshape(-1, P).T


def _solve(implied: ImpliedParameters, hypotheses) -> Explanation | None:
    """The hypotheses' unknowns by Gauss–Newton from the linear fit; None when they are not identifiable."""
    phi, target, P = implied.phi, implied.target, implied.phi.shape[1]
    x, rounding = np.zeros(len(hypotheses)), np.zeros(len(hypotheses))
    free = np.array([h.unknowns > 0 for h in hypotheses])
    if free.any():
        D = _directions(hypotheses, x, P)
        A = phi @ D
        # each direction's image against the sum of its parameters' separate images (unit-free)
        separate = implied.norms @ np.abs(D)
        if not np.all(separate > 0):  # moves only parameters that never enter
            return None
        singular = np.linalg.svd(A / separate, compute_uv=False)
        if singular[-1] <= implied.rank_tolerance:  # a direction in the null space, or two alike
            return None
        for _ in range(GAUSS_NEWTON_STEPS):
            r = target - phi @ _delta(hypotheses, x, P)
            J = phi @ _directions(hypotheses, x, P)
            step, *_ = np.linalg.lstsq(J, r, rcond=None)
            x[free] += step
            if np.all(np.abs(step) <= 4 * EPS * np.abs(x[free])):
                break
        # δx = J⁺ δz with ‖δz‖ within the tolerance: each unknown's rounding
        J = phi @ _directions(hypotheses, x, P)
        rounding[free] = np.linalg.norm(np.linalg.pinv(J), axis=1) * implied.tolerance
    misfit = np.linalg.norm(phi @ _delta(hypotheses, x, P) - target)
    residual = float(np.hypot(misfit, implied.residual))
    return Explanation(tuple(hypotheses), tuple(map(float, x)), residual, tuple(map(float, rounding)))


def explanations(implied: ImpliedParameters, model: pin.Model) -> list[Explanation]:
    """The sparsest explanations that reproduce the equations to rounding (module docstring)."""
    hypotheses = [h for j, link in enumerate(implied.links) for h in link_hypotheses(model, j, link)]
    for size in (1, 2):
        found = []
        for group in itertools.combinations(hypotheses, size):
            explanation = _solve(implied, group)
            if explanation is not None and explanation.residual <= implied.tolerance:
                found.append(explanation)
        if found:
            fewest = min(e.unknowns for e in found)
            return [e for e in found if e.unknowns == fewest]
    return []


# --- the findings ------------------------------------------------------------------------------
def _distinct(a: float, b: float) -> tuple[str, str]:
    """a and b with six significant digits, or as many more as it takes to tell them apart."""
    for digits in range(6, 18):
        x, y = f"{a:.{digits}g}", f"{b:.{digits}g}"
        if x != y:
            break
    return x, y


def _values(h: Hypothesis, x: float, model: pin.Model):
    """(model value, URDF value) of the parameter a hypothesis changes: floats, or I_c (3×3)."""
    body = model.inertias[h.joint + 1]
    m, c, I_c = body.mass, np.array(body.lever), np.array(body.inertia)
    if h.parameter == "mass":
        return m + x, m
    if h.parameter == "first moment":
        a = AXES.index(h.label)
        return m * c[a] + x, m * c[a]
    if h.parameter == "centre of mass":
        a = AXES.index(h.label)
        return c[a] + x, c[a]
    if h.parameter == "inertia about the centre of mass":
        _, i, j = next(comp for comp in COMPONENTS if comp[0] == h.label)
        return I_c[i, j] + x, I_c[i, j]
    sign = 1.0 if h.label == "+" else -1.0
    return I_c + sign * (body.matrix()[3:, 3:] - I_c), I_c


def _phrase(h: Hypothesis, model_value, urdf_value, body: pin.Inertia) -> str:
    """The change in words, as "your equations are this URDF with ..." continues."""
    if h.parameter == "inertia about the pivot":
        c = np.array(body.lever)
        term = f"{body.mass * float(c @ c):.6g} kg·m²"
        if h.label == "+":
            return (
                f"{h.link}'s inertia about its pivot where the URDF has it about the centre of mass "
                f"(the parallel-axis term m·|c|² = {term} counted twice)"
            )
        return (
            f"{h.link}'s inertia about the centre of mass where the URDF has it about the pivot "
            f"(the URDF's is larger by the parallel-axis term m·|c|² = {term})"
        )
    ours, theirs = _distinct(model_value, urdf_value)
    if h.parameter == "mass":
        return f"{h.link}'s mass {ours} kg instead of {theirs} kg"
    if h.parameter == "first moment":
        at = f"{model_value / body.mass:.6g} m" if body.mass else "undefined"
        return (
            f"{h.link}'s first moment m·c_{h.label} = {ours} kg·m instead of {theirs} kg·m "
            f"(its centre of mass at {h.label} = {at}, with its inertia about the joint kept?)"
        )
    if h.parameter == "centre of mass":
        return (
            f"{h.link}'s centre of mass at {h.label} = {ours} m instead of {theirs} m "
            "(in its joint frame; mass and inertia about the centre of mass kept)"
        )
    return f"{h.link}'s inertia about its centre of mass I_{h.label} = {ours} kg·m² instead of {theirs} kg·m²"


def _listed(value):
    return np.asarray(value).tolist() if np.ndim(value) else float(value)


def _combinations(implied: ImpliedParameters) -> str:
    """The identifiable combinations that differ, in words."""
    words = []
    for c in implied.combinations:
        if c.differs:
            ours, theirs = _distinct(c.model_value, c.urdf_value)
            words.append(f"{c.name} = {ours} instead of {theirs} {c.unit}")
    return "; ".join(words)


def _findings(found: list[Explanation], implied: ImpliedParameters, model: pin.Model) -> list[Finding]:
    """One finding per changed parameter of each explanation found (several: they are alternatives)."""
    out = []
    for explanation in found:
        changes = [
            (h, *_values(h, x, model), rounding)
            for h, x, rounding in zip(
                explanation.hypotheses, explanation.values, explanation.roundings, strict=True
            )
        ]
        phrases = [_phrase(h, ours, theirs, model.inertias[h.joint + 1]) for h, ours, theirs, _ in changes]
        sentence = "your equations are this URDF with " + " and ".join(phrases)
        if len(found) > 1:
            sentence += (
                f" — one of {len(found)} explanations your M, C·q̇ and H cannot tell apart: they fix "
                f"only {_combinations(implied)} (I about each joint's origin)"
            )
        for h, ours, theirs, rounding in changes:
            details = {
                "link": h.link,
                "parameter": h.parameter,
                "model_value": _listed(ours),
                "urdf_value": _listed(theirs),
                "rounding": rounding,
                "residual": explanation.residual,
            }
            if h.parameter in ("first moment", "centre of mass"):
                details["axis"] = h.label
            elif h.parameter == "inertia about the centre of mass":
                details["component"] = h.label
            if len(found) > 1:
                details["alternatives"] = len(found)
            out.append(Finding("parameters", sentence, details=details))
    return out


def _combinations_finding(implied: ImpliedParameters) -> Finding:
    differ = [c for c in implied.combinations if c.differs]
    links = sorted({link for c in differ for _, link, _ in c.terms}, key=implied.links.index)
    return Finding(
        "parameters",
        "your equations are this robot with other inertial parameters, but no one or two changes of "
        "a link's mass, centre of mass or inertia explain them; the identifiable combinations that "
        f"differ (I about each joint's origin): {_combinations(implied)}",
        details={
            "link": links,
            "parameter": "identifiable combinations",
            "combinations": [c.name for c in differ],
            "model_value": [c.model_value for c in differ],
            "urdf_value": [c.urdf_value for c in differ],
            "rounding": [c.rounding for c in differ],
            "residual": implied.residual,
        },
    )


def _structural_finding(implied: ImpliedParameters) -> Finding:
    """No parameters reproduce all rows: which quantities are this robot's on their own, which entries not."""
    quantities = implied.quantities
    alone = {q: implied.fits(implied.rows_of(q)) for q in quantities}
    not_alone = [q for q in quantities if not alone[q]]
    if not_alone:
        what = " and ".join(not_alone)
        where = (
            f"{what} on its own is" if len(not_alone) == 1 else f"{what} are, each on its own,"
        ) + " not this robot's for any inertial parameters"
    else:
        together = [
            f"{a} and {b}"
            for a, b in itertools.combinations(quantities, 2)
            if implied.fits(implied.rows_of(a, b))
        ]
        where = (
            f"{', '.join(quantities)} are each this robot's with some inertial parameters, "
            "but not all with the same ones"
        )
        if together:
            where += f" ({'; '.join(together)} together are)"
    entries = implied.unexplained
    relative = implied.residual / float(np.linalg.norm(implied.rows.b))
    return Finding(
        "structural",
        "no mass distribution of this robot produces your equations: the difference is structural: "
        f"{where}; leaving out {', '.join(entries)}, parameters reproduce the rest "
        f"(relative residual of the best fit to all of them {relative:.3g})",
        details={"residual": relative, "entries": entries, "not_alone": not_alone},
    )


def identify_parameters(batch) -> list[Finding]:
    """Whether the hand model's M, C·q̇, H are the URDF tree's with other inertial parameters, and which.

    [] when the URDF's own parameters reproduce them; one ``structural`` finding when no
    parameters do; otherwise one ``parameters`` finding per changed parameter of the
    sparsest explanation (module docstring), or one listing the combinations that differ.
    """
    with np.errstate(all="ignore"):
        implied = implied_parameters(batch)
        if implied.agrees:
            return []
        if not implied.exact:
            return [_structural_finding(implied)]
        found = explanations(implied, batch.system.model)
    if not found:
        return [_combinations_finding(implied)]
    return _findings(found, implied, batch.system.model)
