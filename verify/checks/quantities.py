"""What each check measures: its error at one state and the scale that error is judged against.

Each function takes (model, Pinocchio system, state) and returns a ``Sample``: the
error e in scaled coordinates (``pendverify.checks.scaling``), the scale s (the size
of the terms that produced the quantity, including cancellation) and the known
model-form allowance a.  ``pendverify.checks.catalogue`` names them, gives each its
constant K and passes a state when e ≤ K·ε·((1 + |θ|max)·c_T + (A − 1))·s + a.

The scales:

* ``crba``: 1 (M̃ has entries of order one); ``gravity``: max w·(Σ|terms| of H).
* ``rnea``: (rates + max|D̃|)·Σ|ż| + the gravity scale: a hand C written with friction
  inside (C + D, as seed 000) rounds at the size of D̃ too.
* ``coriolis``, ``skew``: max(rates + max|D̃|, 1); Ṁ for ``skew`` comes from Pinocchio's
  analytic RNEA derivatives with gravity off, Ṁ e_j = ∂τ/∂q(q, 0, e_j)·q̇, which does
  not use its Coriolis matrix.
* ``det``: Π S_i (the determinant of the scaling).
* ``minverse``: ‖M̃⁻¹‖²‖M̃‖, since δ(M⁻¹) = −M⁻¹ δM M⁻¹ with |δM̃| ~ ε‖M̃‖.
* ``aba``: ‖M̃⁻¹‖(forces + ‖M̃‖‖q̈̃‖), forces the sum of |terms| acting.
* ``energy``: ½|ż|²‖M̃‖ + max(gravity scale); potential energies compared as
  V(q) − V(0), since they agree up to a constant.
* ``damping``: the larger of max|D̃| and max|D̃_urdf|, D_urdf = Tᵀ·diag(b)·T.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pendverify.checks.scaling import damping_rate, force_scale, norm2, rate_scale, scaled_matrix, weights


@dataclass(frozen=True)
class Sample:
    error: float
    scale: float
    allowance: float = 0.0
    note: str = ""


def _allowance(system) -> np.ndarray:
    return system.allowance


# --- the checks ---------------------------------------------------------------------------
def crba(model, system, s):
    w = weights(model, s.q)
    err = np.max(np.abs(scaled_matrix(system.mass_matrix(s.q) - model.mass_matrix(s.q), w)))
    return Sample(err, 1.0)


def rnea(model, system, s):
    w = weights(model, s.q)
    err = np.max(w * np.abs(system.bias(s.q, s.v) - model.bias(s.q, s.v)))
    zdot = s.v / w
    scale = (rate_scale(model, s.q, s.v) + damping_rate(model, w)) * np.sum(np.abs(zdot)) + np.max(
        w * model.gravity_scale()
    )
    return Sample(err, scale, float(np.max(w * _allowance(system))))


def gravity(model, system, s):
    w = weights(model, s.q)
    err = np.max(w * np.abs(system.gravity(s.q) - model.gravity(s.q)))
    return Sample(err, float(np.max(w * model.gravity_scale())), float(np.max(w * _allowance(system))))


def coriolis(model, system, s):
    w = weights(model, s.q)
    diff = system.coriolis_matrix(s.q, s.v) - model.coriolis_matrix(s.q, s.v)
    rates = max(rate_scale(model, s.q, s.v) + damping_rate(model, w), 1.0)
    return Sample(np.max(np.abs(scaled_matrix(diff, w))), rates)


def skew(model, system, s):
    w = weights(model, s.q)
    N = system.mass_matrix_derivative(s.q, s.v) - 2 * model.coriolis_matrix(s.q, s.v)
    rates = max(rate_scale(model, s.q, s.v) + damping_rate(model, w), 1.0)
    return Sample(np.max(np.abs(scaled_matrix(N + N.T, w))), rates)


def det(model, system, s):
    scale = float(np.prod(model.diagonal_scale(s.q)))
    closed, lu = model.det_mass_matrix(s.q), system.det_mass_matrix(s.q)
    if not (closed > 0 and lu > 0):
        return Sample(np.inf, scale, note=f"det M not positive: closed form {closed:.3g}, LU {lu:.3g}")
    return Sample(abs(closed - lu), scale)


def minverse(model, system, s):
    sqrt_s = 1.0 / weights(model, s.q)
    diff = system.inverse_mass_matrix(s.q) - model.inverse_mass_matrix(s.q)
    Minv_scaled = scaled_matrix(model.inverse_mass_matrix(s.q), sqrt_s)
    M_scaled = scaled_matrix(model.mass_matrix(s.q), 1.0 / sqrt_s)
    # δ(M⁻¹) = −M⁻¹ δM M⁻¹ with |δM̃| ~ ε‖M̃‖
    scale = norm2(Minv_scaled) ** 2 * norm2(M_scaled)
    return Sample(np.max(np.abs(scaled_matrix(diff, sqrt_s))), scale)


def aba(model, system, s):
    w = weights(model, s.q)
    tau = model.input_matrix() @ s.u + model.disturbance_matrix() @ s.w - model.damping_matrix() @ s.v
    a_pin = system.acceleration(s.q, s.v, tau)
    a_hand = model.acceleration(s.q, s.v, s.u, s.w)
    Minv_norm = norm2(scaled_matrix(model.inverse_mass_matrix(s.q), 1.0 / w))
    M_norm = norm2(scaled_matrix(model.mass_matrix(s.q), w))
    scale = Minv_norm * (force_scale(model, s, w) + M_norm * np.max(np.abs(a_pin / w)))
    allowance = float(np.max(Minv_norm * np.max(w * _allowance(system))))
    return Sample(np.max(np.abs((a_pin - a_hand) / w)), scale, allowance)


def energy(model, system, s):
    w = weights(model, s.q)
    zero = np.zeros(model.nv)
    kinetic = abs(system.kinetic_energy(s.q, s.v) - model.kinetic_energy(s.q, s.v))
    # potential energies agree up to a constant: compare differences from θ = 0
    dv_pin = system.potential_energy(s.q) - system.potential_energy(zero)
    dv_hand = model.potential_energy(s.q) - model.potential_energy(zero)
    kinetic_scale = 0.5 * float(np.sum((s.v / w) ** 2)) * norm2(scaled_matrix(model.mass_matrix(s.q), w))
    potential_scale = float(np.max(model.gravity_scale()))
    allowance = 2 * float(np.sum(_allowance(system)))  # |ΔV| ≤ m g |offset| at both ends
    return Sample(kinetic + abs(dv_pin - dv_hand), kinetic_scale + potential_scale, allowance)


def damping(model, system, s):
    """The URDF's <dynamics damping> seen in the model's coordinates (Tᵀ·diag(b)·T) against D.

    Pinocchio keeps the damping but none of its algorithms applies it, so no other
    check can see a URDF whose damping disagrees with the hand model's D.
    """
    w = weights(model, s.q)
    D_urdf = system.cmap.matrix_to_model(np.diag(system.urdf_damping()))
    D = model.damping_matrix()
    diff = np.abs(scaled_matrix(D_urdf - D, w))
    scale = max(np.max(np.abs(scaled_matrix(D, w))), np.max(np.abs(scaled_matrix(D_urdf, w))))
    note = ""
    if np.max(diff) > 0:
        i, j = np.unravel_index(np.argmax(diff), diff.shape)
        names = model.coordinates
        note = (
            f"D[{names[i]},{names[j]}]: the URDF's <dynamics damping> gives {D_urdf[i, j]:.6g}, "
            f"the hand model {D[i, j]:.6g}"
        )
    return Sample(float(np.max(diff)), float(scale), note=note)
