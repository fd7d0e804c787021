"""Trap: an inertia about the pivot where the centre of mass is meant (``crba`` fails).

M_urdf − M_hand is fitted by Σ_b c_b K_b, where K_b is body b's parallel-axis
term m_b (|c_b|² 𝟙 − c_b c_bᵀ) (c_b its centre of mass in its joint frame)
seen through its angular-velocity Jacobian: the m·r² that separates an
inertia about the pivot from one about the centre of mass.  c_b = +1: the
URDF's inertia is about the pivot; c_b = −1: the hand model adds m·r² to an
inertia already about the pivot.  The fitted coefficients must be integers in
{−1, 0, 1} within ``COEFF_TOL``, and the residual within ``FIT_RESIDUAL``
(``pendverify.diagnosis.traps.fit``).

K_b is Pinocchio's own CRBA on a copy of the model whose only inertia is body b's
term, a rotational inertia of zero mass at the joint origin: M is linear in the
bodies' spatial inertias, and that one contributes J_ωᵀ R (m (|c|² 𝟙 − c cᵀ)) Rᵀ J_ω.
The same copy with c_b·K_b taken off the body's own inertia is the URDF the fit
says was meant (``corrected_system``).

Which side is wrong
-------------------
M alone sees only M_urdf − M_hand, so each sign has two readings that give the same numbers:

* c_b = +1 (the hand's M lacks m·r²): your M misses the parallel-axis term (the URDF is right),
  or the URDF's <inertia> is about the pivot (your M is right);
* c_b = −1 (the hand's M has m·r² too many): your M adds it to an inertia already about the
  pivot, or the URDF's <inertia> is m·r² short (the term taken off an inertia already about
  the centre of mass).

Both are named unless the URDF itself rules one out.  The only reading that asks something of
the URDF's numbers is "the URDF's <inertia> is about the pivot": the body's inertia about its
centre of mass is then I_c − m(|c|²𝟙 − ccᵀ), and every body's moment of inertia about any axis
through its centre of mass is ∫ d² dm ≥ 0.  When that moment is negative about an axis the
body turns about, that reading is impossible and the hand model's side is named alone (a
uniform rod hung from its end: I_c = m·L²/12 < m·r² = m·L²/4; a point mass: I_c = 0).  Only
the axes the body turns about are asked (``turning_axes``): M depends on the inertia through
them alone, and a URDF's other moments are often placeholders.  The other readings are always
possible: the URDF's own inertia is a physical one (Pinocchio refuses any other), and adding
m·r² keeps it one.  A body on the boundary (a hoop hung from its rim: I_c = m·r²) is not ruled
out: the reading is decided only when the moment is below −``SIDE_MARGIN``·m·r², a margin that
covers the rounding of a URDF written with three significant digits (5e-3 of each of m, c and
I, so at most ~1.5e-2 of m·r² and of I_c).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin

from pendverify.checks.batch import CheckBatch
from pendverify.diagnosis.finding import Finding
from pendverify.diagnosis.traps.fit import FIT_RESIDUAL, fit_words
from pendverify.robot.coordinates import CoordinateMap
from pendverify.robot.jacobian import joint_jacobian
from pendverify.robot.system import PinocchioSystem

COEFF_TOL = 1e-3  # how close a fitted coefficient must be to an integer
#: how far below zero (relative to m·r²) the implied moment must be to rule a reading out (docstring)
SIDE_MARGIN = 2e-2
#: configurations the axes a body turns about are gathered at (random, seeded)
AXIS_CONFIGURATIONS = 4
AXIS_SEED = 4242


def _shift(inertia: pin.Inertia) -> np.ndarray:
    """m (|c|² 𝟙 − c cᵀ): the parallel-axis term from the centre of mass to the joint origin."""
    c = np.asarray(inertia.lever)
    return inertia.mass * (float(c @ c) * np.eye(3) - np.outer(c, c))


def _link_name(model: pin.Model, joint: int) -> str:
    """The URDF link a joint moves (the first body frame on it), with the joint's name."""
    for frame in model.frames:
        if frame.type == pin.FrameType.BODY and frame.parentJoint == joint:
            return f"{frame.name} (joint {model.names[joint]})"
    return f"the body of joint {model.names[joint]}"


def _with_model(system: PinocchioSystem, model: pin.Model, cmap: CoordinateMap | None = None):
    """``system`` with another Pinocchio model of the same URDF (and, if given, another map)."""
    geometry = system.geometry if cmap is None else dataclasses.replace(system.geometry, cmap=cmap)
    g = -float(system.model.gravity.linear[2])
    return PinocchioSystem(model, geometry, g, system.source, system.urdf, system.model_form_rtol)


def turning_axes(model: pin.Model, joint: int) -> np.ndarray:
    """An orthonormal basis (3, k) of the directions body ``joint`` turns about, in its joint frame:
    the span of its angular velocity's Jacobian (local frame) at ``AXIS_CONFIGURATIONS`` random
    configurations (a planar chain's body: its joint axis; a body on a spherical joint: all three)."""
    rng = np.random.default_rng(AXIS_SEED)
    data = model.createData()
    columns = []
    for _ in range(AXIS_CONFIGURATIONS):
        q = pin.integrate(model, pin.neutral(model), rng.uniform(-np.pi, np.pi, model.nv))
        pin.computeJointJacobians(model, data, q)
        columns.append(
            joint_jacobian(model, data, joint, pin.ReferenceFrame.LOCAL)[3:, :]
        )  # 6×nv, nv = 1 too
    u, s, _ = np.linalg.svd(np.hstack(columns))
    # the columns are unit axes or cross products of them: rank at rounding level of 1
    return u[:, : int(np.sum(s > 1e-9 * max(float(s[0]), 1.0)))] if s.size else np.zeros((3, 0))


def pivot_reading_moment(model: pin.Model, joint: int) -> tuple[float, float]:
    """(the smallest moment of inertia about an axis body ``joint`` turns about, through its centre of
    mass, if the URDF's <inertia> were about the pivot; m·r² about that axis) in kg·m² (module
    docstring, "Which side is wrong")."""
    inertia = model.inertias[joint]
    P = turning_axes(model, joint)
    if P.shape[1] == 0:
        return 0.0, 0.0
    shift = P.T @ _shift(inertia) @ P
    implied = P.T @ np.asarray(inertia.inertia) @ P - shift
    smallest = np.linalg.eigvalsh(implied)
    k = int(np.argmin(smallest))
    return float(smallest[k]), float(np.max(np.linalg.eigvalsh(shift)))


def pivot_reading_possible(model: pin.Model, joint: int) -> bool:
    """Whether the URDF's <inertia> of body ``joint`` can be an inertia about the pivot: the moment
    about the centre of mass it implies is not below −``SIDE_MARGIN``·m·r² (module docstring)."""
    moment, mr2 = pivot_reading_moment(model, joint)
    return moment >= -SIDE_MARGIN * mr2


def sides(model: pin.Model, joint: int, sign: int) -> str:
    """Which side the parallel-axis term of body ``joint`` is wrong on, in words: both readings, or
    the hand model's alone when the URDF rules its reading out (module docstring); ``sign`` +1 when
    the hand's M lacks m·r², −1 when it has it too many."""
    link = _link_name(model, joint).split(" (")[0]
    if sign < 0:
        return (
            "your M adds the parallel-axis term to an inertia already about the pivot (counted twice), "
            f"or the URDF's <inertia> of {link} is m·r² short (the term taken off an inertia already "
            "about the centre of mass)"
        )
    if pivot_reading_possible(model, joint):
        return (
            f"your M misses the parallel-axis term, or the URDF's <inertia> of {link} is about the pivot "
            "(a URDF <inertia> is about the centre of mass: I_com = I_pivot − m·r²)"
        )
    moment, _ = pivot_reading_moment(model, joint)
    return (
        f"your M misses the parallel-axis term (the URDF's <inertia> of {link} cannot be about the "
        f"pivot: about the centre of mass it would leave {link} a moment of inertia of {moment:.6g} "
        "kg·m² about the axis it turns about, and no body has one below zero)"
    )


def _joint_of(model: pin.Model, name: str) -> int:
    """The joint whose link ``_link_name`` names ``name``."""
    return next(j for j in range(1, model.njoints) if _link_name(model, j) == name)


def parallel_axis_systems(system: PinocchioSystem) -> list[tuple[str, PinocchioSystem]]:
    """(link name, ``system`` with only that body's parallel-axis term as inertia), per body with one.

    The second's M, at any states in ``system``'s coordinates, is the body's K_b.
    """
    out = []
    for j in range(1, system.model.njoints):
        shift = _shift(system.model.inertias[j])
        if not np.any(shift):
            continue
        model = system.model.copy()
        for k in range(1, model.njoints):
            model.inertias[k] = pin.Inertia.Zero()
        model.inertias[j] = pin.Inertia(0.0, np.zeros(3), shift)
        out.append((_link_name(system.model, j), _with_model(system, model)))
    return out


def parallel_axis_terms(system: PinocchioSystem, theta) -> tuple[list[str], np.ndarray]:
    """The links whose body turns at states θ (N, n), and their K_b there (nb, N, n, n)."""
    names, terms = [], []
    for name, only in parallel_axis_systems(system):
        K = only.at(theta).mass_matrix()
        if np.max(np.abs(K)) > 0:
            names.append(name)
            terms.append(K)
    n = system.model.nv
    return names, np.array(terms) if terms else np.zeros((0, len(theta), n, n))


def corrected_system(system: PinocchioSystem, coefficients: dict[str, float], cmap=None):
    """``system`` with c_b·(m (|c|² 𝟙 − c cᵀ)) taken off each named body's inertia (and map ``cmap``),
    or None when that leaves a body an inertia no body has (Pinocchio refuses one that is not
    positive): the correction is then not a physical explanation."""
    model = system.model.copy()
    for j in range(1, model.njoints):
        c = coefficients.get(_link_name(model, j), 0.0)
        if c:
            inertia = model.inertias[j]
            rotational = np.asarray(inertia.inertia) - c * _shift(inertia)
            try:
                model.inertias[j] = pin.Inertia(inertia.mass, np.asarray(inertia.lever), rotational)
            except RuntimeError:  # "The 3d inertia should be positive"
                return None
    return _with_model(system, model, cmap)


def integer_coefficients(coefficients: np.ndarray) -> np.ndarray:
    """Fitted c_b (rows, last axis) rounded to integers in {−1, 0, 1}; a row with an entry not within
    ``COEFF_TOL`` of one becomes zero (no pivot trap)."""
    rounded = np.round(coefficients)
    ok = np.all((np.abs(coefficients - rounded) <= COEFF_TOL) & (np.abs(rounded) <= 1), axis=-1)
    return np.where(ok[..., None], rounded, 0.0)


def pivot_inertia(model, system, failing, states) -> Finding | None:
    if "crba" not in failing:
        return None
    batch = CheckBatch(model, system, states)
    names, K = parallel_axis_terms(system, batch.Q)
    if not names:
        return None
    A = K.reshape(len(names), -1).T
    b = (batch.terms.M_pin - batch.terms.M_hand).ravel()
    if not np.linalg.norm(b) > 0 or not np.all(np.isfinite(b)):
        return None  # (a hand M not finite at a state is no inertia trap; LAPACK would refuse it)
    coeff, *_ = np.linalg.lstsq(A, b, rcond=None)
    rounded = integer_coefficients(coeff)
    if not np.any(rounded):
        return None
    residual = float(np.linalg.norm(A @ rounded - b) / np.linalg.norm(b))
    if residual > FIT_RESIDUAL:
        return None
    fit = fit_words(residual)
    _, at_zero = parallel_axis_terms(system, np.zeros((1, model.nv)))
    parts = []
    for name, c, k, seen in zip(names, rounded, at_zero, np.max(np.abs(K), axis=1), strict=True):
        if not c:
            continue
        mr2 = float(np.max(np.abs(k)))
        n = seen.shape[0]
        # the entries the term reaches at some state (rounding of the CRBA aside)
        where = [
            f"M[{i + 1},{j + 1}]" for i in range(n) for j in range(i, n) if seen[i, j] > 1e-12 * np.max(seen)
        ]
        verb = ("lacks" if len(where) == 1 else "lack") if c > 0 else ("has" if len(where) == 1 else "have")
        extra = "" if c > 0 else " too many"
        difference = "M_urdf − M_hand" if c > 0 else "M_hand − M_urdf"
        parts.append(
            f"{', '.join(where)} {verb} the parallel-axis term m·r² = {mr2:.6g} kg·m² of {name}{extra} "
            f"({difference} is {fit} that term): {sides(system.model, _joint_of(system.model, name), int(c))}"
        )
    details = {"links": {n: int(c) for n, c in zip(names, rounded, strict=True) if c}, "residual": residual}
    return Finding(kind="convention", message="; ".join(parts), quantity="M", details=details)
