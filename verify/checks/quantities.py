"""What each check measures: its error at every state of a batch and the scale it is judged against.

Each check's measure (``MEASURES``) reads the closed forms' and Pinocchio's quantities
from ``Terms`` — arrays with the batch axis first, each computed once for all states and
all checks (``pendverify.checks.batch``) — and returns the error e in scaled coordinates
(``pendverify.checks.scaling``), the scale s (the size of the terms that produced the
quantity, including cancellation) and the known model-form allowance a, one of each per
state.  ``pendverify.checks.catalogue`` names the checks, gives each its constant K and
passes a state when e ≤ K·ε·((1 + |θ|max)·c_T + (A − 1))·s + a.

The scales:

* ``crba``: 1 (M̃ has entries of order one); ``gravity``: max weights·(Σ|terms| of H).
* ``rnea``: (rates + max|D̃|)·Σ|ż| + the gravity scale: a hand C written with friction
  inside (C + D, as the double pendulum's derivation) rounds at the size of D̃ too.
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

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from pendverify.analytic.numeric_derivation import rounding_bounds
from pendverify.checks.scaling import (
    damping_rate_of,
    force_scale_of,
    mv,
    norms2,
    rates_of,
    scaled_matrix,
    total,
    weights_of,
)


@dataclass(frozen=True)
class Measure:
    """A check's measure at each state of a batch (arrays, batch axis first, or scalars for all).

    ``noted``: where a note is due; ``describe(i)`` writes it for state i.
    """

    error: object
    scale: object
    allowance: object = 0.0
    noted: object = False
    describe: Callable[[int], str] | None = None
    #: the error of each entry (batch axis first) whose largest is ``error``, where the
    #: quantity has entries (``pendverify.diagnosis.entries`` names those that differ)
    entries: object = None
    #: the relative rounding the model's own forms carry beyond a closed form's, added to the
    #: check's rounding tolerance: forms derived numerically from q̈ (``Terms.derivation``)
    derived: object = 0.0


class Terms:
    """What the measures read at every state of ``batch``: the quantities, each computed when first read.

    ``*_hand`` are the closed forms (``batch.forms``, ``pendverify.checks.closed_forms``),
    ``*_pin`` Pinocchio's (``batch.pin``, ``pendverify.robot.batch``); D, B, W, the gravity
    scale and the model-form allowance are the same at every state.
    """

    def __init__(self, batch):
        self.batch = batch
        self.q, self.v, self.u, self.w_in = batch.Q, batch.V, batch.U, batch.W
        self.angular, self.coordinates = batch.model.angular, batch.model.coordinates

    # --- the model's scales and constant matrices --------------------------------------
    @cached_property
    def S(self):
        return self.batch.forms.value("diagonal_scale")

    @cached_property
    def g_scale(self):
        return self.batch.forms.constant("gravity_scale")

    @cached_property
    def D(self):
        return self.batch.forms.constant("damping_matrix")

    @cached_property
    def B(self):
        return self.batch.forms.constant("input_matrix")

    @cached_property
    def W(self):
        return self.batch.forms.constant("disturbance_matrix")

    @cached_property
    def allowance(self):
        return self.batch.system.allowance

    @cached_property
    def energy_allowance(self):
        """|ΔV(θ) − ΔV(0)| a model-form term may cause, per state (``PinocchioSystem.energy_allowance``)."""
        return self.batch.system.energy_allowance(self.q)

    @cached_property
    def derivation(self):
        """(crba's, gravity's, rnea's) relative rounding bounds of forms the model derives from its q̈
        (``pendverify.analytic.numeric_derivation``), from Pinocchio's M, H and forces; zeros for any
        other model."""
        if not self.batch.model.mass_from_acceleration:
            return 0.0, 0.0, 0.0
        model = self.batch.model
        steps = np.array([model.derivation_steps(q) for q in self.q])
        force = -(self.bias_pin + self.v @ np.asarray(self.D, dtype=float).T)  # M q̈(q, q̇, 0), Pinocchio's
        return rounding_bounds(
            self.M_pin, self.S, self.B, self.g_scale, steps, self.H_pin, force, self.rnea_scale
        )

    @cached_property
    def rnea_scale(self):
        """The size of the terms rnea compares at each state: rates times Σ|q̇ᵢ/weightsᵢ|, plus gravity's."""
        gravity = np.max(self.weights * self.g_scale, axis=-1)
        return (self.rate + self.d_rate) * total(np.abs(self.v / self.weights)) + gravity

    @cached_property
    def D_urdf(self):
        system = self.batch.system
        return system.cmap.matrix_to_model(np.diag(system.urdf_damping()))

    # --- each quantity, closed form and Pinocchio ----------------------------------------
    @cached_property
    def M_pin(self):
        return self.batch.pin.mass_matrix()

    @cached_property
    def M_hand(self):
        return self.batch.forms.value("mass_matrix")

    @cached_property
    def bias_pin(self):
        return self.batch.pin.bias()

    @cached_property
    def bias_hand(self):
        return self.batch.forms.value("bias")

    @cached_property
    def H_pin(self):
        return self.batch.pin.gravity()

    @cached_property
    def H_hand(self):
        return self.batch.forms.value("gravity")

    @cached_property
    def C_pin(self):
        return self.batch.pin.coriolis_matrix()

    @cached_property
    def C_hand(self):
        return self.batch.forms.value("coriolis_matrix")

    @cached_property
    def Mdot_pin(self):
        return self.batch.pin.mass_matrix_derivative()

    @cached_property
    def det_hand(self):
        return self.batch.forms.value("det_mass_matrix")

    @cached_property
    def det_pin(self):
        return self.batch.pin.det_mass_matrix()

    @cached_property
    def Minv_pin(self):
        return self.batch.pin.inverse_mass_matrix()

    @cached_property
    def Minv_hand(self):
        return self.batch.forms.value("inverse_mass_matrix")

    @cached_property
    def a_hand(self):
        return self.batch.forms.value("acceleration")

    @cached_property
    def a_pin(self):
        """ABA at τ = B u + W w − D q̇: the friction and inputs as the hand model declares them."""
        tau = mv(self.B, self.u) + mv(self.W, self.w_in) - mv(self.D, self.v)
        return self.batch.pin.acceleration(tau)

    @cached_property
    def KE_pin(self):
        return self.batch.pin.kinetic_energy()

    @cached_property
    def KE_hand(self):
        return self.batch.forms.value("kinetic_energy")

    @cached_property
    def V_pin(self):
        return self.batch.pin.potential_energy()

    @cached_property
    def V_pin0(self):
        """Pinocchio's V at θ = 0 (potential energies agree up to a constant)."""
        return self.batch.system.potential_energy(np.zeros(self.batch.model.nv))

    @cached_property
    def V_hand(self):
        return self.batch.forms.value("potential_energy")

    @cached_property
    def V_hand0(self):
        return self.batch.forms.constant("potential_energy", np.zeros(self.batch.model.nv))

    # --- derived scales ---------------------------------------------------------------
    @cached_property
    def weights(self):
        return weights_of(self.S)

    @cached_property
    def rate(self):
        return rates_of(self.S, self.v, self.angular)

    @cached_property
    def d_rate(self):
        return damping_rate_of(self.D, self.weights)

    def norm2(self, A):
        """``norms2(A)``, once per matrix content (minverse, aba and energy share theirs)."""
        A = np.ascontiguousarray(A)
        memo = self.__dict__.setdefault("_norms", {})
        key = (A.shape, A.tobytes())
        if key not in memo:
            memo[key] = norms2(A)
        return memo[key]


def _max2(A):
    return np.max(A, axis=(-2, -1))


def _at_least_one(x):
    return np.where(1.0 > x, 1.0, x)  # max(x, 1.0) as Python takes it


# --- the measures ----------------------------------------------------------------------------
def measure_crba(t):
    entries = np.abs(scaled_matrix(t.M_pin - t.M_hand, t.weights))
    return Measure(_max2(entries), 1.0, entries=entries, derived=t.derivation[0])


def measure_rnea(t):
    weights = t.weights
    entries = weights * np.abs(t.bias_pin - t.bias_hand)
    return Measure(
        np.max(entries, axis=-1),
        t.rnea_scale,
        np.max(weights * t.allowance, axis=-1),
        entries=entries,
        derived=t.derivation[2],
    )


def measure_gravity(t):
    weights = t.weights
    entries = weights * np.abs(t.H_pin - t.H_hand)
    return Measure(
        np.max(entries, axis=-1),
        np.max(weights * t.g_scale, axis=-1),
        np.max(weights * t.allowance, axis=-1),
        entries=entries,
        derived=t.derivation[1],
    )


def measure_coriolis(t):
    weights = t.weights
    entries = np.abs(scaled_matrix(t.C_pin - t.C_hand, weights))
    return Measure(_max2(entries), _at_least_one(t.rate + t.d_rate), entries=entries)


def measure_skew(t):
    weights = t.weights
    N = t.Mdot_pin - 2 * t.C_hand
    return Measure(
        _max2(np.abs(scaled_matrix(N + np.swapaxes(N, -1, -2), weights))), _at_least_one(t.rate + t.d_rate)
    )


def measure_det(t):
    scale = np.prod(t.S, axis=-1)
    closed, lu = t.det_hand, t.det_pin
    bad = np.logical_not(np.logical_and(closed > 0, lu > 0))
    err = np.where(bad, np.inf, np.abs(closed - lu))

    def describe(i):
        return f"det M not positive: closed form {np.asarray(closed)[i]:.3g}, LU {np.asarray(lu)[i]:.3g}"

    return Measure(err, scale, 0.0, bad, describe)


def measure_minverse(t):
    sqrt_s = 1.0 / t.weights
    diff = t.Minv_pin - t.Minv_hand
    Minv_norm = t.norm2(scaled_matrix(t.Minv_hand, sqrt_s))
    # δ(M⁻¹) = −M⁻¹ δM M⁻¹ with |δM̃| ~ ε‖M̃‖
    scale = Minv_norm * Minv_norm * t.norm2(scaled_matrix(t.M_hand, 1.0 / sqrt_s))
    entries = np.abs(scaled_matrix(diff, sqrt_s))
    return Measure(_max2(entries), scale, entries=entries)


def measure_aba(t):
    weights = t.weights
    a_pin = t.a_pin
    a_hand = t.a_hand
    Minv_norm = t.norm2(scaled_matrix(t.Minv_hand, 1.0 / weights))
    M_norm = t.norm2(scaled_matrix(t.M_hand, weights))
    forces = force_scale_of(t.rate, t.v, weights, t.g_scale, t.B, t.W, t.D, t.u, t.w_in)
    scale = Minv_norm * (forces + M_norm * np.max(np.abs(a_pin / weights), axis=-1))
    allowance = Minv_norm * np.max(weights * t.allowance, axis=-1)
    entries = np.abs((a_pin - a_hand) / weights)
    return Measure(np.max(entries, axis=-1), scale, allowance, entries=entries)


def measure_energy(t):
    weights = t.weights
    kinetic = np.abs(t.KE_pin - t.KE_hand)
    # potential energies agree up to a constant: compare differences from θ = 0
    dv_pin = t.V_pin - t.V_pin0
    dv_hand = t.V_hand - t.V_hand0
    kinetic_scale = 0.5 * total((t.v / weights) ** 2) * t.norm2(scaled_matrix(t.M_hand, weights))
    potential_scale = float(np.max(t.g_scale))
    allowance = t.energy_allowance
    return Measure(kinetic + np.abs(dv_pin - dv_hand), kinetic_scale + potential_scale, allowance)


def measure_damping(t):
    """The URDF's <dynamics damping> seen in the model's coordinates (Tᵀ·diag(b)·T) against D.

    Pinocchio keeps the damping but none of its algorithms applies it, so no other
    check can see a URDF whose damping disagrees with the hand model's D.
    """
    weights = t.weights
    D_urdf, D = t.D_urdf, t.D
    diff = np.abs(scaled_matrix(D_urdf - D, weights))
    own, urdf = _max2(np.abs(scaled_matrix(D, weights))), _max2(np.abs(scaled_matrix(D_urdf, weights)))
    err = _max2(diff)

    def describe(index):
        d = diff[index]
        i, j = np.unravel_index(np.argmax(d), d.shape)
        names = t.coordinates
        return (
            f"D[{names[i]},{names[j]}]: the URDF's <dynamics damping> gives {D_urdf[i, j]:.6g}, "
            f"the hand model {D[i, j]:.6g}"
        )

    return Measure(err, np.where(urdf > own, urdf, own), 0.0, err > 0, describe, entries=diff)


MEASURES: dict[str, Callable] = {
    "crba": measure_crba,
    "rnea": measure_rnea,
    "gravity": measure_gravity,
    "coriolis": measure_coriolis,
    "skew": measure_skew,
    "det": measure_det,
    "minverse": measure_minverse,
    "aba": measure_aba,
    "energy": measure_energy,
    "damping": measure_damping,
}
