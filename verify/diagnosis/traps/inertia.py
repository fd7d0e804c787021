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
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin

from pendverify.checks.batch import CheckBatch
from pendverify.diagnosis.finding import Finding
from pendverify.diagnosis.traps.fit import FIT_RESIDUAL, fit_words
from pendverify.robot.coordinates import CoordinateMap
from pendverify.robot.system import PinocchioSystem

COEFF_TOL = 1e-3  # how close a fitted coefficient must be to an integer


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
    mr2 = {n: float(np.max(np.abs(k))) for n, k in zip(names, at_zero, strict=True)}
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
    details = {"links": {n: int(c) for n, c in zip(names, rounded, strict=True) if c}, "residual": residual}
    return Finding(kind="convention", message="; ".join(parts), quantity="M", details=details)
