"""The reference systems' benchmark problems: the default run of ``pendverify bench accuracy`` (data only).

==========  =====================================================================  ==========
key         what                                                                   compared
==========  =====================================================================  ==========
mild        double pendulum, θ = (−π/2 + 0.5, 0.3) rad from rest, no friction:     states
            a mild, quasi-periodic swing
chaotic     double pendulum, θ = (2.0, 2.5) rad from rest, no friction; compared    states
            over T = 2 s only (its double-precision solutions diverge beyond)
cart_lqr    cart double pendulum near upright, (0, 0.1, −0.05) m/rad, rates          states
            (0.2, 0, 0.3), friction on, LQR Q = diag(10, 100, 100, 1, 10, 10), R = 0.1
long        the mild swing over T = 1e3 s (full) — energy only, never states        energy
==========  =====================================================================  ==========

The horizons are the configuration's (``workprecision.FULL``, ``QUICK``); the anchor of
the single-trajectory ratio, engine study and ensemble is ``chaotic`` (``Config.anchor``).
This is the one bench module that names the two reference systems: every other one takes any model
(``tests/test_no_name_branching.py``).
"""

from __future__ import annotations

import math

from pendverify.bench.problems import ProblemSpec

PI = math.pi

SCENES = {
    "mild": {
        "name": "mild swing",
        "model": "double_pendulum",
        "initial": {"q": [-PI / 2 + 0.5, 0.3], "v": [0.0, 0.0]},
        "effects": {"gravity": True},
    },
    "chaotic": {
        "name": "chaotic double pendulum",
        "model": "double_pendulum",
        "initial": {"q": [2.0, 2.5], "v": [0.0, 0.0]},
        "effects": {"gravity": True},
    },
    "cart_lqr": {
        "name": "cart near upright under LQR",
        "model": "cart_double_pendulum",
        "initial": {"q": [0.0, 0.1, -0.05], "v": [0.2, 0.0, 0.3]},
        "effects": {
            "gravity": True,
            "damping": True,
            "actuation": {"type": "lqr", "Q": [10.0, 100.0, 100.0, 1.0, 10.0, 10.0], "R": [0.1]},
        },
    },
    "long": {
        "name": "long conservative run",
        "model": "double_pendulum",
        "initial": {"q": [-PI / 2 + 0.5, 0.3], "v": [0.0, 0.0]},
        "effects": {"gravity": True},
    },
}
TITLES = {
    "mild": "double pendulum, mild swing",
    "chaotic": "double pendulum, chaotic",
    "cart_lqr": "cart double pendulum, LQR",
    "long": "long conservative run (energy)",
}
METRICS = {"mild": "state", "chaotic": "state", "cart_lqr": "state", "long": "energy"}


def specs() -> dict[str, ProblemSpec]:
    """The reference systems' problems by key (documents; parsed when a problem is made)."""
    return {key: ProblemSpec(key, TITLES[key], SCENES[key], METRICS[key]) for key in SCENES}
