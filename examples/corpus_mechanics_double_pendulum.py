"""A double pendulum derived with ``sympy.physics.mechanics`` by Kane's method: a model of the
diagnosis corpus (examples/diagnosis_corpus.toml), the class of models given as a derivation.

    pendverify check --analytic examples/corpus_mechanics_double_pendulum.py \\
        --urdf examples/corpus_mechanics_double_pendulum.urdf \\
        --params examples/corpus_mechanics_double_pendulum_params.toml

θ1 from the x axis of N (gravity along −y), θ2 relative to link 1, the speeds u_i = θ̇_i; link i
is a rigid body of mass m_i and central inertia I_i about z, its centre at r_i along the link
(l1 from joint 1 to joint 2); a torque τ1 at the base and τ2 at the elbow (reacting on link 1),
viscous friction b1 θ̇1 and b2 θ̇2 at the joints; the weights −m_i g N.y at the centres.  The
user writes the bodies and the loads: a repair names the body or load it edits.
"""

import sympy as sp
from sympy.physics.mechanics import KanesMethod, Point, ReferenceFrame, RigidBody, dynamicsymbols, inertia

KINDS = dict(
    m1="mass", m2="mass", l1="length", r1="offset", r2="offset",
    I1="inertia", I2="inertia", b1="damping", b2="damping", g="gravity",
)  # fmt: skip
DECLARATION = {
    "name": "corpus_mechanics_double_pendulum",
    "coordinates": {"theta1": "angle", "theta2": "angle"},
    "inputs": ["tau1", "tau2"],
    "parameters": {name: {"kind": kind} for name, kind in KINDS.items()},
    "urdf": {"joints": ["joint1", "joint2"]},
}

theta1, theta2 = dynamicsymbols("theta1 theta2")
u1, u2 = dynamicsymbols("u1 u2")
tau1, tau2 = dynamicsymbols("tau1 tau2")
m1, m2, l1, r1, r2, I1, I2, b1, b2, g = sp.symbols(list(KINDS))

N = ReferenceFrame("N")
A = N.orientnew("A", "Axis", (theta1, N.z))
B = A.orientnew("B", "Axis", (theta2, A.z))
A.set_ang_vel(N, u1 * N.z)
B.set_ang_vel(A, u2 * A.z)
origin = Point("O")
origin.set_vel(N, 0)
C1 = origin.locatenew("C1", r1 * A.x)
P = origin.locatenew("P", l1 * A.x)
C2 = P.locatenew("C2", r2 * B.x)
C1.v2pt_theory(origin, N, A)
P.v2pt_theory(origin, N, A)
C2.v2pt_theory(P, N, B)

link1 = RigidBody("link1", C1, A, m1, (inertia(A, 0, 0, I1), C1))
link2 = RigidBody("link2", C2, B, m2, (inertia(B, 0, 0, I2), C2))
elbow = (tau2 - b2 * u2) * N.z
loads = [
    (A, (tau1 - b1 * u1) * N.z - elbow),
    (B, elbow),
    (C1, -m1 * g * N.y),
    (C2, -m2 * g * N.y),
]

METHOD = KanesMethod(
    N, q_ind=[theta1, theta2], u_ind=[u1, u2], kd_eqs=[theta1.diff() - u1, theta2.diff() - u2]
)
METHOD.kanes_equations([link1, link2], loads)
