"""Seeded states for the checks: random states plus structured special ones.

Random states draw angles uniformly in ±ANGLE_RANGE rad (so that angle wrapping
is exercised), positions in ±POSITION_RANGE m, rates in ±RATE_RANGE (rad/s or
m/s), and inputs and disturbances as generalized forces of up to ±ACCEL_RANGE
times the coordinate's inertia scale (N·m or N).  Each of the model's named
special configurations (all zero, upright, folded, θ1 = θ2, ...) is visited at
rest and with one random velocity and forcing.  Everything is reproducible from
the seed, which each report records.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pendverify.analytic import ClosedFormModel

DEFAULT_SEED = 20260301
DEFAULT_RANDOM_STATES = 400
ANGLE_RANGE = 100.0  # rad
POSITION_RANGE = 10.0  # m
RATE_RANGE = 20.0  # rad/s or m/s
ACCEL_RANGE = 20.0  # rad/s² or m/s², times the inertia scale gives a force


@dataclass(frozen=True)
class State:
    label: str
    q: np.ndarray
    v: np.ndarray
    u: np.ndarray
    w: np.ndarray

    def as_dict(self) -> dict:
        return {
            "label": self.label,
            "q": self.q.tolist(),
            "v": self.v.tolist(),
            "u": self.u.tolist(),
            "w": self.w.tolist(),
        }


def _force_scales(model: ClosedFormModel, columns: np.ndarray) -> np.ndarray:
    inertia = model.diagonal_scale(np.zeros(model.nv))
    return ACCEL_RANGE * np.array([np.max(np.abs(col) * inertia) for col in columns.T])


def sample_states(model: ClosedFormModel, n_random: int = DEFAULT_RANDOM_STATES, seed: int = DEFAULT_SEED):
    """The special states first, then ``n_random`` random ones; deterministic in ``seed``."""
    rng = np.random.default_rng(seed)
    angular = np.array(model.angular)
    q_range = np.where(angular, ANGLE_RANGE, POSITION_RANGE)
    u_scale = _force_scales(model, model.input_matrix())
    w_scale = _force_scales(model, model.disturbance_matrix())

    def draw_v():
        return rng.uniform(-RATE_RANGE, RATE_RANGE, model.nv)

    def draw_u():
        return rng.uniform(-1, 1, u_scale.size) * u_scale

    def draw_w():
        return rng.uniform(-1, 1, w_scale.size) * w_scale

    states = []
    zero_u, zero_w = np.zeros(u_scale.size), np.zeros(w_scale.size)
    for name, q in model.special_states().items():
        q = np.asarray(q, dtype=float)
        states.append(State(f"{name} at rest", q, np.zeros(model.nv), zero_u, zero_w))
        states.append(State(f"{name} moving", q, draw_v(), draw_u(), draw_w()))
    for i in range(n_random):
        q = rng.uniform(-1, 1, model.nv) * q_range
        states.append(State(f"random #{i}", q, draw_v(), draw_u(), draw_w()))
    return states
