"""The double pendulum of ``tests/analytic/mechanics_double_pendulum.py`` derived with planted errors
in what the user writes (for the repair tests).

``derivation(kind, **plants)`` builds a ``LagrangesMethod`` (given its bodies, so that the terms
of L are the bodies') or a ``KanesMethod`` (speeds u_i = θ̇_i) of the same system, gravity a load
(−m g N.y at each mass centre) for both, or the bodies' potential energy (``gravity="energy"``,
Lagrange only; ``given_bodies=False``: the ``LagrangesMethod`` is given L alone, so its items
are the terms of L).  Plants: ``inertia`` multiplies link 2's inertia I2 (1 is right), ``weight_mass``
is the mass whose weight acts at link 2's centre (``"m2"`` is right), ``torque_sign`` multiplies
the friction torque −b2 θ̇2 on link 2, a load of its own (1 is right; the input torques are loads
of their own too: a sign of τ2 no check could see, since B enters both sides of every comparison,
and a sign flipped on a load holding both τ2 and b2 θ̇2 has two repairs the checks cannot tell
apart), ``c1_axis`` the axis of link 1 along which its centre of mass is
placed (``"x"`` is right; ``"y"`` is an error of the kinematics, which no edit of a body, particle
or load undoes: it turns link 1's gravity torque m1 g r1 cos θ1 into −m1 g r1 sin θ1, H[1] alone).
"""

from __future__ import annotations

import sympy as sp
from sympy.physics.mechanics import (
    KanesMethod,
    LagrangesMethod,
    Lagrangian,
    Point,
    ReferenceFrame,
    RigidBody,
    dynamicsymbols,
    inertia,
)

from tests.analytic.mechanics_double_pendulum import DECLARATION, KINDS

__all__ = ["DECLARATION", "derivation"]


def derivation(
    kind="lagrange",
    inertia_factor=1,
    weight_mass="m2",
    torque_sign=1,
    gravity="load",
    c1_axis="x",
    given_bodies=True,
):
    theta1, theta2 = dynamicsymbols("theta1 theta2")
    m1, m2, l1, r1, r2, I1, I2, b1, b2, g = sp.symbols(list(KINDS))
    tau1, tau2 = dynamicsymbols("tau1 tau2")
    N = ReferenceFrame("N")
    A = N.orientnew("A", "Axis", (theta1, N.z))
    B = A.orientnew("B", "Axis", (theta2, A.z))
    origin = Point("O")
    origin.set_vel(N, 0)
    C1 = origin.locatenew("C1", r1 * getattr(A, c1_axis))
    P = origin.locatenew("P", l1 * A.x)
    C2 = P.locatenew("C2", r2 * B.x)
    if kind == "kane":
        u1, u2 = dynamicsymbols("u1 u2")
        A.set_ang_vel(N, u1 * N.z)
        B.set_ang_vel(A, u2 * A.z)
    for point, base, frame in ((C1, origin, A), (P, origin, A), (C2, P, B)):
        point.v2pt_theory(base, N, frame)
    link1 = RigidBody("link1", C1, A, m1, (inertia(A, 0, 0, I1), C1))
    link2 = RigidBody("link2", C2, B, m2, (inertia(B, 0, 0, inertia_factor * I2), C2))
    inputs = [(A, (tau1 - tau2) * N.z), (B, tau2 * N.z)]
    friction = [
        (A, (b2 * theta2.diff() - b1 * theta1.diff()) * N.z),
        (B, -torque_sign * b2 * theta2.diff() * N.z),
    ]
    loads = inputs + friction
    weights = [(C1, -m1 * g * N.y), (C2, -sp.Symbol(weight_mass) * g * N.y)]
    if gravity == "energy":
        link1.potential_energy = m1 * g * C1.pos_from(origin).dot(N.y)
        link2.potential_energy = sp.Symbol(weight_mass) * g * C2.pos_from(origin).dot(N.y)
        weights = []
    bodies = [link1, link2]
    if kind == "kane":
        method = KanesMethod(
            N, q_ind=[theta1, theta2], u_ind=[u1, u2], kd_eqs=[theta1.diff() - u1, theta2.diff() - u2]
        )
        method.kanes_equations(bodies, loads + weights)
        return method
    method = LagrangesMethod(
        Lagrangian(N, *bodies),
        [theta1, theta2],
        forcelist=loads + weights,
        bodies=bodies if given_bodies else None,
        frame=N,
    )
    method.form_lagranges_equations()
    return method
