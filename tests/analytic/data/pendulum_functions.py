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
