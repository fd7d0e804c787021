"""Benchmark problems: a scene (any model: built in, or a model file with its parameters and URDF)
over a horizon, compiled, with what is compared.

A problem is a scene's initial state and declared effects run over ``duration``: the
model's generated back ends under the scene's force law (``numerics.generate``), the
closed-form ``Dynamics`` for the invariant checks, and a Pinocchio system on the scene's
URDF (or the URDF the project writes for a built-in parameter set) for scipy's ``aba``.
Every problem carries its ``metric``: "state" (states against a Taylor reference) or
"energy" (relative energy error only; conservative scenes).

Where problems come from: the shipped scenes ``scenes/bench/*.toml`` (``shipped_problems``, the
default run: the problem's key is the file's name, its title the scene's name, and the run's
configuration says which are compared by energy alone), or a user's scene (``scene_problems``,
``pendverify bench accuracy --scene``):

* a state problem over min(the scene's duration, ``Config.scene_horizon``: 10 s full,
  3 s quick) — the references are Taylor series in decimal arithmetic, whose cost grows
  with the horizon, and a chaotic scene's double-precision solutions stop agreeing with
  any reference a few seconds in (the default run's ``chaotic`` is compared over 2 s);
* when the scene is conservative (no damping, actuation or disturbance), an energy-only
  long run of ``Config.scene_long`` seconds (1000 s full, 200 s quick), as the default run's ``long``.

The state problem is the scene's anchor: the single-trajectory ratio, the engine study
and the ensemble run on it.  Each problem's scene keeps its model, parameters, URDF and
effects; its time and integrator are the benchmark's (DOP853 at 1e-10 for the
invariant checks, ``grid_intervals`` + 1 dense points).

Refused, as a one-line error naming the scene file and the reason: a time-varying effect
or a saturated LQR (``FastPathError``: the fast path does not compile it), a model whose
generated field or energy the Taylor references cannot take, a model file without a URDF.

URDFs with continuous joints (cos φ, sin φ in Pinocchio's configuration): scipy integrates
the model's coordinates and each ``aba`` call writes Pinocchio's configuration from them
with the system's coordinate map (``continuous_aba``, engine label ``aba (cos/sin per
call)``); the engine study then has no ``crba_cholesky`` or ``minverse`` rows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from pendverify.errors import InputError, PendverifyError
from pendverify.numerics.generate import GeneratedSystem
from pendverify.numerics.integrators.taylor import energy_above_minimum, float_system
from pendverify.shipped import shipped_folder
from pendverify.simulation import engines
from pendverify.simulation.dynamics import build_dynamics
from pendverify.simulation.engine_names import PINOCCHIO_ENGINES
from pendverify.simulation.scene import Integrator, Scene, load_scene

METRICS = ("state", "energy")
INVARIANT_INTEGRATOR = Integrator("DOP853", 1e-10, 1e-10)


@dataclass(frozen=True)
class ProblemSpec:
    key: str
    title: str
    scene: Scene
    metric: str = "state"  # "state" or "energy"


@dataclass
class Problem:
    key: str
    title: str
    scene: Scene
    dynamics: object  # pendverify.simulation.dynamics.Dynamics (closed form, with its Pinocchio system)
    fast: GeneratedSystem  # the model's generated back ends and the scene's force law
    x0: np.ndarray
    duration: float
    grid: np.ndarray
    metric: str  # "state" or "energy"

    @property
    def conservative(self) -> bool:
        return self.fast.conservative

    @property
    def continuous_joints(self) -> bool:
        return any(nq != 1 for nq in self.dynamics.system.cmap.joint_nq)


def _scene(spec: ProblemSpec, duration: float, grid_intervals: int) -> Scene:
    rate = grid_intervals / duration
    return replace(spec.scene, duration=duration, sample_rate=rate, integrator=INVARIANT_INTEGRATOR)


def _refuse(scene: Scene, exc: Exception, what: str) -> InputError:
    value = scene.model_file or scene.model
    return InputError(scene.source, "model", value, f"cannot benchmark: {what}: {exc}")


def build_problem(spec: ProblemSpec, duration: float, grid_intervals: int = 64) -> Problem:
    """The problem ``spec`` over ``duration``, or a one-line ``PendverifyError`` naming the scene."""
    if spec.metric not in METRICS:
        raise ValueError(f"{spec.key}: metric {spec.metric!r}, expected one of {METRICS}")
    scene = _scene(spec, duration, grid_intervals)
    dyn = build_dynamics(scene, "both")  # the closed form, and Pinocchio's system for aba
    fast = GeneratedSystem.from_dynamics(dyn, scene.source)
    x0 = np.concatenate([scene.q0, scene.v0])
    try:
        system = float_system(fast)
    except PendverifyError as exc:
        raise _refuse(scene, exc, "the Taylor references integrate the generated field") from None
    if fast.conservative:
        try:
            energy_above_minimum(system, list(x0))
        except PendverifyError as exc:
            raise _refuse(scene, exc, "the energy errors need the generated energy") from None
    grid = np.linspace(0.0, duration, grid_intervals + 1)
    return Problem(spec.key, spec.title, scene, dyn, fast, x0, duration, grid, spec.metric)


def shipped_problems(energy_only: tuple = ()) -> dict[str, ProblemSpec]:
    """The default run's problems by key: each shipped scene ``scenes/bench/KEY.toml``, titled by
    its name, compared by its energy when KEY is in ``energy_only``, else by its states."""
    specs = {}
    for path in sorted(shipped_folder("bench").glob("*.toml")):
        scene = load_scene(path)
        specs[path.stem] = ProblemSpec(
            path.stem, scene.name, scene, "energy" if path.stem in energy_only else "state"
        )
    return specs


def scene_problems(path, config) -> tuple[object, dict[str, ProblemSpec]]:
    """(the configuration for a user's scene, its problems): see the module docstring."""
    scene = load_scene(path)
    key = Path(path).stem
    specs = {key: ProblemSpec(key, scene.name, scene, "state")}
    horizons = {key: min(scene.duration, config.scene_horizon)}
    if scene.conservative:
        long = f"{key}_long"
        specs[long] = ProblemSpec(long, f"{scene.name}, long run (energy)", scene, "energy")
        horizons[long] = config.scene_long
    name = f"{config.name}, scene {Path(path).name}"
    energy_only = tuple(k for k, s in specs.items() if s.metric == "energy")
    config = replace(
        config, name=name, horizons=horizons, anchor=key, engine_problems=(key,), energy_only=energy_only
    )
    return config, specs


def continuous_aba(problem: Problem) -> engines.EngineRhs:
    """scipy's ``aba`` on a URDF with continuous joints, in the model's coordinates: each call
    writes Pinocchio's configuration (cos φ, sin φ for a continuous joint) from the joint angles
    q = T (θ − θ0) (``robot.coordinates``; its ``configuration``, a general loop, costs 4× aba)."""
    import pinocchio as pin

    system, fast, n = problem.dynamics.system, problem.fast, problem.fast.nv
    model, data, cmap = system.model, system.data, system.cmap
    T, theta0, T_inv = cmap.T, cmap.theta0, np.linalg.inv(cmap.T)
    slots = list(zip(np.cumsum((0, *cmap.joint_nq[:-1])).tolist(), cmap.joint_nq, strict=True))
    B, K, u0, D = fast.B, fast.K, fast.u0, fast.D
    forced = not fast.conservative
    zero = np.zeros(n)
    config = np.empty(model.nq)

    def fun(t, x):
        theta, rate = x[:n], x[n:]
        tau = T_inv.T @ (B @ (u0 - K @ x) - D @ rate) if forced else zero
        for angle, (i, nq) in zip((T @ (theta - theta0)).tolist(), slots, strict=True):
            if nq == 1:
                config[i] = angle
            else:
                config[i], config[i + 1] = math.cos(angle), math.sin(angle)
        a = pin.aba(model, data, config, T @ rate, tau)
        return np.concatenate([rate, T_inv @ a])

    def same(x):
        return np.asarray(x, float)

    return engines.EngineRhs("aba (cos/sin per call)", fun, same, same)


def engine_rhs(problem: Problem, engine: str) -> engines.EngineRhs | None:
    """The right-hand side of ``engine`` on the problem's URDF; None if that engine cannot take it."""
    if engine in PINOCCHIO_ENGINES and problem.continuous_joints:
        return continuous_aba(problem) if engine == "aba" else None
    return engines.build(engine, problem.dynamics.model, problem.fast, problem.dynamics.system)
