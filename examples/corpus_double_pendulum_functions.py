"""The reference double pendulum as NumPy functions (the diagnosis corpus's class "dynamics as code").

examples/minimal_double_pendulum.py's M, C, H, D, B written as plain functions of (q, q̇, p): θ1
from the horizontal, θ2 relative to link 1, the URDF's joint angles (urdf/double_pendulum.urdf,
parameters examples/minimal_double_pendulum.toml).  SymPy does not read it: its errors are
repaired in the parameters the functions are given (docs/diagnosis.md).
"""

import numpy as np


def M(q, p):
    alpha = p.I1 + p.I2 + p.m1 * p.r1**2 + p.m2 * (p.l1**2 + p.r2**2)
    beta, delta = p.m2 * p.l1 * p.r2, p.I2 + p.m2 * p.r2**2
    c2 = np.cos(q[1])
    return np.array([[alpha + 2 * beta * c2, delta + beta * c2], [delta + beta * c2, delta]])


def C(q, v, p):
    h = p.m2 * p.l1 * p.r2 * np.sin(q[1])
    return np.array([[-h * v[1], -h * (v[0] + v[1])], [h * v[0], 0.0]])


def G(q, p):
    c1, c12 = np.cos(q[0]), np.cos(q[0] + q[1])
    return p.g * np.array([(p.m1 * p.r1 + p.m2 * p.l1) * c1 + p.m2 * p.r2 * c12, p.m2 * p.r2 * c12])


def D(p):
    return np.diag([p.b1, p.b2])


def B(p):
    return np.eye(2)


DECLARATION = {
    "name": "minimal_double_pendulum",
    "coordinates": {"theta1": "angle", "theta2": "angle"},
    "inputs": ["tau1", "tau2"],
    "parameters": {
        "m1": {"kind": "mass"},
        "m2": {"kind": "mass"},
        "l1": {"kind": "length"},
        "r1": {"kind": "offset"},
        "r2": {"kind": "offset"},
        "I1": {"kind": "inertia"},
        "I2": {"kind": "inertia"},
        "b1": {"kind": "damping"},
        "b2": {"kind": "damping"},
        "g": {"kind": "gravity"},
    },
    "urdf": {"joints": ["joint1", "joint2"]},
}
