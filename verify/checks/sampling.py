"""Seeded states for the checks: random states plus structured special ones.

Random states draw angles uniformly in ±ANGLE_RANGE rad (so that angle wrapping
is exercised), positions in ±POSITION_RANGE m, rates in ±RATE_RANGE (rad/s or
m/s), and inputs and disturbances as generalized forces of up to ±ACCEL_RANGE
times the coordinate's inertia scale (N·m or N) — for a model given by q̈ alone, which has
no inertia scale, the force whose q̈ at rest is at most ±ACCEL_RANGE.  Each of the model's named
special configurations (all zero, upright, folded, θ1 = θ2, ...) is visited at
rest and with one random velocity and forcing.  Everything is reproducible from
the seed, which each report records.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pendverify.analytic import ClosedFormModel
from pendverify.analytic.numeric_values import model_value

DEFAULT_SEED = 20260301
DEFAULT_RANDOM_STATES = 400
ANGLE_RANGE = 100.0  # rad
POSITION_RANGE = 10.0  # m
RATE_RANGE = 20.0  # rad/s or m/s
ACCEL_RANGE = 20.0  # rad/s² or m/s², times the inertia scale gives a force


@dataclass(slots=True)
class State:
    """One state the checks visit: its label, q, q̇, the inputs u and the disturbances w."""

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


def _force_scales(model: ClosedFormModel, columns: np.ndarray, group: str) -> np.ndarray:
    if not model.has_mass_matrix:  # q̈ alone: the force giving an acceleration of ACCEL_RANGE at rest
        return np.array(
            [ACCEL_RANGE / _acceleration_per_unit(model, group, k) for k in range(columns.shape[1])]
        )
    inertia = model_value(model, "diagonal_scale", np.zeros(model.nv))
    return ACCEL_RANGE * np.array([np.max(np.abs(col) * inertia) for col in columns.T])


def _acceleration_per_unit(model: ClosedFormModel, group: str, k: int) -> float:
    """max |Δq̈| for a unit of input (``group`` "u") or disturbance ("w") k at the zero state."""
    zero = np.zeros(model.nv)
    u, w = np.zeros(len(model.inputs)), np.zeros(len(model.disturbances))
    rest = model_value(model, "acceleration", zero, zero, u, w)
    (u if group == "u" else w)[k] = 1.0
    push = model_value(model, "acceleration", zero, zero, u, w) - rest
    return float(np.max(np.abs(push))) or 1.0


def sample_states(model: ClosedFormModel, n_random: int = DEFAULT_RANDOM_STATES, seed: int = DEFAULT_SEED):
    """The special states first, then ``n_random`` random ones; deterministic in ``seed``.

    Each moving special state draws q̇, u, w and each random state q, q̇, u, w, in that
    order, uniformly from the generator seeded with ``seed``; all draws are made by one
    ``Generator.uniform`` call on arrays of bounds, which takes the same numbers from the
    stream, one per entry and in order, as one call per vector would.
    """
    rng = np.random.default_rng(seed)
    nv = model.nv
    angular = np.array(model.angular)
    q_range = np.where(angular, ANGLE_RANGE, POSITION_RANGE)
    u_scale = _force_scales(model, model_value(model, "input_matrix"), "u")
    w_scale = _force_scales(model, model_value(model, "disturbance_matrix"), "w")
    nu, nw = u_scale.size, w_scale.size
    special = {name: np.asarray(q, dtype=float) for name, q in model.special_states().items()}
    moving = np.concatenate([np.full(nv, RATE_RANGE), np.ones(nu + nw)])  # q̇, u, w of a moving state
    bounds = np.concatenate([moving] * len(special) + [np.concatenate([np.ones(nv), moving])] * n_random)
    draws = rng.uniform(-bounds, bounds) if bounds.size else bounds
    scale = np.concatenate([np.ones(nv), u_scale, w_scale])  # u and w scaled after the draw, as before
    at = len(special) * (nv + nu + nw)
    specials = draws[:at].reshape(len(special), nv + nu + nw)
    randoms = draws[at:].reshape(n_random, 2 * nv + nu + nw)
    states = []
    zero_u, zero_w = np.zeros(nu), np.zeros(nw)
    vuw = specials * scale  # q̇ as drawn (its scale is exactly 1), u and w times their force scales
    for (name, q), x in zip(special.items(), vuw, strict=True):
        states.append(State(f"{name} at rest", q, np.zeros(nv), zero_u, zero_w))
        states.append(State(f"{name} moving", q, x[:nv], x[nv : nv + nu], x[nv + nu :]))
    qs, vuw = randoms[:, :nv] * q_range, randoms[:, nv:] * scale
    labels = [f"random #{i}" for i in range(n_random)]
    # each state's vectors are rows of the blocks (views, as the slices of a row were)
    states += map(State, labels, qs, vuw[:, :nv], vuw[:, nv : nv + nu], vuw[:, nv + nu :])
    return states
