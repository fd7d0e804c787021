"""The inertia-tensor rules of a URDF, within the rounding of the digits as written.

Used by ``pendverify.robot.strict``: each inertia tensor I is positive semi-definite and
its principal moments λ1 ≥ λ2 ≥ λ3 satisfy the triangle inequality λ1 ≤ λ2 + λ3 (for a
rigid body λ_i = ∫(r² − x_i²) dm, so λ2 + λ3 − λ1 = 2∫x_1² dm ≥ 0).

Tolerance of the tensor rules.  The file holds the tensor rounded to the digits
written, so a correct body rounded to 4 digits (a thin rod, 1/6, 1/12, 1/12, written
``0.1667 0.0833 0.0833``: 0.1667 > 0.1666) must pass.  A written decimal with ``f``
digits after the point and exponent ``E`` stands for some value within
r = ½·10^(E−f) of it ("0.1667" → 5e-5, "1e-3" → ½·10^-3 = 5e-4, "2.5E-06" → 5e-8).
A written zero is taken to lie on the grid of its tensor's other entries: its r is
the smaller of its own half unit and the largest r among the tensor's non-zero
entries, and 0 when all entries are zero ("0" and Python's "0.0" mark entries that
are zero by symmetry; their own half unit, 0.5 or 0.05, would swamp a tensor of size
0.02).  Let R be the symmetric 3×3 matrix of these r.  The true tensor is I + E with
|E_ij| ≤ R_ij, so ‖E‖₂ ≤ ‖E‖_F ≤ ‖R‖_F, and by Weyl's inequality every eigenvalue of
I + E lies within ‖E‖₂ of the matching eigenvalue of I.  Hence with
δ = ‖R‖_F + 16·ε·‖I‖_F (the second term covers the decimal → double conversion,
≤ ε/2 per entry, and the backward error of the symmetric eigensolver, a small multiple
of ε‖I‖₂; ε is the double's machine epsilon) a file is refused only when no tensor
within its rounding is valid:

* positive semi-definite: require λ3 ≥ −δ;
* triangle inequality: λ1 − λ2 − λ3 moves by at most 3δ, so require
  λ1 ≤ λ2 + λ3 + 3δ (checking the largest moment is enough: the other two
  inequalities then hold with room to spare).

The bound is loose for coarsely written numbers ("0.1" carries ±0.05), so a violation
shows only when the written digits resolve it; that is the price of never refusing a
correct but rounded file.
"""

from __future__ import annotations

import math

import numpy as np

from pendverify.errors import UrdfShapeError
from pendverify.robot.urdf_numbers import DECIMAL

_EPS = float(np.finfo(float).eps)
#: Multiple of ε·‖I‖_F added to the rounding tolerance (conversion + eigensolver error).
FLOAT_SLACK = 16.0


def resolution(literal: str) -> float:
    """Half a unit in the last written digit of a decimal literal: "0.1667" → 5e-5, "2e-3" → 5e-4."""
    if not DECIMAL.fullmatch(literal):
        raise ValueError(f"not a decimal literal: {literal!r}")
    significand, _, exponent = literal.lower().partition("e")
    digits_after_point = len(significand.partition(".")[2])
    return float(f"5e{int(exponent or 0) - digits_after_point - 1}")


def inertia_tolerance(literals: dict[str, str]) -> float:
    """δ of the module docstring for the six written entries ``{ixx: "0.1667", ...}``."""
    values = {k: float(v) for k, v in literals.items()}
    own = {k: resolution(v) for k, v in literals.items()}
    nonzero = [own[k] for k in literals if values[k] != 0.0]
    grid = max(nonzero, default=0.0)
    r = {k: own[k] if values[k] != 0.0 else min(own[k], grid) for k in literals}
    R = _tensor(r)
    I = _tensor(values)  # noqa: E741 (the inertia tensor's usual name)
    return _frobenius(R) + FLOAT_SLACK * _EPS * _frobenius(I)


def _frobenius(tensor: np.ndarray) -> float:
    """‖T‖_F without overflow in the squares (``math.hypot`` scales): finite for entries near 1e300."""
    return math.hypot(*tensor.ravel().tolist())


def _tensor(v: dict[str, float]) -> np.ndarray:
    return np.array(
        [
            [v["ixx"], v["ixy"], v["ixz"]],
            [v["ixy"], v["iyy"], v["iyz"]],
            [v["ixz"], v["iyz"], v["izz"]],
        ]
    )


def check_inertia_tensor(literals: dict[str, str], place: object, source: str) -> None:
    """Refuse a tensor no tensor within its written rounding makes valid (``UrdfShapeError``).

    ``literals`` are the six attributes as written (``{"ixx": "0.1667", ...}``); ``place``
    names the element in the message.
    """
    tensor = _tensor({k: float(v) for k, v in literals.items()})
    delta = inertia_tolerance(literals)
    # Weyl: each eigenvalue of the true tensor is within δ of one of these (see module docstring).
    moments = sorted(np.linalg.eigvalsh(tensor).tolist(), reverse=True)
    shown = "(" + ", ".join(f"{m:.6g}" for m in moments) + ")"
    big, mid, small = moments
    if small < -delta:
        raise UrdfShapeError(
            source,
            f"{place}: principal moments {shown} include a negative one, {small:.6g} "
            f"(an inertia tensor must be positive semi-definite)",
        )
    if big > mid + small + 3 * delta:
        raise UrdfShapeError(
            source,
            f"{place}: principal moments {shown} violate the triangle inequality "
            f"{big:.6g} ≤ {mid:.6g} + {small:.6g} (a rigid body's moments must satisfy it)",
        )
