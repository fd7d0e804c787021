"""Runs of a closed-form model's own equations in Python, recorded: RK4, RK45, backward Euler
and Störmer–Verlet.

Every method integrates

    M(q) q̈ + C(q, q̇) q̇ + D q̇ + H(q) = 0        (no input, no disturbance),

through ``model.acceleration`` (explicit and implicit methods) or through
M, C and H (the symplectic method), and records the state every ``record``
steps in an ``IntegrationRecord``: the times and states, the steps and evaluations
spent, and the step at which the run blew up (a non-finite state or one beyond
``BLOW_UP``), which ends it, reported, not raised.

Methods
-------
* ``rk4``: classical fixed-step Runge–Kutta, the tableau ``RK4`` (``tableaux``) run by the
  one stepper ``explicit_rk_step``.
* ``rk45``: SciPy's adaptive Dormand–Prince; reports its step count.  It is scipy's
  ``solve_ivp`` and not the Dormand–Prince tableau on ``explicit_rk_step``: what its
  callers report is the step count of scipy's error control (step-size selection, first
  step, error norm), which the one stepper, having no error estimate, does not carry.
* ``implicit_euler``: backward Euler, x₊ = x + h F(x₊), by Newton with a
  central-difference Jacobian (L-stable: the stiff modes of heavy damping are
  damped at any step).
* ``stormer_verlet``: the generalized leapfrog for H(q, p) = ½ pᵀ M(q)⁻¹ p + V(q)
  (Hairer, Lubich & Wanner, *Geometric Numerical Integration*, §VI.3), with
  p = M(q) q̇ and ∂H/∂q = H(q) − C(q, q̇)ᵀ q̇.  The latter follows from
  Lagrange's equations when Ṁ = C + Cᵀ (the Christoffel C, which the skew
  check verifies): ∂T/∂q = Ṁ q̇ − C q̇ = Cᵀ q̇.  Its two implicit stages are
  solved by fixed-point iteration to rounding level.  Symplectic, so the energy
  error stays bounded over long horizons.  Conservative models only.

The compiled counterparts on a model's generated code (``fixedstep``: Euler, symplectic
Euler, implicit midpoint, RK4) are other methods, or the same tableaux, for the
work–precision study; these run the model object itself, in Python, for the stress suite.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pendverify.numerics.integrators.runge_kutta import explicit_rk_step
from pendverify.numerics.integrators.tableaux import RK4

EPS = float(np.finfo(float).eps)
FIXED_POINT_MAX = 60  # iterations per implicit stage before giving up
FIXED_POINT_TOL = 1e-14  # relative update at which a stage counts as solved (rate ≲ 0.1: error ≲ 1e-15)
NEWTON_MAX = 30
BLOW_UP = 1e150  # a state entry beyond this counts as a blow-up
RK45_MAX_EVALUATIONS = 50_000  # RK45 gives up (and says so) beyond this


@dataclass
class IntegrationRecord:
    """One run of a model: recorded times and states, the work done, and where it blew up (if it did)."""

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    steps: int
    evaluations: int
    blew_up_at: int | None = None
    note: str = ""


def state_derivative_of(model):
    """x ↦ ẋ = (q̇, q̈) of the model's closed form, with no input and no disturbance."""
    u, w = np.zeros(len(model.inputs)), np.zeros(len(model.disturbances))

    def f(x):
        n = model.nv
        return np.concatenate([x[n:], model.acceleration(x[:n], x[n:], u, w)])

    return f


def _finite(x) -> bool:
    return bool(np.all(np.isfinite(x)) and np.max(np.abs(x)) < BLOW_UP)


class _Recorder:
    def __init__(self, n_dof: int, x0: np.ndarray, record: int):
        self.n, self.record = n_dof, record
        self.t, self.x = [0.0], [x0.copy()]

    def add(self, step: int, t: float, x: np.ndarray, force: bool = False) -> None:
        if force or step % self.record == 0:
            self.t.append(t)
            self.x.append(x.copy())

    def finish(self, steps, evaluations, blew_up_at=None, note="") -> IntegrationRecord:
        X = np.array(self.x)
        return IntegrationRecord(
            np.array(self.t), X[:, : self.n], X[:, self.n :], steps, evaluations, blew_up_at, note
        )


def rk4(model, q0, v0, h: float, n: int, record: int = 1) -> IntegrationRecord:
    f = state_derivative_of(model)

    def rhs(t, x):
        return f(x)

    x = np.concatenate([q0, v0]).astype(float)
    rec = _Recorder(model.nv, x, record)
    evaluations = 0
    with np.errstate(all="ignore"):
        for i in range(1, n + 1):
            try:
                x = explicit_rk_step(rhs, (i - 1) * h, x, h, RK4)
            except (ValueError, OverflowError, np.linalg.LinAlgError):
                x = np.full_like(x, np.nan)
            evaluations += RK4.stages
            if not _finite(x):
                return rec.finish(i, evaluations, blew_up_at=i, note=f"non-finite after {i} steps")
            rec.add(i, i * h, x, force=i == n)
    return rec.finish(n, evaluations)


class _TooMuchWork(Exception):
    pass


def rk45(model, q0, v0, t_end: float, rtol: float = 1e-6, atol: float = 1e-9) -> IntegrationRecord:
    """SciPy's RK45; stops at a blow-up (|x| > ``BLOW_UP``) or after ``RK45_MAX_EVALUATIONS``."""
    from scipy.integrate import solve_ivp

    f = state_derivative_of(model)
    x0 = np.concatenate([q0, v0]).astype(float)
    count = [0]

    def fun(t, x):
        count[0] += 1
        if count[0] > RK45_MAX_EVALUATIONS:
            raise _TooMuchWork
        with np.errstate(all="ignore"):
            try:
                return f(x)
            except (ValueError, OverflowError, np.linalg.LinAlgError):
                return np.full_like(x, np.nan)

    def blow_up(t, x):
        return BLOW_UP - float(np.max(np.abs(x))) if np.all(np.isfinite(x)) else -1.0

    blow_up.terminal = True
    n = model.nv
    try:
        sol = solve_ivp(fun, (0.0, t_end), x0, method="RK45", rtol=rtol, atol=atol, events=blow_up)
    except _TooMuchWork:
        empty = np.empty((0, n))
        note = f"gave up after {RK45_MAX_EVALUATIONS} evaluations"
        return IntegrationRecord(np.empty(0), empty, empty, -1, count[0], blew_up_at=-1, note=note)
    blew_up = sol.status != 0 or not np.all(np.isfinite(sol.y))
    steps = len(sol.t) - 1
    return IntegrationRecord(
        sol.t,
        sol.y[:n].T,
        sol.y[n:].T,
        steps,
        sol.nfev,
        blew_up_at=steps if blew_up else None,
        note=sol.message,
    )


def jacobian(f, x: np.ndarray) -> np.ndarray:
    """∂f/∂x by central differences, steps ∛ε·max(1, |x_i|)."""
    J = np.empty((x.size, x.size))
    for i in range(x.size):
        d = EPS ** (1 / 3) * max(1.0, abs(x[i]))
        e = np.zeros(x.size)
        e[i] = d
        J[:, i] = (f(x + e) - f(x - e)) / (2 * d)
    return J


def implicit_euler(model, q0, v0, h: float, n: int, record: int = 1, tol: float = 1e-13) -> IntegrationRecord:
    """Backward Euler; Newton on G(x₊) = x₊ − x − h F(x₊) with a Jacobian per step."""
    f = state_derivative_of(model)
    x = np.concatenate([q0, v0]).astype(float)
    rec = _Recorder(model.nv, x, record)
    evaluations = 0
    eye = np.eye(x.size)
    for i in range(1, n + 1):
        J = eye - h * jacobian(f, x)
        evaluations += 2 * x.size
        y = x.copy()
        for _ in range(NEWTON_MAX):
            G = y - x - h * f(y)
            evaluations += 1
            dy = np.linalg.solve(J, G)
            y = y - dy
            if np.max(np.abs(dy)) <= tol * (1.0 + np.max(np.abs(y))):
                break
        else:
            return rec.finish(i, evaluations, blew_up_at=i, note=f"Newton did not converge at step {i}")
        x = y
        if not _finite(x):
            return rec.finish(i, evaluations, blew_up_at=i, note=f"non-finite after {i} steps")
        rec.add(i, i * h, x, force=i == n)
    return rec.finish(n, evaluations)


def _fixed_point(g, x0: np.ndarray) -> tuple[np.ndarray, int]:
    """Iterate x = g(x) until the update is at rounding level (or stops shrinking)."""
    x, last = x0, np.inf
    for k in range(1, FIXED_POINT_MAX + 1):
        x_new = g(x)
        change = float(np.max(np.abs(x_new - x)))
        x = x_new
        if change <= FIXED_POINT_TOL * (1.0 + float(np.max(np.abs(x)))) or (change >= last and k > 3):
            return x, k
        last = change
    return x, FIXED_POINT_MAX


def stormer_verlet(model, q0, v0, h: float, n: int, record: int = 1) -> IntegrationRecord:
    """Generalized leapfrog in (q, p); needs a conservative model (D = 0)."""
    if np.any(model.damping_matrix() != 0):
        raise ValueError("stormer_verlet integrates conservative models only (D = 0)")
    q = np.asarray(q0, dtype=float).copy()
    p = model.mass_matrix(q) @ np.asarray(v0, dtype=float)
    rec = _Recorder(model.nv, np.concatenate([q, v0]), record)
    evaluations = 0

    def velocity(q, p):
        return np.linalg.solve(model.mass_matrix(q), p)

    for i in range(1, n + 1):
        # stage 1: p½ = p − h/2 ∂H/∂q(q, p½), with M(q)⁻¹ and H(q) fixed
        M_inv, H = np.linalg.inv(model.mass_matrix(q)), model.gravity(q)

        def dH_dq_here(ph, M_inv=M_inv, H=H, q=q):
            v = M_inv @ ph
            return H - model.coriolis_matrix(q, v).T @ v

        p_half, k1 = _fixed_point(lambda ph, p=p: p - 0.5 * h * dH_dq_here(ph), p - 0.5 * h * dH_dq_here(p))
        # stage 2: q₊ = q + h/2 (M(q)⁻¹ + M(q₊)⁻¹) p½
        v_start = M_inv @ p_half
        q_new, k2 = _fixed_point(
            lambda qn, q=q, ph=p_half, vs=v_start: q + 0.5 * h * (vs + velocity(qn, ph)), q + h * v_start
        )
        # stage 3, explicit: p₊ = p½ − h/2 ∂H/∂q(q₊, p½)
        v_end = velocity(q_new, p_half)
        p = p_half - 0.5 * h * (model.gravity(q_new) - model.coriolis_matrix(q_new, v_end).T @ v_end)
        q = q_new
        evaluations += k1 + k2 + 2
        x = np.concatenate([q, p])
        if not _finite(x):
            return rec.finish(i, evaluations, blew_up_at=i, note=f"non-finite after {i} steps")
        if i % record == 0 or i == n:
            rec.add(i, i * h, np.concatenate([q, velocity(q, p)]), force=True)
    return rec.finish(n, evaluations)
