"""The checks: one Pinocchio quantity against its closed form, on many states.

Error measure
-------------
Every comparison is made in diagonally scaled coordinates z_i = √S_i·θ_i, with
S_i the model's inertia scale of coordinate i (``diagonal_scale``), so that a
cart in kg and a rod in kg·m² are judged on one footing and raw κ(M), which
mostly reflects units, does not inflate tolerances.  In these coordinates
M̃ = S^{-½} M S^{-½} has entries of order one, forces scale by S^{-½} and
accelerations by S^{½}.

For each state the check computes the error e, a *scale* s (the size of the
terms that produced the quantity, including cancellation and, for inverses and
accelerations, the conditioning ‖M̃⁻¹‖) and passes when

    e ≤ K·ε·((1 + |θ|max)·c_T + (A − 1))·s + a,

where ε is machine epsilon, K the check's named constant, (1 + |θ|max) the
growth of rounding in angles as large as |θ| (cos(θ + 2πk) is only as exact as
θ is), c_T = cond₂(T)² the amplification of rounding that Pinocchio commits in
its own joint coordinates by the map to the model's (1 for the double
pendulum, 6.85 for the cart's relative joint), A ≥ 1 the factor by which
Pinocchio's world-frame terms exceed the result (``pendverify.checks.trust.
term_amplification``: a cart far along its rail, a light link at the end of a
long one), whose rounding adds to the angles' rather than multiplying it, and a
the known model-form allowance (zero unless the URDF lies outside the
closed form's family, see ``pendverify.robot.geometry``).  This is the one
tolerance model: ``pendverify stress``, the certification battery and the
simulator's checks call these checks as they are.  Reported: e/s and the
tolerance (K·ε·((1 + |θ|max)·c_T + (A − 1)) + a/s) at the worst state, the state
with the largest e / tolerance.

How Ṁ is obtained (skew check): from Pinocchio's analytic RNEA derivatives with
gravity off, Ṁ e_j = ∂τ/∂q(q, 0, e_j)·q̇, which does not use its Coriolis matrix.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from pendverify.analytic import ClosedFormModel
from pendverify.checks.sampling import State
from pendverify.checks.trust import REFUSE_REL, term_amplification
from pendverify.checks.verdict import FAIL, PASS, REFUSED
from pendverify.robot.system import PinocchioSystem

EPS = float(np.finfo(float).eps)


@dataclass(frozen=True)
class Sample:
    error: float
    scale: float
    allowance: float = 0.0
    note: str = ""


@dataclass(frozen=True)
class Check:
    name: str
    pinocchio: str
    closed_form: str
    K: float
    evaluate: Callable[[ClosedFormModel, PinocchioSystem, State], Sample]
    #: "" when the check applies to this model and system, else why it is not run
    requires: Callable[[ClosedFormModel, PinocchioSystem | None], str] = lambda model, system: ""
    #: whether the Pinocchio side is computed by its world-frame recursions (then A counts)
    world_frame: bool = True


@dataclass
class CheckResult:
    """The evidence of one check on one model: errors, tolerance, where it was worst."""

    model: str
    check: str
    description: str
    max_error: float
    tolerance: float
    max_abs_error: float
    samples: int
    seed: int
    worst_state: dict
    passed: bool
    notes: list[str] = field(default_factory=list)
    #: pass, warn, fail or refused (``pendverify.checks.verdict``); ``passed`` is pass or warn
    status: str = ""

    def __post_init__(self) -> None:
        if not self.status:
            self.status = PASS if self.passed else FAIL

    def as_dict(self) -> dict:
        return dict(self.__dict__)


# --- scaled-coordinate helpers ------------------------------------------------------------
def weights(model, q):
    return 1.0 / np.sqrt(model.diagonal_scale(q))


def scaled_matrix(A, w):
    return A * np.outer(w, w)


def rate_scale(model, q, v) -> float:
    """Largest rate in 1/s: angular rates as they are, linear rates over a natural length.

    Pinocchio's recursions carry body velocities that include linear ones (the
    cart's), so they set the size of the intermediate terms too.  The length for
    a linear coordinate i is ℓ_i = √(min S_angular / S_i), a radius of gyration.
    """
    angular = np.array(model.angular)
    S = model.diagonal_scale(q)
    rates = np.abs(v).astype(float)
    if np.any(~angular) and np.any(angular):
        rates[~angular] /= np.sqrt(np.min(S[angular]) / S[~angular])
    return float(np.max(rates, initial=0.0))


def norm2(A) -> float:
    return float(np.linalg.norm(A, 2))


def world_lever(model, system, q) -> float:
    """A ≥ 1: how much larger Pinocchio's world-frame terms are than M's diagonal (scaled).

    Pinocchio expresses spatial inertias about the world origin, so a joint whose
    subtree sits far from it (a cart 10 m along the rail, a small link 2 at the
    end of a long link 1) carries second moments m·|c|² ≫ M_ii into its
    recursions, which cancel in the result: its rounding is ε·A times the
    result's scale, added to the angles' (``run_check``).
    (``pendverify.checks.trust.term_amplification``.)
    """
    return term_amplification(model, system, q)


def _force_scale(model, state, w) -> float:
    """Size of the generalized forces acting, in scaled units (sum of |terms|)."""
    rate = rate_scale(model, state.q, state.v)
    zdot = state.v / w
    coriolis = rate * np.sum(np.abs(zdot))
    gravity = np.max(w * model.gravity_scale())
    applied = w * (
        np.abs(model.input_matrix()) @ np.abs(state.u)
        + np.abs(model.disturbance_matrix()) @ np.abs(state.w)
        + np.abs(model.damping_matrix()) @ np.abs(state.v)
    )
    return float(coriolis + gravity + np.max(applied, initial=0.0))


def _allowance(system) -> np.ndarray:
    return system.allowance


# --- the checks ---------------------------------------------------------------------------
def _crba(model, system, s):
    w = weights(model, s.q)
    err = np.max(np.abs(scaled_matrix(system.mass_matrix(s.q) - model.mass_matrix(s.q), w)))
    return Sample(err, 1.0)


def _damping_rate(model, w) -> float:
    """max |D̃| in 1/s: a hand C written with friction inside (C + D, as seed 000) rounds at this size."""
    return float(np.max(np.abs(scaled_matrix(model.damping_matrix(), w)), initial=0.0))


def _rnea(model, system, s):
    w = weights(model, s.q)
    err = np.max(w * np.abs(system.bias(s.q, s.v) - model.bias(s.q, s.v)))
    zdot = s.v / w
    scale = (rate_scale(model, s.q, s.v) + _damping_rate(model, w)) * np.sum(np.abs(zdot)) + np.max(
        w * model.gravity_scale()
    )
    return Sample(err, scale, float(np.max(w * _allowance(system))))


def _gravity(model, system, s):
    w = weights(model, s.q)
    err = np.max(w * np.abs(system.gravity(s.q) - model.gravity(s.q)))
    return Sample(err, float(np.max(w * model.gravity_scale())), float(np.max(w * _allowance(system))))


def _coriolis(model, system, s):
    w = weights(model, s.q)
    diff = system.coriolis_matrix(s.q, s.v) - model.coriolis_matrix(s.q, s.v)
    rates = max(rate_scale(model, s.q, s.v) + _damping_rate(model, w), 1.0)
    return Sample(np.max(np.abs(scaled_matrix(diff, w))), rates)


def _skew(model, system, s):
    w = weights(model, s.q)
    N = system.mass_matrix_derivative(s.q, s.v) - 2 * model.coriolis_matrix(s.q, s.v)
    rates = max(rate_scale(model, s.q, s.v) + _damping_rate(model, w), 1.0)
    return Sample(np.max(np.abs(scaled_matrix(N + N.T, w))), rates)


def _det(model, system, s):
    scale = float(np.prod(model.diagonal_scale(s.q)))
    closed, lu = model.det_mass_matrix(s.q), system.det_mass_matrix(s.q)
    if not (closed > 0 and lu > 0):
        return Sample(np.inf, scale, note=f"det M not positive: closed form {closed:.3g}, LU {lu:.3g}")
    return Sample(abs(closed - lu), scale)


def _minverse(model, system, s):
    sqrt_s = 1.0 / weights(model, s.q)
    diff = system.inverse_mass_matrix(s.q) - model.inverse_mass_matrix(s.q)
    Minv_scaled = scaled_matrix(model.inverse_mass_matrix(s.q), sqrt_s)
    M_scaled = scaled_matrix(model.mass_matrix(s.q), 1.0 / sqrt_s)
    # δ(M⁻¹) = −M⁻¹ δM M⁻¹ with |δM̃| ~ ε‖M̃‖
    scale = norm2(Minv_scaled) ** 2 * norm2(M_scaled)
    return Sample(np.max(np.abs(scaled_matrix(diff, sqrt_s))), scale)


def _aba(model, system, s):
    w = weights(model, s.q)
    tau = model.input_matrix() @ s.u + model.disturbance_matrix() @ s.w - model.damping_matrix() @ s.v
    a_pin = system.acceleration(s.q, s.v, tau)
    a_hand = model.acceleration(s.q, s.v, s.u, s.w)
    Minv_norm = norm2(scaled_matrix(model.inverse_mass_matrix(s.q), 1.0 / w))
    M_norm = norm2(scaled_matrix(model.mass_matrix(s.q), w))
    scale = Minv_norm * (_force_scale(model, s, w) + M_norm * np.max(np.abs(a_pin / w)))
    allowance = float(np.max(Minv_norm * np.max(w * _allowance(system))))
    return Sample(np.max(np.abs((a_pin - a_hand) / w)), scale, allowance)


def _energy(model, system, s):
    w = weights(model, s.q)
    zero = np.zeros(model.nv)
    kinetic = abs(system.kinetic_energy(s.q, s.v) - model.kinetic_energy(s.q, s.v))
    # potential energies agree up to a constant: compare differences from θ = 0
    dv_pin = system.potential_energy(s.q) - system.potential_energy(zero)
    dv_hand = model.potential_energy(s.q) - model.potential_energy(zero)
    kinetic_scale = 0.5 * float(np.sum((s.v / w) ** 2)) * norm2(scaled_matrix(model.mass_matrix(s.q), w))
    potential_scale = float(np.max(model.gravity_scale()))
    allowance = 2 * float(np.sum(_allowance(system)))  # |ΔV| ≤ m g |offset| at both ends
    return Sample(kinetic + abs(dv_pin - dv_hand), kinetic_scale + potential_scale, allowance)


def _damping(model, system, s):
    """The URDF's <dynamics damping> seen in the model's coordinates (Tᵀ·diag(b)·T) against D.

    Pinocchio keeps the damping but none of its algorithms applies it, so no other
    check can see a URDF whose damping disagrees with the hand model's D.
    """
    w = weights(model, s.q)
    D_urdf = system.cmap.matrix_to_model(np.diag(system.urdf_damping()))
    D = model.damping_matrix()
    diff = np.abs(scaled_matrix(D_urdf - D, w))
    scale = max(np.max(np.abs(scaled_matrix(D, w))), np.max(np.abs(scaled_matrix(D_urdf, w))))
    note = ""
    if np.max(diff) > 0:
        i, j = np.unravel_index(np.argmax(diff), diff.shape)
        names = model.coordinates
        note = (
            f"D[{names[i]},{names[j]}]: the URDF's <dynamics damping> gives {D_urdf[i, j]:.6g}, "
            f"the hand model {D[i, j]:.6g}"
        )
    return Sample(float(np.max(diff)), float(scale), note=note)


def _needs_matrix_c(model, system) -> str:
    if model.has_coriolis_matrix:
        return ""
    name = model.__name__ if isinstance(model, type) else type(model).__name__
    return (
        f"not run: {name} gives the force C·q̇ (coriolis_force), not a matrix C; "
        "C·q̇ is checked by rnea and aba"
    )


def _class(model) -> type:
    return model if isinstance(model, type) else type(model)


#: The quantities a model may leave to the interface's defaults: (method, name, how it is derived).
DERIVED = {
    "det_mass_matrix": ("det M", "from M (LU)"),
    "inverse_mass_matrix": ("M⁻¹", "from M (solving with M)"),
    "acceleration": ("q̈", "from M, C, H, D, B, W (M⁻¹(B u + W w − D q̇ − C q̇ − H))"),
    "gravity_scale": ("the gravity scale", "from H (Σ|terms|)"),
    "diagonal_scale": ("the inertia scale", "from M (Σ|terms| of M_ii)"),
    "special_states": ("the special states", "(the zero state only)"),
}


def _hand_written(method: str):
    """A ``requires``: the check compares a hand-written closed form, so a derived one is not run."""

    def requires(model, system) -> str:
        if method in _class(model).hand_written():
            return ""
        what, how = DERIVED[method]
        return f"not run: {what} is derived {how}, not hand-written: nothing to check"

    return requires


def derived_notes(model) -> list[str]:
    """What the model left to the interface's defaults and what that means for the evidence.

    ``aba`` runs on a derived q̈ too, but it is then weaker evidence: the derived
    M⁻¹(B u + W w − D q̇ − C q̇ − H) and Pinocchio's ABA of the same τ = B u + W w − D q̇
    see B, W and D alike, so aba checks only M and C·q̇ + H (which crba and rnea
    check directly) composed by the solve the simulator uses — not B or W, which the
    URDF does not define (``pendverify sympy`` compares them with the input power),
    and D only through ``damping`` (the URDF's <dynamics damping>).
    """
    written = set(_class(model).hand_written())
    notes = []
    if "acceleration" not in written:
        notes.append(
            "aba: q̈ is derived from the model's M, C, H, D, B, W, not hand-written: aba checks M and "
            "C·q̇ + H composed (the same τ = B u + W w − D q̇ enters both sides), not B or W, and no "
            "closed form of q̈; B and W are compared only by pendverify sympy"
        )
    derived = [
        f"{what} {how}"
        for method, (what, how) in DERIVED.items()
        if method not in written and method in ("gravity_scale", "diagonal_scale", "special_states")
    ]
    if derived:
        notes.append("derived, not hand-written: " + "; ".join(derived))
    return notes


def _needs_urdf_damping(model, system) -> str:
    if system is None or system.urdf_damping() is not None:
        return ""
    return "not run: the URDF declares no <dynamics damping>, so there is nothing to compare D with"


CHECKS: tuple[Check, ...] = (
    Check("crba", "crba (symmetrised)", "M(q)", 8, _crba),
    Check("rnea", "rnea(q, q̇, 0)", "C(q,q̇)·q̇ + H(q), friction removed", 16, _rnea),
    Check("gravity", "computeGeneralizedGravity", "H(q)", 16, _gravity),
    Check("coriolis", "computeCoriolisMatrix", "C(q,q̇) without friction", 16, _coriolis, _needs_matrix_c),
    Check("skew", "Ṁ (RNEA derivatives) − 2C", "skew-symmetric", 16, _skew, _needs_matrix_c),
    Check("det", "det(crba) by LU", "closed-form det M(q) > 0", 16, _det, _hand_written("det_mass_matrix")),
    Check(
        "minverse",
        "computeMinverse",
        "M(q)⁻¹ (closed form)",
        16,
        _minverse,
        _hand_written("inverse_mass_matrix"),
    ),
    Check("aba", "aba(q, q̇, Bu + Ww − Dq̇)", "closed-form q̈ (f + g·u, M⁻¹f)", 16, _aba),
    Check("energy", "kinetic + potential energy", "½q̇ᵀMq̇, V(q) − V(0)", 16, _energy),
    # Tᵀ·diag(b)·T: each entry a sum of at most n products of exact decimals' roundings
    Check("damping", "<dynamics damping> (Tᵀ·diag(b)·T)", "D", 8, _damping, _needs_urdf_damping, False),
)
CHECK_NAMES = tuple(c.name for c in CHECKS)


def run_check(check: Check, label: str, model, system, states, seed: int) -> CheckResult:
    """Evaluate one check on every state and keep the evidence of the worst one.

    A state whose own rounding tolerance K·ε·((1 + |θ|)·c_T + (A − 1)) exceeds the
    trust limit (``trust.REFUSE_REL``) is not judged: a tolerance that wide would
    pass a 1 ppm modelling error.  The check is then ``refused`` (unless another
    state fails), whatever the guard before it let through.
    """
    worst_ratio, worst = -1.0, None
    max_abs = 0.0
    c_T = system.cmap.amplification
    notes: list[str] = []
    refused: list[tuple[State, float]] = []
    for state in states:
        angle = float(np.max(np.abs(state.q[np.array(model.angular)]), initial=0.0))
        lever = world_lever(model, system, state.q) if check.world_frame else 1.0
        rounding = check.K * EPS * ((1.0 + angle) * c_T + (lever - 1.0))
        if not rounding <= REFUSE_REL:
            refused.append((state, rounding))
            continue
        sample = check.evaluate(model, system, state)
        if sample.note and len(notes) < 3:
            notes.append(f"{state.label}: {sample.note}")
        if sample.scale > 0:
            rel_tol = rounding + sample.allowance / sample.scale
            rel_err = sample.error / sample.scale
        else:  # nothing acts (at rest with g = 0): any error at all is a failure
            rel_tol = rounding
            rel_err = 0.0 if sample.error == 0 else np.inf
        ratio = rel_err / rel_tol if np.isfinite(rel_err) else np.inf
        if np.isnan(rel_err):
            ratio = np.inf
            notes.append(f"{state.label}: NaN")
        max_abs = max(max_abs, float(sample.error))
        if ratio > worst_ratio:
            worst_ratio, worst = ratio, (state, rel_err, rel_tol)
    status = ""
    if refused:
        state, rounding = refused[0]
        lever = world_lever(model, system, state.q)
        notes.insert(
            0,
            f"{len(refused)} of {len(states)} states refused: at {state.label} the rounding tolerance "
            f"{rounding:.2g} exceeds the trust limit {REFUSE_REL:g} (Pinocchio's terms {lever:.2g}× the "
            "result)",
        )
        if worst is None:
            worst = (state, float("nan"), rounding)
        if worst_ratio <= 1.0:
            status = REFUSED
    state, rel_err, rel_tol = worst
    return CheckResult(
        model=label,
        check=check.name,
        description=f"{check.pinocchio} vs {check.closed_form}",
        max_error=float(rel_err),
        tolerance=float(rel_tol),
        max_abs_error=max_abs,
        samples=len(states),
        seed=seed,
        worst_state=state.as_dict(),
        passed=bool(worst_ratio <= 1.0) and not refused,
        notes=notes,
        status=status,
    )


def not_applicable(model, system=None) -> dict[str, str]:
    """{check: why it is not run} for the checks this model (and URDF, if given) cannot take."""
    reasons = {c.name: c.requires(model, system) for c in CHECKS}
    return {name: why for name, why in reasons.items() if why}


def skipped_notes(model, system=None) -> list[str]:
    """One note per reason some checks are not run: "coriolis, skew not run: …"."""
    by_reason: dict[str, list[str]] = {}
    for name, why in not_applicable(model, system).items():
        by_reason.setdefault(why, []).append(name)
    return [f"{', '.join(names)} {why}" for why, names in by_reason.items()]


def applicable_checks(model, system=None) -> tuple[str, ...]:
    """The checks a model (and its URDF, if given) can take, in the table's order."""
    skipped = not_applicable(model, system)
    return tuple(name for name in CHECK_NAMES if name not in skipped)


def run_checks(label, model, system, states, seed, names=CHECK_NAMES) -> list[CheckResult]:
    """The named checks that apply to ``model`` and ``system``, each on every state."""
    names = set(names) & set(applicable_checks(model, system))
    return [run_check(c, label, model, system, states, seed) for c in CHECKS if c.name in names]
