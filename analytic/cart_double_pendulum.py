"""Double inverted pendulum on a cart: the cart reference system.

Conventions
-----------
::

         m2 o            θ1, θ2: absolute angles of the rods from the upright,
             \\  l2       positive when the rod leans towards +x;
              \\          q: cart position along +x [m];
           m1  o          massless rods of lengths l1, l2 [m];
               |  l1     point masses m (cart), m1, m2 [kg];
               |         pivot of rod 1 at the cart's height (0).
        [=====m=====]  → +x,  u: force on the cart [N]
        ================ rail

Positions: q0 = (q, 0), q1 = q0 + l1 (sin θ1, cos θ1), q2 = q1 + l2 (sin θ2, cos θ2).
Friction −d1 q̇ on the cart [N·s/m], −d2 θ̇1 and −d3 θ̇2 [N·m·s/rad] on the
*absolute* angular rates, exactly as the derivation models them.  Disturbances
w = (w1, w2, w3) act as generalized forces on (q, θ1, θ2).  y = (q, θ1, θ2).

Equations::

    M(y) = [ m + m1 + m2         l1 (m1+m2) cos θ1         m2 l2 cos θ2        ]
           [ l1 (m1+m2) cos θ1   l1² (m1+m2)               l1 l2 m2 cos(θ1−θ2) ]
           [ m2 l2 cos θ2        l1 l2 m2 cos(θ1−θ2)       l2² m2              ]

    f(y, ẏ, u, w) = [ l1 (m1+m2) θ̇1² sin θ1 + m2 l2 θ̇2² sin θ2             ]
                    [ −l1 l2 m2 θ̇2² sin(θ1−θ2) + g (m1+m2) l1 sin θ1        ]
                    [ l1 l2 m2 θ̇1² sin(θ1−θ2) + g l2 m2 sin θ2              ]
                    − (d1 q̇, d2 θ̇1, d3 θ̇2) + (u, 0, 0) + w

    M(y) ÿ = f,     det M = l1² l2² m2 (m m1 + (m1² + m1 m2) sin² θ1 + m m2 sin²(θ1−θ2)),
    ẋ = F(x, u, w) = (ẏ, M⁻¹ f),  x = (y, ẏ).

The derivation's typeset M lost its third row; it is derived here from the kinetic
energy K = ½ (m‖q̇0‖² + m1‖q̇1‖² + m2‖q̇2‖²): ∂²K/∂θ̇2∂ẏ gives
(m2 l2 cos θ2, l1 l2 m2 cos(θ1−θ2), l2² m2), consistent with the symmetry of the
first two rows.  The derivation's intermediate lines carry typos; its f and det M are
used verbatim.  The derivation gives no C matrix: the Christoffel form of M is

    C(y, ẏ) = [ 0   −l1 (m1+m2) sin θ1 θ̇1   −m2 l2 sin θ2 θ̇2      ]
              [ 0    0                       l1 l2 m2 sin(θ1−θ2) θ̇2 ]
              [ 0   −l1 l2 m2 sin(θ1−θ2) θ̇1  0                      ]

and H = ∂V/∂y = (0, −g (m1+m2) l1 sin θ1, −g m2 l2 sin θ2) with
V = g (m1 l1 cos θ1 + m2 (l1 cos θ1 + l2 cos θ2)), so that f = −C ẏ − H − D ẏ + B u + w.

Lagrangian (for ``pendverify sympy``): the derivation's K and P verbatim, the Rayleigh
function R = ½ (d1 q̇² + d2 θ̇1² + d3 θ̇2²) and the input power
P_in = (u + w1) q̇ + w2 θ̇1 + w3 θ̇2.
"""

from __future__ import annotations

import dataclasses
import math
from typing import ClassVar

import numpy as np

from pendverify.analytic.forms import STANDARD_CLOSED_FORMS, BatteryMotion, ClosedForm, Energies
from pendverify.analytic.interface import ClosedFormModel
from pendverify.analytic.parameter_set import ParameterSet, quantity


@dataclasses.dataclass(frozen=True)
class CartDoublePendulumParams(ParameterSet):
    """Parameters of the double inverted pendulum on a cart, SI units."""

    model = "cart_double_pendulum"

    m: float = quantity("mass", "mass of the cart in [kg]")
    m1: float = quantity("mass", "point mass at the top of rod 1 in [kg]")
    m2: float = quantity("mass", "point mass at the top of rod 2 in [kg]")
    l1: float = quantity("length", "length of rod 1 in [m]")
    l2: float = quantity("length", "length of rod 2 in [m]")
    d1: float = quantity("damping", "viscous friction of the cart in [N·s/m]")
    d2: float = quantity("damping", "viscous friction on the absolute rate of rod 1 in [N·m·s/rad]")
    d3: float = quantity("damping", "viscous friction on the absolute rate of rod 2 in [N·m·s/rad]")
    g: float = quantity("gravity", "gravitational acceleration in [m/s²]")


class CartDoublePendulum(ClosedFormModel):
    name = "cart_double_pendulum"
    params_type = CartDoublePendulumParams
    coordinates = ("q", "theta1", "theta2")
    angular = (False, True, True)
    inputs = ("u",)
    battery_motion = BatteryMotion(
        q=(0.0, 0.15, -0.1),
        v=(0.1, 0.0, 0.2),
        input_amplitude=(2.0,),
        input_frequency=0.5,
        disturbance_std=(0.5, 0.05, 0.05),
        disturbance_bandwidth=4.0,
        damping_floor=0.05,
    )
    disturbances = ("w1", "w2", "w3")
    # The derivation's own right-hand side f is a closed form too.
    closed_forms: ClassVar[dict[str, ClosedForm]] = {
        **STANDARD_CLOSED_FORMS,
        "f": ClosedForm("qvuw", "-C*v - H - D*v + B*u + W*w"),
    }

    #: the map is read off the URDF (``pendverify.analytic.reference_geometry``)
    geometry_reader = "cart_double_pendulum"

    def mass_matrix(self, y):
        p = self.params
        c1, c2, c12 = self.math.cos(y[1]), self.math.cos(y[2]), self.math.cos(y[1] - y[2])
        m12 = p.m1 + p.m2
        return np.array(
            [
                [p.m + m12, p.l1 * m12 * c1, p.m2 * p.l2 * c2],
                [p.l1 * m12 * c1, p.l1**2 * m12, p.l1 * p.l2 * p.m2 * c12],
                [p.m2 * p.l2 * c2, p.l1 * p.l2 * p.m2 * c12, p.l2**2 * p.m2],
            ]
        )

    def coriolis_matrix(self, y, yd):
        p = self.params
        s1, s2, s12 = self.math.sin(y[1]), self.math.sin(y[2]), self.math.sin(y[1] - y[2])
        k = p.l1 * p.l2 * p.m2
        return np.array(
            [
                [0.0, -p.l1 * (p.m1 + p.m2) * s1 * yd[1], -p.m2 * p.l2 * s2 * yd[2]],
                [0.0, 0.0, k * s12 * yd[2]],
                [0.0, -k * s12 * yd[1], 0.0],
            ]
        )

    def gravity(self, y):
        p = self.params
        return np.array(
            [0.0, -p.g * (p.m1 + p.m2) * p.l1 * self.math.sin(y[1]), -p.g * p.m2 * p.l2 * self.math.sin(y[2])]
        )

    def gravity_scale(self):
        p = self.params
        return p.g * np.array([0.0, (p.m1 + p.m2) * p.l1, p.m2 * p.l2])

    def diagonal_scale(self, y):
        # M's diagonal is constant and cannot cancel: its entries are their own scales
        # (what the derived Σ|terms| gives too, without reading M with SymPy per process).
        p = self.params
        return np.array([p.m + p.m1 + p.m2, p.l1**2 * (p.m1 + p.m2), p.l2**2 * p.m2])

    def potential_energy(self, y):
        p = self.params
        return p.g * ((p.m1 + p.m2) * p.l1 * self.math.cos(y[1]) + p.m2 * p.l2 * self.math.cos(y[2]))

    def damping_matrix(self):
        p = self.params
        return np.diag([p.d1, p.d2, p.d3])

    def input_matrix(self):
        return np.array([[1.0], [0.0], [0.0]])

    def disturbance_matrix(self):
        return np.eye(3)

    def f(self, y, yd, u, w):
        """The derivation's right-hand side f(y, ẏ, u, w) of M(y) ÿ = f, verbatim."""
        p = self.params
        s1, s2, s12 = self.math.sin(y[1]), self.math.sin(y[2]), self.math.sin(y[1] - y[2])
        return (
            np.array(
                [
                    p.l1 * (p.m1 + p.m2) * yd[1] ** 2 * s1 + p.m2 * p.l2 * yd[2] ** 2 * s2,
                    -p.l1 * p.l2 * p.m2 * yd[2] ** 2 * s12 + p.g * (p.m1 + p.m2) * p.l1 * s1,
                    p.l1 * p.l2 * p.m2 * yd[1] ** 2 * s12 + p.g * p.l2 * p.m2 * s2,
                ]
            )
            - np.array([p.d1 * yd[0], p.d2 * yd[1], p.d3 * yd[2]])
            + np.array([u[0], 0.0, 0.0])
            + w
        )

    def det_mass_matrix(self, y):
        p = self.params
        s1sq, s12sq = self.math.sin(y[1]) ** 2, self.math.sin(y[1] - y[2]) ** 2
        return (
            p.l1**2 * p.l2**2 * p.m2 * (p.m * p.m1 + p.m1**2 * s1sq + p.m1 * p.m2 * s1sq + p.m * p.m2 * s12sq)
        )

    def inverse_mass_matrix(self, y):
        (a, pp, r), (_, b, s), (_, _, c) = self.mass_matrix(y)
        adj = np.array(
            [
                [b * c - s * s, r * s - pp * c, pp * s - b * r],
                [r * s - pp * c, a * c - r * r, pp * r - a * s],
                [pp * s - b * r, pp * r - a * s, a * b - pp * pp],
            ]
        )
        return adj / self.det_mass_matrix(y)

    def state_derivative(self, x, u, w):
        """F(x, u, w) = (ẏ, M⁻¹(y) f(y, ẏ, u, w)) with x = (y, ẏ), M⁻¹ the closed form above."""
        y, yd = x[:3], x[3:]
        return np.concatenate([yd, self.inverse_mass_matrix(y) @ self.f(y, yd, u, w)])

    def acceleration(self, q, v, u, w):
        return self.state_derivative(np.concatenate([q, v]), u, w)[3:]

    def energies(self, y, yd, u, w):
        p, cos, sin = self.params, self.math.cos, self.math.sin
        qd, t1, t2 = yd
        kinetic = (
            p.m * qd**2
            + p.m1 * ((qd + p.l1 * t1 * cos(y[1])) ** 2 + (p.l1 * t1 * sin(y[1])) ** 2)
            + p.m2
            * (
                (qd + p.l1 * t1 * cos(y[1]) + p.l2 * t2 * cos(y[2])) ** 2
                + (p.l1 * t1 * sin(y[1]) + p.l2 * t2 * sin(y[2])) ** 2
            )
        ) / 2
        return Energies(
            kinetic=kinetic,
            potential=p.g * (p.m1 * p.l1 * cos(y[1]) + p.m2 * (p.l1 * cos(y[1]) + p.l2 * cos(y[2]))),
            dissipation=(p.d1 * qd**2 + p.d2 * t1**2 + p.d3 * t2**2) / 2,
            power=(u[0] + w[0]) * qd + w[1] * t1 + w[2] * t2,
        )

    def derived_constants(self) -> dict[str, float]:
        """The coefficients of M: m + m1 + m2, l1·(m1 + m2), m2·l2, and det M at upright."""
        p = self.params
        return {
            "m_total": p.m + p.m1 + p.m2,
            "l1_m1_plus_m2": p.l1 * (p.m1 + p.m2),
            "m2_l2": p.m2 * p.l2,
            "det_M_upright": self.det_mass_matrix(np.zeros(3)),
        }

    def special_states(self):
        pi = math.pi
        return {
            "upright": np.array([0.0, 0.0, 0.0]),
            "hanging": np.array([0.0, pi, pi]),
            "folded": np.array([0.0, 0.0, pi]),
            "theta1=theta2": np.array([0.3, 0.7, 0.7]),
        }
