"""What each check measures: its error at one state and the scale that error is judged against.

Each check's measure (``MEASURES``) reads the closed forms' and Pinocchio's quantities
from ``Terms`` and returns the error e in scaled coordinates (``pendverify.checks.scaling``),
the scale s (the size of the terms that produced the quantity, including cancellation)
and the known model-form allowance a.  One state's terms (``StateTerms``, the model's and
the system's methods called at that state) give numbers; a batch's terms
(``pendverify.checks.batch``) give arrays with the batch axis first, and the measure
runs once for all states.  The measures use only operations that give each state the
same bits either way (elementwise arithmetic, reductions over the last axes, one
BLAS/LAPACK call per state).  The per-state functions (``crba``, ``rnea``, …: model,
Pinocchio system, state → ``Sample``) are what ``Check.evaluate`` calls.
``pendverify.checks.catalogue`` names them, gives each its constant K and passes a
state when e ≤ K·ε·((1 + |θ|max)·c_T + (A − 1))·s + a.

The scales:

* ``crba``: 1 (M̃ has entries of order one); ``gravity``: max w·(Σ|terms| of H).
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
class Sample:
    error: float
    scale: float
    allowance: float = 0.0
    note: str = ""


@dataclass(frozen=True)
class Measure:
    """A measure at one state (numbers) or at each state of a batch (arrays, batch axis first).

    ``noted``: where a note is due; ``describe(index)`` writes it (index () for one state).
    """

    error: object
    scale: object
    allowance: object = 0.0
    noted: object = False
    describe: Callable[[tuple], str] | None = None


class Terms:
    """What the measures read; subclasses give the quantities, the derived scales are formed here."""

    @cached_property
    def w(self):
        return weights_of(self.S)

    @cached_property
    def rate(self):
        return rates_of(self.S, self.v, self.angular)

    @cached_property
    def d_rate(self):
        return damping_rate_of(self.D, self.w)

    def norm2(self, A):
        """``norms2(A)``, once per matrix content (minverse, aba and energy share theirs)."""
        A = np.ascontiguousarray(A)
        memo = self.__dict__.setdefault("_norms", {})
        key = (A.shape, A.tobytes())
        if key not in memo:
            memo[key] = norms2(A)
        return memo[key]


class StateTerms(Terms):
    """One state's terms: the model's and the system's methods at that state, called when first read."""

    def __init__(self, model, system, s):
        self.model, self.system = model, system
        self.q, self.v, self.u, self.w_in = s.q, s.v, s.u, s.w
        self.angular, self.coordinates = model.angular, model.coordinates

    def __getattr__(self, name):  # the quantities, each computed once
        if name.startswith("__") or name not in _STATE_QUANTITIES:
            raise AttributeError(name)
        value = _STATE_QUANTITIES[name](self.model, self.system, self)
        self.__dict__[name] = value
        return value

    def acceleration_pin(self, tau):
        return self.system.acceleration(self.q, self.v, tau)


def _zero(model):
    return np.zeros(model.nv)


_STATE_QUANTITIES = {
    "S": lambda m, sy, t: m.diagonal_scale(t.q),
    "g_scale": lambda m, sy, t: m.gravity_scale(),
    "D": lambda m, sy, t: m.damping_matrix(),
    "B": lambda m, sy, t: m.input_matrix(),
    "W": lambda m, sy, t: m.disturbance_matrix(),
    "allowance": lambda m, sy, t: sy.allowance,
    "D_urdf": lambda m, sy, t: sy.cmap.matrix_to_model(np.diag(sy.urdf_damping())),
    "M_pin": lambda m, sy, t: sy.mass_matrix(t.q),
    "M_hand": lambda m, sy, t: m.mass_matrix(t.q),
    "bias_pin": lambda m, sy, t: sy.bias(t.q, t.v),
    "bias_hand": lambda m, sy, t: m.bias(t.q, t.v),
    "H_pin": lambda m, sy, t: sy.gravity(t.q),
    "H_hand": lambda m, sy, t: m.gravity(t.q),
    "C_pin": lambda m, sy, t: sy.coriolis_matrix(t.q, t.v),
    "C_hand": lambda m, sy, t: m.coriolis_matrix(t.q, t.v),
    "Mdot_pin": lambda m, sy, t: sy.mass_matrix_derivative(t.q, t.v),
    "det_hand": lambda m, sy, t: m.det_mass_matrix(t.q),
    "det_pin": lambda m, sy, t: sy.det_mass_matrix(t.q),
    "Minv_pin": lambda m, sy, t: sy.inverse_mass_matrix(t.q),
    "Minv_hand": lambda m, sy, t: m.inverse_mass_matrix(t.q),
    "a_hand": lambda m, sy, t: m.acceleration(t.q, t.v, t.u, t.w_in),
    "KE_pin": lambda m, sy, t: sy.kinetic_energy(t.q, t.v),
    "KE_hand": lambda m, sy, t: m.kinetic_energy(t.q, t.v),
    "V_pin": lambda m, sy, t: sy.potential_energy(t.q),
    "V_pin0": lambda m, sy, t: sy.potential_energy(_zero(m)),
    "V_hand": lambda m, sy, t: m.potential_energy(t.q),
    "V_hand0": lambda m, sy, t: m.potential_energy(_zero(m)),
}


def _max2(A):
    return np.max(A, axis=(-2, -1))


def _at_least_one(x):
    return np.where(1.0 > x, 1.0, x)  # max(x, 1.0) as Python takes it


# --- the measures ----------------------------------------------------------------------------
def measure_crba(t):
    w = t.w
    return Measure(_max2(np.abs(scaled_matrix(t.M_pin - t.M_hand, w))), 1.0)


def measure_rnea(t):
    w = t.w
    err = np.max(w * np.abs(t.bias_pin - t.bias_hand), axis=-1)
    scale = (t.rate + t.d_rate) * total(np.abs(t.v / w)) + np.max(w * t.g_scale, axis=-1)
    return Measure(err, scale, np.max(w * t.allowance, axis=-1))


def measure_gravity(t):
    w = t.w
    err = np.max(w * np.abs(t.H_pin - t.H_hand), axis=-1)
    return Measure(err, np.max(w * t.g_scale, axis=-1), np.max(w * t.allowance, axis=-1))


def measure_coriolis(t):
    w = t.w
    diff = t.C_pin - t.C_hand
    return Measure(_max2(np.abs(scaled_matrix(diff, w))), _at_least_one(t.rate + t.d_rate))


def measure_skew(t):
    w = t.w
    N = t.Mdot_pin - 2 * t.C_hand
    return Measure(
        _max2(np.abs(scaled_matrix(N + np.swapaxes(N, -1, -2), w))), _at_least_one(t.rate + t.d_rate)
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
    sqrt_s = 1.0 / t.w
    diff = t.Minv_pin - t.Minv_hand
    Minv_norm = t.norm2(scaled_matrix(t.Minv_hand, sqrt_s))
    # δ(M⁻¹) = −M⁻¹ δM M⁻¹ with |δM̃| ~ ε‖M̃‖
    scale = Minv_norm * Minv_norm * t.norm2(scaled_matrix(t.M_hand, 1.0 / sqrt_s))
    return Measure(_max2(np.abs(scaled_matrix(diff, sqrt_s))), scale)


def measure_aba(t):
    w = t.w
    tau = mv(t.B, t.u) + mv(t.W, t.w_in) - mv(t.D, t.v)
    a_pin = t.acceleration_pin(tau)
    a_hand = t.a_hand
    Minv_norm = t.norm2(scaled_matrix(t.Minv_hand, 1.0 / w))
    M_norm = t.norm2(scaled_matrix(t.M_hand, w))
    forces = force_scale_of(t.rate, t.v, w, t.g_scale, t.B, t.W, t.D, t.u, t.w_in)
    scale = Minv_norm * (forces + M_norm * np.max(np.abs(a_pin / w), axis=-1))
    allowance = Minv_norm * np.max(w * t.allowance, axis=-1)
    return Measure(np.max(np.abs((a_pin - a_hand) / w), axis=-1), scale, allowance)


def measure_energy(t):
    w = t.w
    kinetic = np.abs(t.KE_pin - t.KE_hand)
    # potential energies agree up to a constant: compare differences from θ = 0
    dv_pin = t.V_pin - t.V_pin0
    dv_hand = t.V_hand - t.V_hand0
    kinetic_scale = 0.5 * total((t.v / w) ** 2) * t.norm2(scaled_matrix(t.M_hand, w))
    potential_scale = float(np.max(t.g_scale))
    allowance = 2 * float(np.sum(t.allowance))  # |ΔV| ≤ m g |offset| at both ends
    return Measure(kinetic + np.abs(dv_pin - dv_hand), kinetic_scale + potential_scale, allowance)


def measure_damping(t):
    """The URDF's <dynamics damping> seen in the model's coordinates (Tᵀ·diag(b)·T) against D.

    Pinocchio keeps the damping but none of its algorithms applies it, so no other
    check can see a URDF whose damping disagrees with the hand model's D.
    """
    w = t.w
    D_urdf, D = t.D_urdf, t.D
    diff = np.abs(scaled_matrix(D_urdf - D, w))
    own, urdf = _max2(np.abs(scaled_matrix(D, w))), _max2(np.abs(scaled_matrix(D_urdf, w)))
    err = _max2(diff)

    def describe(index):
        d = diff[index]
        i, j = np.unravel_index(np.argmax(d), d.shape)
        names = t.coordinates
        return (
            f"D[{names[i]},{names[j]}]: the URDF's <dynamics damping> gives {D_urdf[i, j]:.6g}, "
            f"the hand model {D[i, j]:.6g}"
        )

    return Measure(err, np.where(urdf > own, urdf, own), 0.0, err > 0, describe)


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


def _at_one_state(measure):
    def evaluate(model, system, s) -> Sample:
        m = measure(StateTerms(model, system, s))
        note = m.describe(()) if m.describe is not None and bool(m.noted) else ""
        return Sample(float(m.error), float(m.scale), float(m.allowance), note)

    evaluate.__name__ = evaluate.__qualname__ = measure.__name__.removeprefix("measure_")
    evaluate.__doc__ = measure.__doc__
    return evaluate


crba, rnea, gravity, coriolis, skew, det, minverse, aba, energy, damping = (
    _at_one_state(MEASURES[name]) for name in MEASURES
)
