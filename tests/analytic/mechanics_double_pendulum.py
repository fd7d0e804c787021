"""The double pendulum reference system derived with ``sympy.physics.mechanics`` (for the tests).

θ1 from the horizontal (the x axis of N, gravity along −y), θ2 relative to link 1, a torque
τ1 at the base joint and τ2 at the elbow (reacting on link 1), viscous friction b1 θ̇1 and
b2 θ̇2 at the joints: the conventions of ``examples/minimal_double_pendulum.py``.
``lagrange(factor)`` builds the ``LagrangesMethod`` (``factor`` multiplies link 2's inertia
I2: 1 is right, 2 a planted error), ``kane()`` the same system by Kane's method with the
speeds u_i = θ̇_i; ``DECLARATION`` declares it as ``examples/minimal_double_pendulum_text.toml``
does.
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

KINDS = dict(
    m1="mass", m2="mass", l1="length", r1="offset", r2="offset",
    I1="inertia", I2="inertia", b1="damping", b2="damping", g="gravity",
)  # fmt: skip
DECLARATION = {
    "name": "minimal_double_pendulum",
    "coordinates": {"theta1": "angle", "theta2": "angle"},
    "inputs": ["tau1", "tau2"],
    "parameters": {name: {"kind": kind} for name, kind in KINDS.items()},
    "urdf": {"joints": ["joint1", "joint2"]},
}


def _system(factor=1):
    theta1, theta2 = dynamicsymbols("theta1 theta2")
    m1, m2, l1, r1, r2, I1, I2, b1, b2, g = sp.symbols(list(KINDS))
    tau1, tau2 = dynamicsymbols("tau1 tau2")  # inputs as dynamic symbols, as often written
    N = ReferenceFrame("N")
    A = N.orientnew("A", "Axis", (theta1, N.z))
    B = A.orientnew("B", "Axis", (theta2, A.z))
    origin = Point("O")
    origin.set_vel(N, 0)
    C1 = origin.locatenew("C1", r1 * A.x)
    C1.v2pt_theory(origin, N, A)
    P = origin.locatenew("P", l1 * A.x)
    P.v2pt_theory(origin, N, A)
    C2 = P.locatenew("C2", r2 * B.x)
    C2.v2pt_theory(P, N, B)
    link1 = RigidBody("link1", C1, A, m1, (inertia(A, 0, 0, I1), C1))
    link2 = RigidBody("link2", C2, B, m2, (inertia(B, 0, 0, factor * I2), C2))
    link1.potential_energy = m1 * g * C1.pos_from(origin).dot(N.y)
    link2.potential_energy = m2 * g * C2.pos_from(origin).dot(N.y)
    elbow = (tau2 - b2 * theta2.diff()) * N.z
    loads = [(A, (tau1 - b1 * theta1.diff()) * N.z - elbow), (B, elbow)]
    return N, (theta1, theta2), (A, B), (link1, link2), loads


def lagrange(factor=1) -> LagrangesMethod:
    N, q, _, bodies, loads = _system(factor)
    method = LagrangesMethod(Lagrangian(N, *bodies), list(q), forcelist=loads, frame=N)
    method.form_lagranges_equations()
    return method


def kane() -> KanesMethod:
    N, q, (A, B), bodies, loads = _system()
    u = dynamicsymbols("u1 u2")
    A.set_ang_vel(N, u[0] * N.z)  # the speeds: A turns at u1, B at u1 + u2
    B.set_ang_vel(A, u[1] * A.z)
    l1, r1, r2, g = sp.symbols("l1 r1 r2 g")
    origin = Point("O")
    origin.set_vel(N, 0)
    P = origin.locatenew("P", l1 * A.x)
    bodies[0].masscenter.set_pos(origin, r1 * A.x)
    bodies[1].masscenter.set_pos(P, r2 * B.x)
    bodies[0].masscenter.v2pt_theory(origin, N, A)
    P.v2pt_theory(origin, N, A)
    bodies[1].masscenter.v2pt_theory(P, N, B)
    weights = [(b.masscenter, -b.mass * g * N.y) for b in bodies]
    method = KanesMethod(N, q_ind=list(q), u_ind=u, kd_eqs=[q[0].diff() - u[0], q[1].diff() - u[1]])
    method.kanes_equations(list(bodies), loads + weights)
    return method
