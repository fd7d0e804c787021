"""The trust rule measured: the cart's m1 → 0 study against a 50-digit mpmath reference.

What ``trust_study`` measures
-----------------------------
For m1 = 1, 0.1, ..., 1e-16 kg and three aligned states it compares with a
50-digit mpmath reference built from the *same* float parameters and state: the
model's own closed forms as generated, generic over the number type
(``pendverify.numerics.codegen.generic``: M from ``mass``, q̈ = M⁻¹ (τ − C q̇ − H) from
``field``, solved by its LDLᵀ), evaluated on mpf numbers in ``REFERENCE_DIGITS`` digits,
with det M and M⁻¹ of that M by mpmath:

* det M: the cart's closed form (a sum of non-negative terms) and the LU
  determinant of Pinocchio's CRBA;
* q̈: the closed form (an LU solve with M) and Pinocchio's ABA;
* M⁻¹: the closed form (adjugate / closed-form det) and ``computeMinverse``.

Errors are relative, in the scaled coordinates (q̈ and M⁻¹ scaled by √S).
The measured trust limit is the smallest m1 from which on every quantity stays
within ``REFUSE_REL`` of the reference; the guard must refuse everything below
it and must never accept a state whose measured error exceeds its bound.

The rule itself (``check_conditioning``) lives in ``pendverify.checks.trust``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import mpmath as mp
import numpy as np

from pendverify.analytic import MODELS
from pendverify.checks import trust
from pendverify.checks.trust import REFUSE_REL
from pendverify.errors import IllConditionedError
from pendverify.numerics.generate import GeneratedSystem
from pendverify.numerics.integrators import taylor
from pendverify.robot.system import PinocchioSystem

REFERENCE_DIGITS = 50
STUDY_MASSES = tuple(10.0**-k for k in range(17))  # m1 in kg


# --- the 50-digit reference ---------------------------------------------------------------
def _mpf(x) -> mp.mpf:
    return mp.mpf(float(x))  # exact: every double is an mpf


def reference_numbers(model, u=None, w=None) -> dict:
    """The model's generated generic code with its numbers as mpf (exact), for ``reference_mass_matrix``
    and ``reference_acceleration``: τ = B u + W w − D q̇, u and w (None: zero) as a constant input."""
    B = np.hstack([model.input_matrix(), model.disturbance_matrix()])
    u = np.zeros(len(model.inputs)) if u is None else np.asarray(u, dtype=float)
    w = np.zeros(len(model.disturbances)) if w is None else np.asarray(w, dtype=float)
    u0 = np.concatenate([u, w])
    return taylor.exact_system(GeneratedSystem.from_model(model, model.damping_matrix(), B, None, u0))


def reference_mass_matrix(numbers: dict, q) -> mp.matrix:
    """M(q) from the generated ``mass`` in mpf (call inside ``mp.workdps``)."""
    rows = numbers["module"].mass(numbers, [_mpf(x) for x in q], mp.mpf, taylor.series_sincos)
    return mp.matrix(rows)


def reference_acceleration(numbers: dict, y, yd) -> list:
    """q̈ = M⁻¹ (τ − C q̇ − H) from the generated ``field`` in mpf (call inside ``mp.workdps``)."""
    return taylor.field(numbers, [_mpf(x) for x in (*y, *yd)])[len(y) :]


def _rel(approx, exact) -> float:
    """max |approx − exact| / max |exact| over entries, in 50 digits; inf for non-finite input."""
    approx = np.atleast_1d(np.asarray(approx, dtype=float)).ravel()
    if not np.all(np.isfinite(approx)):
        return math.inf
    exact = list(exact)
    scale = max(abs(x) for x in exact)
    return float(max(abs(_mpf(a) - e) for a, e in zip(approx, exact, strict=True)) / scale)


# --- the m1 → 0 study -----------------------------------------------------------------------
def study_states() -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    """(y, ẏ, u, w) at which det M ∝ m1: θ1 = θ2 = 0, θ1 = θ2 = 0.7, and θ2 = θ1 + 1e-12."""
    v = np.array([0.3, 1.0, -2.0])
    u = np.array([0.5])
    return {
        "theta1=theta2=0, torque on rod 1": (np.zeros(3), v, u, np.array([0.0, 1.0, 0.0])),
        "theta1=theta2=0.7": (np.array([0.3, 0.7, 0.7]), v, u, np.zeros(3)),
        "theta2=theta1+1e-12": (np.array([0.3, 0.7, 0.7 + 1e-12]), v, u, np.zeros(3)),
    }


@dataclass
class StudyRow:
    """One (m1, state) of the study: relative errors against the 50-digit reference."""

    m1: float
    state: str
    kappa_raw: float
    kappa_scaled: float
    bound: float
    level: str
    det_closed_form: float
    det_lu: float
    accel_closed_form: float
    accel_aba: float
    minv_closed_form: float
    minv_pinocchio: float

    QUANTITIES = (
        "det_closed_form",
        "det_lu",
        "accel_closed_form",
        "accel_aba",
        "minv_closed_form",
        "minv_pinocchio",
    )

    def errors(self) -> dict[str, float]:
        return {name: getattr(self, name) for name in self.QUANTITIES}

    @property
    def worst(self) -> float:
        return max(self.errors().values())


@dataclass
class StudyResult:
    rows: list[StudyRow]
    #: smallest m1 from which on every quantity is within REFUSE_REL of the reference
    measured_limit: float
    #: smallest m1 the guard accepts at every study state
    accepted_limit: float
    #: per quantity, the smallest m1 from which on it stays within REFUSE_REL
    limit_per_quantity: dict[str, float]
    #: accepted rows whose measured error exceeds the predicted rounding bound
    violations: list[str] = field(default_factory=list)
    zero_mass_note: str = ""
    zero_mass_refused: bool = False


def _measure(params, label, y, v, u, w) -> StudyRow:

    model = MODELS[params.model](params)
    system = PinocchioSystem.for_params(params)
    verdict = trust.assess(model, y, system)
    root = np.sqrt(model.diagonal_scale(y))
    numbers = reference_numbers(model, u, w)
    with mp.workdps(REFERENCE_DIGITS):
        M = reference_mass_matrix(numbers, y)
        det_ref = mp.det(M)
        a_ref = reference_acceleration(numbers, y, v)
        Minv_ref = M**-1
        a_scaled = [a_ref[i] * _mpf(root[i]) for i in range(3)]
        Minv_scaled = [Minv_ref[i, j] * _mpf(root[i] * root[j]) for i in range(3) for j in range(3)]
        tau = model.input_matrix() @ u + model.disturbance_matrix() @ w - model.damping_matrix() @ v
        with np.errstate(all="ignore"):
            try:
                a_cf = model.acceleration(y, v, u, w)
            except np.linalg.LinAlgError:
                a_cf = np.full(3, np.nan)
            Minv_cf = model.inverse_mass_matrix(y)
        return StudyRow(
            m1=params.m1,
            state=label,
            kappa_raw=verdict.kappa_raw,
            kappa_scaled=verdict.kappa_scaled,
            bound=verdict.bound,
            level=verdict.level,
            det_closed_form=_rel(model.det_mass_matrix(y), [det_ref]),
            det_lu=_rel(system.det_mass_matrix(y), [det_ref]),
            accel_closed_form=_rel(a_cf * root, a_scaled),
            accel_aba=_rel(system.acceleration(y, v, tau) * root, a_scaled),
            minv_closed_form=_rel(Minv_cf * np.outer(root, root), Minv_scaled),
            minv_pinocchio=_rel(system.inverse_mass_matrix(y) * np.outer(root, root), Minv_scaled),
        )


def _limit(rows: list[StudyRow], ok) -> float:
    """Smallest m1 such that ``ok`` holds for every row with that m1 and every larger one."""
    limit = math.inf
    for m1 in sorted({r.m1 for r in rows}, reverse=True):
        if not all(ok(r) for r in rows if r.m1 == m1):
            break
        limit = m1
    return limit


def zero_mass_demo(base):
    """Pinocchio with m1 = 0 (set in the loaded model; a parameter set refuses it).

    Returns (ABA's q̈ at θ2 = θ1 + 1e-12, whether ``check_conditioning`` refused).
    """
    import pinocchio as pin

    system = PinocchioSystem.for_params(base)
    inertia = system.model.inertias[2]  # rod 1's bob
    system.model.inertias[2] = pin.Inertia(0.0, inertia.lever, inertia.inertia)
    system.data = system.model.createData()
    y, v, u, _ = study_states()["theta2=theta1+1e-12"]
    model = MODELS[base.model](base)
    tau = model.input_matrix() @ u - model.damping_matrix() @ v
    with np.errstate(all="ignore"):
        accel = system.acceleration(y, v, tau)
    try:
        trust.check_conditioning(model, y, system, what="cart with m1 = 0 (Pinocchio)")
    except IllConditionedError:
        return accel, True
    return accel, False


def trust_study(base, masses=STUDY_MASSES) -> StudyResult:
    """The m1 → 0 sweep of the cart reference system at the study states."""
    rows = [
        _measure(base.replace(m1=m1), label, *state)
        for m1 in masses
        for label, state in study_states().items()
    ]
    violations = [
        f"m1 = {r.m1:.0e}, {r.state}: measured {r.worst:.2g} > bound {r.bound:.2g}"
        for r in rows
        if r.level != "refuse" and not r.worst <= r.bound
    ]
    per_quantity = {
        name: _limit(rows, lambda r, name=name: getattr(r, name) <= REFUSE_REL)
        for name in StudyRow.QUANTITIES
    }
    accel, refused = zero_mass_demo(base)
    note = "ABA at m1 = 0, θ2 = θ1 + 1e-12: q̈ = (" + ", ".join(f"{a:.3g}" for a in accel) + ")"
    note += ", finite" if np.all(np.isfinite(accel)) else ", not finite"
    return StudyResult(
        rows=rows,
        measured_limit=_limit(rows, lambda r: r.worst <= REFUSE_REL),
        accepted_limit=_limit(rows, lambda r: r.level != "refuse"),
        limit_per_quantity=per_quantity,
        violations=violations,
        zero_mass_note=note,
        zero_mass_refused=refused,
    )


def det_accuracy(params, q) -> tuple[float, float]:
    """(closed-form det, LU det of the CRBA): relative errors against the 50-digit det."""
    model = MODELS[params.model](params)
    system = PinocchioSystem.for_params(params)
    numbers = reference_numbers(model)
    with mp.workdps(REFERENCE_DIGITS):
        exact = mp.det(reference_mass_matrix(numbers, q))
        return _rel(model.det_mass_matrix(q), [exact]), _rel(system.det_mass_matrix(q), [exact])
