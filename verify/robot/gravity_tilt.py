"""A description's gravity not along −z: the part a closed form with a scalar g cannot express.

A closed form's H has one scalar g along −z.  A description may set any vector γ (an MJCF's
``<option gravity>``: gymnasium's double pendulum has 1e-5 0 −9.81).  Pinocchio is evaluated
with γ as the file gives it; the closed form's g is −γ_z, and the tilt t = (γ_x, γ_y, 0) is a
term the closed form has no place for.  It is treated as a ``ModelForm``
(``pendverify.robot.geometry``), the way an off-line centre of mass is.

Size.  Generalized gravity is linear in the gravity vector: H(q; γ) = −Σ_b m_b J_b(q)ᵀ γ, with
J_b the Jacobian of body b's centre of mass.  So the tilt adds ΔH(q) = −Σ_b m_b J_b(q)ᵀ t, and
per joint coordinate i
    |ΔH_i| ≤ |t| Σ_{joints k at or below i} m_k ρ_ik,
where m_k is the mass carried by joint k and ρ_ik bounds |∂c_k/∂q_i| over every configuration:
1 for a slide i; for a hinge i, the distance from its axis to k's centre of mass, at most the
lengths of the joint placements from i down to k plus |c_k| in k's frame.  (A slide between a
hinge i and k makes that distance unbounded: the bound is then infinite, and the tilt is
outside any threshold.)  The same sum with |γ_z| in place of |t| bounds the size of the closed
form's H_i, so the tilt's size relative to H is |t| / |γ_z| on every coordinate.  In the
model's coordinates θ (q = T (θ − θ0), ``pendverify.robot.coordinates``) H_θ = Tᵀ H_q, so the
allowance per coordinate is |T|ᵀ times the joint-coordinate bound.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from pendverify.robot.coordinates import CoordinateMap
from pendverify.robot.geometry import ModelForm


def tilt_form(model: pin.Model, cmap: CoordinateMap, gravity) -> ModelForm | None:
    """The tilt of ``gravity`` (the file's vector, [m/s²]) as a model form; None if it has none."""
    gx, gy, gz = (float(x) for x in gravity)
    tilt = math.hypot(gx, gy)
    if tilt == 0:
        return None
    bound = np.array([_lever_sum(model, i) for i in range(1, model.njoints)])
    with np.errstate(invalid="ignore"):
        allowance = (
            tilt * (np.abs(cmap.T).T @ bound) if np.all(np.isfinite(bound)) else np.full(model.nv, np.inf)
        )
    relative = tilt / abs(gz) if gz != 0 else math.inf
    degrees = math.degrees(math.atan2(tilt, -gz))
    return ModelForm(
        f"the file's gravity ({gx:g}, {gy:g}, {gz:g}) m/s² is tilted {degrees:.3g}° from −z; the closed "
        f"form's g is its −z part {-gz:g} m/s² and its H has no term for the tilt |t| = {tilt:.3g} m/s²: "
        f"up to {float(np.max(allowance)):.3g} on H",
        float(relative),
        allowance,
        enters="H",
        outside="the file's gravity is not the model's (the closed form has g along −z only)",
        potential_grows=True,  # −Σ m t·c grows with a slide's travel
    )


def _lever_sum(model: pin.Model, i: int) -> float:
    """Σ_k m_k ρ_ik over joint i and the joints below it (see the module docstring)."""
    slide = model.joints[i].shortname().startswith(("JointModelP", "JointModelPrismatic"))
    total = 0.0
    for k in range(i, model.njoints):
        path, length, bounded = k, 0.0, True
        while path != i and path != 0:
            length += float(np.linalg.norm(model.jointPlacements[path].translation))
            if model.joints[path].shortname().startswith(("JointModelP", "JointModelPrismatic")):
                bounded = False
            path = model.parents[path]
        if path != i:
            continue  # k is not below i
        inertia = model.inertias[k]
        if slide:
            total += inertia.mass
        elif not bounded and inertia.mass > 0:
            return math.inf
        else:
            total += inertia.mass * (length + float(np.linalg.norm(inertia.lever)))
    return total
