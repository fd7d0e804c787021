"""The battery's simulations: one short scene per effect the model has, for any model.

Gravity alone always (energy drift); damping when the model's D is not zero
(dissipation balance, energy never rises); actuation when it declares inputs B
(work–energy balance); a seeded noise disturbance when it declares disturbances W
(work–energy balance).  The motion is the model's own ``battery_motion`` when it
states one (the two reference systems do), else derived from its scales (``derived_motion``).  The
scenes are documents for ``pendverify.simulation.scene.parse_scene``, the path every
scene file takes, with the model class itself as ``model``.
"""

from __future__ import annotations

import numpy as np

from pendverify.analytic import ClosedFormModel, ParameterSet
from pendverify.analytic.forms import BatteryMotion

ANGLE_STEP = 0.3  # rad: the start is this far from the model's first special state, per angle
ANGULAR_RATE = 0.5  # rad/s
LINEAR_RATE = 0.1  # m/s
INPUT_SHARE = 0.2  # the sine's amplitude, as a share of each coordinate's force scale
DISTURBANCE_SHARE = 0.05  # the noise's standard deviation, likewise
UNIT_ACCELERATION = 1.0  # rad/s² or m/s²: times M's diagonal scale, a force scale where H has none


def force_scales(model: ClosedFormModel, q: np.ndarray) -> np.ndarray:
    """Per coordinate: the larger of |H_i|'s bound and S_i·(1 rad/s² or 1 m/s²) (N·m or N)."""
    gravity = np.abs(np.asarray(model.gravity_scale(), dtype=float))
    return np.maximum(gravity, UNIT_ACCELERATION * np.asarray(model.diagonal_scale(q), dtype=float))


def _sized(matrix: np.ndarray, forces: np.ndarray, share: float) -> tuple[float, ...]:
    """Per column k: share × the smallest F_i / |matrix_ik| over the coordinates it drives."""
    out = []
    for column in np.asarray(matrix, dtype=float).T:
        driven = np.abs(column) > 0
        out.append(float(share * np.min(forces[driven] / np.abs(column[driven]))) if driven.any() else 0.0)
    return tuple(out)


def derived_motion(model: ClosedFormModel) -> BatteryMotion:
    """A start near the model's first special state, moving, with inputs sized by its force scales."""
    n = model.nv
    angular = np.array(model.angular, dtype=bool)
    signs = np.array([(-1.0) ** i for i in range(n)])
    start = np.asarray(next(iter(model.special_states().values())), dtype=float)
    q = start + np.where(angular, ANGLE_STEP * signs * (1 + 0.5 * np.arange(n)), 0.0)
    v = np.where(angular, ANGULAR_RATE, LINEAR_RATE) * signs
    forces = force_scales(model, q)
    return BatteryMotion(
        q=tuple(float(x) for x in q),
        v=tuple(float(x) for x in v),
        input_amplitude=_sized(model.input_matrix(), forces, INPUT_SHARE) if model.inputs else (),
        disturbance_std=(
            _sized(model.disturbance_matrix(), forces, DISTURBANCE_SHARE) if model.disturbances else ()
        ),
    )


def _damping(model: ClosedFormModel, motion: BatteryMotion):
    """The damping effect: diag(max(D_ii, floor)) with a floor; else the model's D (None if zero)."""
    D = np.asarray(model.damping_matrix(), dtype=float)
    if motion.damping_floor > 0:
        return [max(float(d), motion.damping_floor) for d in np.diag(D)]
    return True if np.any(D != 0) else None


def effect_scenes(
    model_cls: type[ClosedFormModel], params: ParameterSet, duration: float, rtol: float, seed: int
) -> dict[str, dict]:
    """One short scene per effect the model has, as scene documents."""
    model = model_cls(params)
    motion = model_cls.battery_motion or derived_motion(model)
    base = {
        "model": model_cls,
        "parameters": params.as_dict(),
        "initial": {"q": list(motion.q), "v": list(motion.v)},
        "time": {"duration": duration, "sample_rate": 50.0},
        "integrator": {"method": "DOP853", "rtol": rtol, "atol": rtol},
    }
    effects: dict[str, dict] = {"gravity": {"gravity": True}}
    damping = _damping(model, motion)
    if damping is not None:
        effects["damping"] = {"gravity": True, "damping": damping}
    if model_cls.inputs:
        amplitude = list(motion.input_amplitude)
        sine = {"type": "sine", "amplitude": amplitude, "frequency": motion.input_frequency}
        effects["actuation"] = {"gravity": True, "actuation": sine}
    if model_cls.disturbances:
        noise = {
            "type": "noise",
            "std": list(motion.disturbance_std),
            "bandwidth": motion.disturbance_bandwidth,
            "seed": seed,
        }
        effects["disturbance"] = {"gravity": True, "disturbance": noise}
    return {name: {**base, "name": f"battery:{name}", "effects": e} for name, e in effects.items()}
