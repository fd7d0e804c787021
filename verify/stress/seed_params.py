"""The reference systems' hard parameter sets: the default sets, scaled, for their own stress cases.

Lengths scale with their inertias (I ∝ m·l², so a link k times longer has k² its
inertia); a mass ratio scales link 1's mass and its inertia together.  The generic
cases for any model (``pendverify.stress.generic``) derive their sets from the
parameters' kinds instead.
"""

from __future__ import annotations

from pendverify.analytic import CartDoublePendulumParams, DoublePendulumParams
from pendverify.analytic.params import default_parameter_file, load_parameter_file


def default(model: str):
    return load_parameter_file(default_parameter_file(model))[2]


def dp_scaled(length: float = 1.0, **changes) -> DoublePendulumParams:
    """The default double pendulum with every length × ``length`` (inertias × length²)."""
    p = default("double_pendulum")
    s = length
    p = p.replace(l1=p.l1 * s, l2=p.l2 * s, r1=p.r1 * s, r2=p.r2 * s, I1=p.I1 * s * s, I2=p.I2 * s * s)
    return p.replace(**changes)


def dp_link_mass_ratio(ratio: float) -> DoublePendulumParams:
    """m1/m2 = ratio (m2 kept); link 1's inertia scales with its mass."""
    p = default("double_pendulum")
    return p.replace(m1=ratio * p.m2, I1=p.I1 * ratio * p.m2 / p.m1)


def dp_link_lengths(s1: float, s2: float) -> DoublePendulumParams:
    p = default("double_pendulum")
    return p.replace(l1=p.l1 * s1, r1=p.r1 * s1, I1=p.I1 * s1**2, l2=p.l2 * s2, r2=p.r2 * s2, I2=p.I2 * s2**2)


def cart(**changes) -> CartDoublePendulumParams:
    return default("cart_double_pendulum").replace(**changes)
