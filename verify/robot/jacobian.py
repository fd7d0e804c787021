"""Pinocchio's joint Jacobians as 6 × nv arrays, whatever nv.

Pinocchio's Python bindings (eigenpy) hand a matrix of one column back as a 1-D array: on a
robot of one degree of freedom ``data.J`` and ``getJointJacobian`` are arrays of 6, and
``J[:, k]`` fails.  These functions always return shape (6, nv): rows 0–2 the linear part,
rows 3–5 the angular part (Pinocchio's ordering), one column per velocity coordinate.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin


def joint_jacobians(model: pin.Model, data: pin.Data, q: np.ndarray) -> np.ndarray:
    """Every joint's motion at configuration ``q`` in the world frame (``data.J``), shape (6, nv)."""
    pin.computeJointJacobians(model, data, q)
    return np.reshape(data.J, (6, model.nv))


def joint_jacobian(model: pin.Model, data: pin.Data, j: int, reference=pin.LOCAL) -> np.ndarray:
    """Joint ``j``'s Jacobian in ``reference`` after ``computeJointJacobians``, shape (6, nv)."""
    return np.reshape(pin.getJointJacobian(model, data, j, reference), (6, model.nv))
