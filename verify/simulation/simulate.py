"""Run a scene: integrate, sample, check its invariants, compare engines.

``run_scene(scene)`` returns a ``Run`` holding the samples (t, q, v, u, w, E),
the integrator's own steps, the invariant results and, with engine ``both``,
the comparison of Pinocchio's ABA with the closed-form right-hand side
evaluated at the *same* states along the trajectory (two chaotic trajectories
separate for reasons that are not model errors, so they are never diffed).
"""

from __future__ import annotations

import io
from dataclasses import dataclass, field, replace

import numpy as np

from pendverify.checks.scaling import norm2, rate_scale, scaled_matrix, weights_at
from pendverify.checks.trust import EPS
from pendverify.display import html_table, shortened
from pendverify.errors import IntegrationError
from pendverify.jsonio import to_json, versions
from pendverify.simulation.dynamics import Dynamics, build_dynamics
from pendverify.simulation.integrate import Integration, integrate
from pendverify.simulation.invariants import (
    InvariantResult,
    adaptive_bound,
    energy_scale,
    evaluate,
    figures_of,
    residual,
    richardson_bound,
)
from pendverify.simulation.scene import Integrator, Scene

ENGINE_K = 16.0  # as the aba check: K·ε·(1 + |θ|max)


@dataclass(repr=False)
class Run:
    """One simulated scene: the samples, the integrator's record and the invariants' verdicts.

    ``t`` (s, the scene's sample times), ``q``, ``v`` (one row per sample, the model's
    coordinates), ``u``, ``w`` (inputs and disturbances), ``energy`` (J) are arrays;
    ``invariants`` holds one ``InvariantResult`` per invariant (name, error, tolerance,
    passed, detail), ``engine_comparison`` the ABA-vs-closed-form comparison (engine
    ``both``), ``notes`` what the run noticed.  ``passed`` is every invariant (and the
    comparison) passing.  ``scene``, ``dynamics`` and ``integration`` are what was run and how.
    ``metadata()``, ``to_npz_bytes()`` and ``to_csv()`` are the files ``pendverify simulate``
    writes.
    """

    scene: Scene
    dynamics: Dynamics
    integration: Integration
    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    u: np.ndarray
    w: np.ndarray
    energy: np.ndarray
    invariants: list[InvariantResult]
    engine_comparison: InvariantResult | None = None
    notes: list[str] = field(default_factory=list)

    @property
    def checks(self) -> list[InvariantResult]:
        """The invariants and, with engine ``both``, the engines' comparison."""
        return [*self.invariants, *([self.engine_comparison] if self.engine_comparison else [])]

    @property
    def passed(self) -> bool:
        """Whether every invariant (and, with engine ``both``, the engines' comparison) holds."""
        return all(c.passed for c in self.checks)

    @property
    def engine(self) -> str:
        """aba, closed_form or both (ABA integrated, compared with the closed form): what ran."""
        return "both" if self.engine_comparison is not None else self.dynamics.engine

    def __repr__(self) -> str:
        held = sum(c.passed for c in self.checks)
        return (
            f"<Run {shortened(self.scene.name, 80)!r} ({shortened(self.scene.model, 60)}): "
            f"engine {self.engine}, {self.scene.duration:g} s, {len(self.t)} samples, "
            f"{held}/{len(self.checks)} invariants hold: {'pass' if self.passed else 'FAIL'}>"
        )

    def _repr_html_(self) -> str:
        """A table of the invariants under a caption naming the scene, engine, duration and samples."""
        caption = (
            f"scene {self.scene.name} ({self.scene.model}): engine {self.engine}, "
            f"{self.scene.duration:g} s, {len(self.t)} samples, "
            f"{int(len(self.integration.steps_t) - 1)} steps: {'pass' if self.passed else 'FAIL'}"
        )
        header = ("invariant", "error", "tolerance", "worst t (s)", "result", "detail")
        rows = [
            (
                c.name,
                f"{c.error:.2e}",
                f"{c.tolerance:.2e}",
                f"{c.worst_t:.4g}",
                "pass" if c.passed else "FAIL",
                c.detail,
            )
            for c in self.checks
        ]
        return html_table(header, rows, caption, [not c.passed for c in self.checks])

    def metadata(self) -> dict:
        """The run's description: scene, model, parameters, engine, integrator, invariants, versions."""
        s = self.scene
        return {
            "scene": s.name,
            "scene_file": s.source,
            "model": s.model,
            **({"model_file": s.model_file} if s.model_file else {}),
            **({"urdf": _urdf_name(self.dynamics.urdf)} if self.dynamics.urdf else {}),
            "parameters": s.params.as_dict(),
            "parameters_source": s.params_source,
            "engine": self.engine,
            "integrator": s.integrator.describe(),
            "steps": int(len(self.integration.steps_t) - 1),
            "rhs_evaluations": int(self.integration.nfev),
            "terms": self.dynamics.terms,
            "invariants": [i.as_dict() for i in self.invariants],
            "passed": self.passed,
            "versions": versions(),
        }

    def to_npz_bytes(self) -> bytes:
        """The samples and ``metadata()`` as an ``.npz`` file's bytes."""
        buf = io.BytesIO()
        np.savez(
            buf,
            t=self.t,
            q=self.q,
            v=self.v,
            u=self.u,
            w=self.w,
            energy=self.energy,
            metadata=np.array(to_json(self.metadata())),
        )
        return buf.getvalue()

    def to_csv(self) -> str:
        """The samples as CSV: t, the coordinates, their rates, inputs, disturbances, energy."""
        coords = self.dynamics.model.coordinates
        cols = (
            ["t"]
            + list(coords)
            + [f"d{c}" for c in coords]
            + [f"u_{n}" for n in self.dynamics.model.inputs]
            + [f"w_{n}" for n in self.dynamics.model.disturbances]
            + ["energy"]
        )
        data = np.column_stack([self.t, self.q, self.v, self.u, self.w, self.energy])
        lines = [",".join(cols)] + [",".join(repr(float(x)) for x in row) for row in data]
        return "\n".join(lines) + "\n"


def _urdf_name(urdf) -> str:
    """The metadata's ``urdf``: a path or text as given; for a Pinocchio object, its source."""
    return urdf if isinstance(urdf, str) else urdf.source


def _breakpoints(scene: Scene) -> list[float]:
    laws = [law for law in (scene.actuation, scene.disturbance) if law is not None]
    return sorted({b for law in laws for b in law.breakpoints()})


def relative_differences(differences, scales) -> np.ndarray:
    """Each state's |Δq̈| (scaled) over its scale, the scale floored at ε × the scene's largest.

    A state's scale s = ‖M̃⁻¹‖·(F + ‖M̃‖·|q̃̈|) sums the sizes of the terms both engines add up
    there, so their rounding is at most a few ε·s.  Floor: a force below ε × the largest
    scale the scene reaches is below the rounding of that largest force, so the scene cannot
    tell it from zero; a state near rest (gravity off, no force yet) is judged at that
    resolution instead of dividing by its own vanishing scale.  A scene that never moves and
    feels no force has every scale 0: both engines then add only zero terms, which round to
    nothing, so an exact agreement (Δ = 0) is no error and any difference is an infinite one.
    """
    differences, scales = np.asarray(differences, dtype=float), np.asarray(scales, dtype=float)
    floor = EPS * float(np.max(scales, initial=0.0))
    scales = np.maximum(scales, floor)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(differences == 0.0, 0.0, differences / scales)


def _engine_comparison(dyn: Dynamics, steps_t, steps_x) -> InvariantResult:
    """ABA against the closed-form right-hand side at the trajectory's own states."""
    n, model = dyn.nv, dyn.model
    differences, scales, tolerances = [], [], []
    for t, x in zip(steps_t, steps_x, strict=True):
        q, v = x[:n], x[n : 2 * n]
        tau_in, tau_diss = dyn.generalized_force(t, q, v)
        tau = tau_in + tau_diss
        a_pin = dyn.acceleration(q, v, tau, "aba")
        a_cf = dyn.acceleration(q, v, tau, "closed_form")
        weights = weights_at(model, q)
        Minv = norm2(scaled_matrix(model.inverse_mass_matrix(q), 1 / weights))
        M = norm2(scaled_matrix(model.mass_matrix(q), weights))
        forces = rate_scale(model, q, v) * np.sum(np.abs(v / weights)) + np.max(
            weights * model.gravity_scale()
        )
        forces += np.max(weights * (np.abs(tau_in) + np.abs(tau_diss)))
        scales.append(Minv * (forces + M * np.max(np.abs(a_pin / weights))))
        differences.append(np.max(np.abs((a_pin - a_cf) / weights)))
        tolerances.append(ENGINE_K * EPS * (1 + np.max(np.abs(q[np.array(model.angular)]), initial=0.0)))
    result = figures_of(
        "engines agree: ABA vs closed-form q̈ at the same states",
        relative_differences(differences, scales),
        np.array(tolerances),
        steps_t,
        1.0,
        f"over {len(steps_t)} states",
    )
    return replace(result, scale=float("nan"))  # each state's error is relative to its own scale


def run_scene(scene: Scene, engine: str | None = None, urdf: str | None = None) -> Run:
    """Integrate ``scene`` (with ``engine`` instead of the scene's, and ``urdf`` instead of the
    URDF the project writes for its parameters, when given) and check its invariants."""
    engine = engine or scene.engine
    dyn = build_dynamics(scene, engine, urdf)
    x0 = np.concatenate([scene.q0, scene.v0, [0.0, 0.0]])
    n_samples = int(np.floor(scene.duration * scene.sample_rate + 1e-9)) + 1
    sample_times = np.arange(n_samples) / scene.sample_rate
    bps = _breakpoints(scene)
    try:
        run = integrate(dyn.rhs, x0, scene.duration, scene.integrator, sample_times, bps, label=scene.name)
    except IntegrationError as exc:  # name the scene's file
        raise IntegrationError(scene.source, exc.problem) from None
    scale = energy_scale(dyn, run.steps_x)
    if scene.integrator.adaptive:
        bound = adaptive_bound(dyn, run.steps_x, scene.integrator, scale)
    else:
        half = Integrator(scene.integrator.method, step=scene.integrator.step / 2)
        fine = integrate(dyn.rhs, x0, scene.duration, half, run.steps_t, bps, label=f"{scene.name} (h/2)")
        _, r_h = residual(dyn, run.steps_x)
        _, r_half = residual(dyn, fine.samples_x)
        bound = richardson_bound(r_h, r_half, scale)
    invariants = evaluate(dyn, scene, run.steps_t, run.steps_x, bound, scale)
    comparison = _engine_comparison(dyn, run.steps_t, run.steps_x) if engine == "both" else None

    n = dyn.nv
    q, v = run.samples_x[:, :n], run.samples_x[:, n : 2 * n]
    uw = [dyn.inputs(t, qi, vi) for t, qi, vi in zip(run.samples_t, q, v, strict=True)]
    u = np.array([a for a, _ in uw]).reshape(len(uw), -1)
    w = np.array([b for _, b in uw]).reshape(len(uw), -1)
    energy = np.array([dyn.energy(qi, vi) for qi, vi in zip(q, v, strict=True)])
    result = Run(scene, dyn, run, run.samples_t, q, v, u, w, energy, invariants, comparison)
    if scene.actuation is not None and scene.actuation.kind == "lqr":
        spec = scene.actuation.spec
        result.notes.append(
            f"LQR: Pinocchio (computeABADerivatives) vs closed-form linearisation differ by "
            f"{spec['linearisation_error']:.2e} (relative); closed-loop max Re λ = "
            f"{spec['closed_loop_max_real']:.3g} 1/s"
        )
    return result
