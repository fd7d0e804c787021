"""Trap: an inertia about the pivot where the centre of mass is meant (``crba`` fails).

M_urdf − M_hand is fitted by Σ_b c_b K_b, where K_b is body b's parallel-axis
term m_b (|c_b|² 𝟙 − c_b c_bᵀ) (c_b its centre of mass in its joint frame)
seen through its angular-velocity Jacobian: the m·r² that separates an
inertia about the pivot from one about the centre of mass.  c_b = +1: the
URDF's inertia is about the pivot; c_b = −1: the hand model adds m·r² to an
inertia already about the pivot.  The fitted coefficients must be integers in
{−1, 0, 1} within ``COEFF_TOL``, and the residual within ``FIT_RESIDUAL``
(``pendverify.diagnosis.traps.fit``).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pendverify.diagnosis.traps.fit import FIT_RESIDUAL, fit_words
from pendverify.robot.system import PinocchioSystem

COEFF_TOL = 1e-3  # how close a fitted coefficient must be to an integer


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
    fit = fit_words(residual)
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
