"""A single pendulum written as plain NumPy functions: the light way to give a model.

Verify it against its URDF (the parameters are the file's own ``PARAMS``)::

    pendverify check --analytic examples/pendulum_functions.py --urdf examples/pendulum_functions.urdf

θ is the hinge angle from hanging straight down, positive about the URDF's axis y: the bob at
distance l below the hinge is then at height −l cos θ, so V = −m g l cos θ and G = ∂V/∂θ =
m g l sin θ.  The bob is a point mass (zero inertia about its centre), so M = m l²; one
coordinate has no Coriolis terms (C = 0); the hinge's viscous friction is D = b.
``pendverify.analytic.numpy_model`` says what each function is and how it is called.
"""

import numpy as np


def M(q, p):
    return np.array([[p.m * p.l**2]])


def C(q, v, p):
    return np.zeros((1, 1))


def G(q, p):
    return np.array([p.m * p.g * p.l * np.sin(q[0])])


def D(p):
    return np.array([[p.b]])


DECLARATION = {
    "name": "pendulum_functions",
    "coordinates": {"theta": "angle"},
    "parameters": {
        "m": {"kind": "mass"},
        "l": {"kind": "length"},
        "b": {"kind": "damping"},
        "g": {"kind": "gravity"},
    },
    "urdf": {"joints": ["hinge"]},
}
PARAMS = {"m": 2.0, "l": 0.5, "b": 0.1, "g": 9.81}
