"""Whether an MJCF orientation attribute (``quat``, ``euler``, ``axisangle``, ``xyaxes``,
``zaxis``) is the identity rotation, to a few units in the last place.

Used for a fixed root body, whose pose Pinocchio's MJCF reader drops: dropping an identity
rotation changes nothing.  Each form is reduced as MuJoCo reduces it (a quaternion and the
axes normalised; angles in the compiler's unit) and is the identity when what would rotate
is at most ``IDENTITY_TOL`` = 4 ulp of 1: a quaternion's vector part |v| ≤ 4 ulp (|w| ≈ 1,
either sign: q and −q are one rotation), an angle ≤ 4 ulp in radians, a normalised axis
within 4 ulp of its unit vector.  Such a rotation R has ‖R − I‖ ≤ 2·4 ulp, below the
rounding of any written coordinate, so "1 0 0 0" and "1 0 0 1e-17" are read as no rotation
and "0.9999 0 0 0.0141" (1.6°) is a rotation.
"""

from __future__ import annotations

import math

IDENTITY_TOL = 4 * 2.0**-52


def is_identity(attr: str, values: tuple[float, ...], degrees: bool) -> bool:
    """Whether ``attr = values`` (checked already for count and finiteness) rotates nothing."""
    scale = math.pi / 180 if degrees else 1.0
    if attr == "quat":
        norm = math.hypot(*values)
        return norm > 0 and math.hypot(*values[1:]) <= IDENTITY_TOL * norm
    if attr == "euler":
        return all(abs(a) * scale <= IDENTITY_TOL for a in values)
    if attr == "axisangle":
        return abs(values[3]) * scale <= IDENTITY_TOL
    if attr == "zaxis":
        return _along(values, 2)
    if attr == "xyaxes":
        x, y = values[:3], values[3:]
        norm_x = math.hypot(*x)
        if norm_x == 0 or not _along(x, 0):
            return False
        along = sum(a * b for a, b in zip(x, y, strict=True)) / norm_x**2
        return _along(tuple(b - along * a for a, b in zip(x, y, strict=True)), 1)
    return False


def _along(vector: tuple[float, ...], axis: int) -> bool:
    """Whether ``vector``, normalised, is within ``IDENTITY_TOL`` of the positive unit vector ``axis``."""
    norm = math.hypot(*vector)
    if norm == 0 or vector[axis] <= 0:
        return False
    return all(abs(v) <= IDENTITY_TOL * norm for i, v in enumerate(vector) if i != axis)
