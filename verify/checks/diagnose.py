"""Name the known trap behind a failure, in words next to the numbers.

When checks fail, each hypothesis below is tested against the model and the
URDF, and the ones that explain the failure become a sentence in the report
that says how well they fit: the *residual*, the part of the discrepancy the
hypothesis leaves unexplained, relative to the whole.  A residual at rounding
level (≤ ``EXACT_RESIDUAL``) is an exact fit; up to ``FIT_RESIDUAL`` (1e-3) the
trap is named with its residual and the sentence says that a smaller
difference remains (a URDF rotation written as 3.1416 for π leaves 7e-6);
beyond it the hypothesis is not named.

Never a wrong diagnosis: a trap of these kinds changes M or H by a relative
amount of order one (a degree is 1.7e-2), so a failure smaller than
``TRAP_MIN_ERROR`` (1e-6, relative) is never blamed on one — and states
beyond the trust limit (``pendverify.checks.trust``) are refused before any
check or diagnosis sees them.

pivot inertia (``crba`` fails)
    M_urdf − M_hand is fitted by Σ_b c_b K_b, where K_b is body b's parallel-axis
    term m_b (|c_b|² 𝟙 − c_b c_bᵀ) (c_b its centre of mass in its joint frame)
    seen through its angular-velocity Jacobian: the m·r² that separates an
    inertia about the pivot from one about the centre of mass.  c_b = +1: the
    URDF's inertia is about the pivot; c_b = −1: the hand model adds m·r² to an
    inertia already about the pivot.
missing damping (``aba`` fails)
    r = M_hand (q̈_hand − q̈_pin) is fitted by X q̇ with a constant matrix X over
    the moving states.  X = D: the hand q̈ lacks the friction D q̇; X = 2D: the
    friction has the wrong sign; X a part of D: those terms are missing; X not
    in D: the q̈ carries friction that ``damping_matrix`` does not declare.
coordinate conventions (any check fails)
    the coordinate map q = T (θ − θ0) is changed as each trap would change it,
    and the change is adopted when every check then passes on a small state set:
    absolute vs relative angles (T → T·A or T·A⁻¹, A the difference matrix of
    consecutive angles), degrees vs radians (θ0 read as degrees; angles scaled by
    π/180), an angle zero measured from the vertical instead of the horizontal
    (θ0 shifted by ±π/2, on one angle or on all), and from hanging instead of
    upright (±π).
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pinocchio as pin

from pendverify.checks.catalogue import applicable_checks, run_checks
from pendverify.checks.sampling import sample_states
from pendverify.robot.coordinates import CoordinateMap
from pendverify.robot.system import PinocchioSystem

FIT_RTOL = 1e-6  # relative residual of the damping fit that counts as exact
EXACT_RESIDUAL = 1e-9  # a residual at rounding level (of the fitted data, ~1e-15, with margin)
FIT_RESIDUAL = 1e-3  # the most a named trap may leave unexplained
TRAP_MIN_ERROR = 1e-6  # smallest relative failure a convention or inertia trap can cause
COEFF_TOL = 1e-3  # how close a fitted coefficient must be to an integer
DIAGNOSIS_STATES = 8  # random states per hypothesis, besides the special ones
DIAGNOSIS_SEED = 4242


def _states(model):
    return sample_states(model, DIAGNOSIS_STATES, DIAGNOSIS_SEED)


def _fmt(values) -> str:
    return "(" + ", ".join(f"{x:.6g}" for x in values) + ")"


def _fit(residual: float) -> str:
    """How well a pattern fits, in words, with its residual."""
    if residual <= EXACT_RESIDUAL:
        return "exactly"
    return f"up to a relative residual of {residual:.2g} (a smaller difference remains as well)"


def _largest_failure(results) -> float:
    return max((r.max_error for r in results if not r.passed), default=0.0)


# --- pivot inertia ---------------------------------------------------------------------------
def _parallel_axis_terms(system: PinocchioSystem, theta) -> dict[str, np.ndarray]:
    """{body: its m·r² term of M in the model's coordinates} at θ, for bodies that turn."""
    model, data = system.model, system.data
    q = system.cmap.configuration(theta)
    pin.computeJointJacobians(model, data, q)
    out = {}
    for j in range(1, model.njoints):
        inertia = model.inertias[j]
        c = np.asarray(inertia.lever)
        shift = inertia.mass * (float(c @ c) * np.eye(3) - np.outer(c, c))
        J = pin.getJointJacobian(model, data, j, pin.ReferenceFrame.WORLD)[3:, :]
        R = data.oMi[j].rotation
        K = J.T @ R @ shift @ R.T @ J
        if np.max(np.abs(K)) > 0:
            out[_link_name(model, j)] = system.cmap.matrix_to_model(K)
    return out


def _link_name(model: pin.Model, joint: int) -> str:
    """The URDF link a joint moves (the first body frame on it), with the joint's name."""
    for frame in model.frames:
        if frame.type == pin.FrameType.BODY and frame.parentJoint == joint:
            return f"{frame.name} (joint {model.names[joint]})"
    return f"the body of joint {model.names[joint]}"


def pivot_inertia(model, system, failing, states) -> str | None:
    if "crba" not in failing:
        return None
    rows, target = [], []
    names: list[str] = []
    for s in states:
        terms = _parallel_axis_terms(system, s.q)
        names = list(terms)
        if not names:
            return None
        rows.append(np.column_stack([terms[n].ravel() for n in names]))
        target.append((system.mass_matrix(s.q) - model.mass_matrix(s.q)).ravel())
    A, b = np.vstack(rows), np.concatenate(target)
    if not np.linalg.norm(b) > 0:
        return None
    coeff, *_ = np.linalg.lstsq(A, b, rcond=None)
    rounded = np.round(coeff)
    if np.any(np.abs(coeff - rounded) > COEFF_TOL) or not np.any(rounded) or np.any(np.abs(rounded) > 1):
        return None
    residual = float(np.linalg.norm(A @ rounded - b) / np.linalg.norm(b))
    if residual > FIT_RESIDUAL:
        return None
    fit = _fit(residual)
    mr2 = {n: float(np.max(np.abs(_parallel_axis_terms(system, np.zeros(model.nv))[n]))) for n in names}
    plus = [n for n, c in zip(names, rounded, strict=True) if c > 0]
    minus = [n for n, c in zip(names, rounded, strict=True) if c < 0]
    parts = []
    if plus:
        parts.append(
            f"M_urdf − M_hand is {fit} the parallel-axis term m·r² of {', '.join(plus)} "
            f"(m·r² = {', '.join(f'{mr2[n]:.6g} kg·m²' for n in plus)}): inertia given about the pivot "
            "instead of the centre of mass — a URDF <inertia> is about the centre of mass, "
            "I_com = I_pivot − m·r²"
        )
    if minus:
        parts.append(
            f"M_hand − M_urdf is {fit} the parallel-axis term m·r² of {', '.join(minus)} "
            f"(m·r² = {', '.join(f'{mr2[n]:.6g} kg·m²' for n in minus)}): the hand model adds m·r² to an "
            "inertia that is already about the pivot (I_pivot = I_com + m·r², counted twice)"
        )
    return "; ".join(parts)


# --- missing damping -------------------------------------------------------------------------
def missing_damping(model, system, failing, states) -> str | None:
    if "aba" not in failing:
        return None
    moving = [s for s in states if np.any(s.v != 0)]
    if len(moving) < model.nv + 1:
        return None
    rows, target = [], []
    for s in moving:
        tau = model.input_matrix() @ s.u + model.disturbance_matrix() @ s.w - model.damping_matrix() @ s.v
        diff = model.acceleration(s.q, s.v, s.u, s.w) - system.acceleration(s.q, s.v, tau)
        target.append(model.mass_matrix(s.q) @ diff)
        rows.append(s.v)
    V, R = np.array(rows), np.array(target)
    X, *_ = np.linalg.lstsq(V, R, rcond=None)  # R ≈ V Xᵀ: r = X q̇
    X = X.T
    if np.linalg.norm(V @ X.T - R) > FIT_RTOL * np.linalg.norm(R) or np.max(np.abs(X)) == 0:
        return None
    D = model.damping_matrix()
    scale = max(float(np.max(np.abs(D))), float(np.max(np.abs(X))))
    X[np.abs(X) < FIT_RTOL * scale] = 0.0
    names = model.coordinates
    where = [(i, j) for i in range(model.nv) for j in range(model.nv) if X[i, j] != 0]
    terms = ", ".join(f"{X[i, j]:.6g}·d{names[j]}/dt on {names[i]}" for i, j in where)
    if np.allclose(X, D, rtol=FIT_RTOL, atol=0) and np.any(D):
        return (
            f"a missing damping term: M·(q̈_hand − q̈_pin) = D·q̇ exactly ({terms}): the hand model's q̈ "
            "leaves out the friction −D·q̇ that damping_matrix() declares"
        )
    if np.allclose(X, 2 * D, rtol=FIT_RTOL, atol=0) and np.any(D):
        return f"damping with the wrong sign: M·(q̈_hand − q̈_pin) = 2·D·q̇ exactly ({terms})"
    if all(abs(X[i, j] - D[i, j]) <= FIT_RTOL * abs(D[i, j]) for i, j in where):
        return (
            f"a missing damping term: M·(q̈_hand − q̈_pin) = {terms} exactly, part of D: the hand model's q̈ "
            "leaves out that friction"
        )
    return (
        f"a damping mismatch: M·(q̈_hand − q̈_pin) = {terms} exactly, which damping_matrix() does not "
        f"declare (D = {D.tolist()}): the q̈ carries friction the model's D lacks, or the reverse"
    )


# --- coordinate conventions ------------------------------------------------------------------
def _with_map(system: PinocchioSystem, T, theta0) -> PinocchioSystem:
    cmap = CoordinateMap(np.asarray(T, float), np.asarray(theta0, float), system.cmap.joint_nq)
    return system.with_map(cmap)


def _discrepancy(model, system, states) -> tuple[float, bool]:
    """(largest relative error of crba and gravity, whether every applicable check passes)."""
    quick_names = ("crba", "gravity")
    quick = run_checks("diagnosis", model, system, states, DIAGNOSIS_SEED, names=quick_names)
    largest = max(r.max_error for r in quick)
    if not all(r.passed for r in quick):
        return largest, False
    rest = [n for n in applicable_checks(model, system) if n not in quick_names]  # crba, gravity done
    return largest, all(
        r.passed for r in run_checks("diagnosis", model, system, states, DIAGNOSIS_SEED, rest)
    )


def _difference_matrix(model) -> np.ndarray:
    """A with θ_rel = A θ_abs over the angular coordinates, in order."""
    A = np.eye(model.nv)
    angular = [i for i, a in enumerate(model.angular) if a]
    for prev, cur in itertools.pairwise(angular):
        A[cur, prev] = -1.0
    return A


def _map_candidates(model, system):
    """(sentence, T', θ0') for each convention trap."""
    T, theta0 = system.cmap.T, system.cmap.theta0
    angular = np.array(model.angular)
    if angular.sum() >= 2:
        A = _difference_matrix(model)
        A_inv = np.linalg.inv(A)
        yield (
            "absolute vs relative angles: the hand model's angles are absolute (all from one reference) "
            "where the coordinate map takes them as relative (each from the previous link); with "
            f"θ_rel = A·θ_abs, T → T·A = {(T @ A).tolist()}, every check passes",
            T @ A,
            A_inv @ theta0,
        )
        yield (
            "absolute vs relative angles: the hand model's angles are relative (each from the previous "
            "link) where the coordinate map takes them as absolute; with T → T·A⁻¹ = "
            f"{(T @ A_inv).tolist()}, every check passes",
            T @ A_inv,
            A @ theta0,
        )
    deg = math.pi / 180
    if np.any(theta0[angular] != 0):
        fixed = np.where(angular, theta0 * deg, theta0)
        yield (
            f"degrees vs radians: the offsets θ0 = {_fmt(theta0[angular])} look like degrees; read as "
            f"degrees, θ0 = {_fmt(fixed[angular])} rad, and every check passes "
            "(angles are radians throughout)",
            T,
            fixed,
        )
        nonzero = [i for i in np.flatnonzero(angular) if theta0[i] != 0]
        for i in nonzero if len(nonzero) >= 2 else ():
            one = theta0.copy()
            one[i] = theta0[i] * deg
            yield (
                f"degrees vs radians: the offset of {model.coordinates[i]}, {theta0[i]:.6g}, is in degrees "
                f"while the others are in radians; read as {one[i]:.6g} rad, every check passes",
                T,
                one,
            )
    S = np.diag(np.where(angular, deg, 1.0))
    yield (
        "degrees vs radians: the hand model's angles behave as degrees; scaled by π/180 every check passes",
        T @ S,
        np.linalg.inv(S) @ theta0,
    )
    subsets = [[i] for i in np.flatnonzero(angular)]
    if angular.sum() >= 2:
        subsets.append(list(np.flatnonzero(angular)))
    for shift, what in ((math.pi / 2, "vertical vs horizontal zero"), (math.pi, "upright vs hanging zero")):
        for subset in subsets:
            for sign in (1.0, -1.0):
                offset = np.zeros(model.nv)
                offset[subset] = sign * shift
                which = ", ".join(model.coordinates[i] for i in subset)
                plane = (
                    "measured from the vertical where the map measures from the horizontal, or the reverse"
                    if shift < 3
                    else "measured from hanging where the map measures from upright, or the reverse"
                )
                yield (
                    f"{what}: {which} {'is' if len(subset) == 1 else 'are'} {plane}; with θ0 shifted by "
                    f"{'+' if sign > 0 else '−'}{'π/2' if shift < 3 else 'π'} on {which} every check passes",
                    T,
                    theta0 + offset,
                )


def coordinate_conventions(model, system, failing, states) -> str | None:
    before, _ = _discrepancy(model, system, states)
    if not before > 0:
        return None
    for sentence, T, theta0 in _map_candidates(model, system):
        if abs(np.linalg.det(T)) < 1e-12:
            continue
        after, every_check_passes = _discrepancy(model, _with_map(system, T, theta0), states)
        residual = after / before
        if every_check_passes:
            fit = "an exact fit" if residual <= EXACT_RESIDUAL else "a fit within the tolerances"
            return f"{sentence} ({fit}: residual {residual:.2g} of the discrepancy)"
        if residual <= FIT_RESIDUAL:
            return (
                sentence.replace("every check passes", f"all but {residual:.2g} of the discrepancy goes")
                + "; a smaller difference remains as well"
            )
    return None


HYPOTHESES = (pivot_inertia, missing_damping, coordinate_conventions)


def diagnose(model, system, results) -> list[str]:
    """One sentence per known trap that explains the failing checks, with how well it fits."""
    failing = {r.check for r in results if not r.passed}
    if not failing:
        return []
    # a convention or inertia trap changes M or H by O(1): never blame one for a rounding-size failure
    hypotheses = HYPOTHESES if _largest_failure(results) >= TRAP_MIN_ERROR else (missing_damping,)
    states = _states(model)
    out = []
    with np.errstate(all="ignore"):
        for hypothesis in hypotheses:
            sentence = hypothesis(model, system, failing, states)
            if sentence:
                out.append(sentence)
    return out
