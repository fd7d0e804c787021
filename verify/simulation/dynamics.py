"""The right-hand side of a scene, assembled from its declared effects alone.

    M(q) q̈ + C(q, q̇) q̇ + H_g(q) = Σ active generalized forces

Only the terms a scene turns on are built: with damping off there is no
friction term at all (not a zero one), with gravity off H is zero (the engine
is built with g = 0), with no actuation or disturbance there is no input path.
``terms`` lists what is in the dynamics, for the summary.

Engines, both fed the same generalized force τ (model coordinates):

* ``aba``: Pinocchio's ABA on the scene's URDF (``urdf``, or ``simulate --urdf``), else, for a
  built-in model, on the URDF the project writes for the scene's parameter set; a model file
  (plug-in) has no such writer, so it needs a URDF for ``aba`` and ``both``;
* ``closed_form``: the hand model's control-affine form,
  q̈ = f₀(x) + g(x) τ with f₀ = −M⁻¹ (C q̇ + H) and g(x) = M⁻¹ — the reference systems' f
  and g, with friction entering τ as −D q̇ only when damping is on.

Besides (q, q̇) the integrated state carries the work integrals, so that the
energy balance is checked on the integrator's own steps:
W_in = ∫ q̇ᵀ (B u + W w) dt and W_diss = ∫ q̇ᵀ D q̇ dt.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from pendverify.analytic import MODELS, ClosedFormModel  # noqa: F401  (MODELS: the scenes' built-ins)
from pendverify.errors import SceneError
from pendverify.robot.system import PinocchioSystem
from pendverify.simulation.lqr import (
    closed_form_linearisation,
    linearisation_error,
    lqr_gain,
    pinocchio_linearisation,
)
from pendverify.simulation.scene import Scene
from pendverify.targets import target_system


@dataclass
class Dynamics:
    model: ClosedFormModel
    system: PinocchioSystem | None
    engine: str
    terms: list[str]
    generalized_force: Callable[[float, np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]
    u_of: Callable | None
    w_of: Callable | None
    D: np.ndarray | None
    urdf: str | None = None  # the URDF given (scene or --urdf), None: the project's for the parameter set

    @property
    def nv(self) -> int:
        return self.model.nv

    def acceleration(self, q, v, tau, engine: str | None = None) -> np.ndarray:
        engine = engine or self.engine
        if engine == "aba":
            return self.system.acceleration(q, v, tau)
        return self.model.inverse_mass_matrix(q) @ (tau - self.model.bias(q, v))

    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        n = self.nv
        q, v = x[:n], x[n : 2 * n]
        tau_in, tau_diss = self.generalized_force(t, q, v)
        a = self.acceleration(q, v, tau_in + tau_diss)
        return np.concatenate([v, a, [v @ tau_in, -(v @ tau_diss)]])

    def energy(self, q, v) -> float:
        """E = T + V of the system being integrated: Pinocchio's under ABA, the hand model's otherwise."""
        if self.engine == "aba":
            return self.system.kinetic_energy(q, v) + self.system.potential_energy(q)
        return self.model.kinetic_energy(q, v) + self.model.potential_energy(q)

    def inputs(self, t, q, v) -> tuple[np.ndarray, np.ndarray]:
        u = self.u_of(t, q, v) if self.u_of else np.zeros(len(self.model.inputs))
        w = self.w_of(t, q, v) if self.w_of else np.zeros(len(self.model.disturbances))
        return u, w


def build_dynamics(scene: Scene, engine: str | None = None, urdf: str | None = None) -> Dynamics:
    """Model, engine and force terms for a scene; LQR gains are computed here.

    ``urdf`` (text or path) replaces the URDF the project writes for the scene's
    parameter set, e.g. to simulate a user's URDF that is being certified.
    """
    engine = engine or scene.engine
    if engine == "closed_form" and not scene.model_cls.has_potential_energy():
        raise SceneError(
            scene.source,
            "engine",
            engine,
            f"closed_form integrates {scene.model_cls.name}'s own equations and records their energy "
            "½q̇ᵀMq̇ + V(q), but the model gives no potential energy V(q) (potential_energy): "
            "use aba or both, whose energy is Pinocchio's",
        )
    g = scene.gravity if scene.gravity is not None else 0.0
    params = scene.params.replace(g=g)
    model = scene.model_cls(params)
    urdf = urdf or scene.urdf
    system = None
    if engine in ("aba", "both"):
        system = _system(scene, params, urdf, engine)
    terms = ["inertia M(q)q̈", "Coriolis/centrifugal C(q,q̇)q̇"]
    terms.append(f"gravity H(q), g = {g:g} m/s²" if scene.gravity is not None else "gravity: off (H = 0)")

    parts_in: list[Callable] = []
    u_of = w_of = None
    if scene.actuation is not None:
        law = scene.actuation
        B = model.input_matrix()
        if law.kind == "lqr":
            _prepare_lqr(law, model, system or _system(scene, params, urdf, "lqr"), scene)
        u_of = law
        parts_in.append(lambda t, q, v: B @ law(t, q, v))
        terms.append(f"actuation B·u ({law.kind}{', feedback' if law.feedback else ''})")
    if scene.disturbance is not None:
        dist = scene.disturbance
        W = model.disturbance_matrix()
        w_of = dist
        parts_in.append(lambda t, q, v: W @ dist(t, q, v))
        terms.append(f"disturbance W·w ({dist.kind})")
    D = None
    if scene.damping is not None:
        D = scene.damping_matrix
        if np.any(D - np.diag(np.diag(D))):
            rows = "; ".join(", ".join(f"{d:g}" for d in row) for row in D)
            terms.append(f"friction −D·q̇, D = [{rows}]")
        else:
            terms.append(f"friction −D·q̇, D = diag({', '.join(f'{d:g}' for d in scene.damping)})")

    zero = np.zeros(model.nv)

    def generalized_force(t, q, v):
        tau_in = zero.copy()
        for part in parts_in:
            tau_in = tau_in + part(t, q, v)
        tau_diss = -(D @ v) if D is not None else zero
        return tau_in, tau_diss

    if engine == "both":
        engine = "aba"
    return Dynamics(model, system, engine, terms, generalized_force, u_of, w_of, D, urdf)


def _system(scene: Scene, params, urdf: str | None, needed_by: str) -> PinocchioSystem:
    """Pinocchio's side: the given URDF, else the project's URDF of a built-in parameter set."""
    if urdf is None and scene.model_file is not None:
        what = (
            "the lqr actuation linearises with Pinocchio"
            if needed_by == "lqr"
            else f"engine {needed_by} integrates ABA"
        )
        raise SceneError(
            scene.source,
            "urdf",
            None,
            f"missing key: {what} on a URDF, and the model file {scene.model_file} has none "
            "the project can write (give urdf = FILE or --urdf)",
        )
    return target_system(scene.model_cls, urdf, params, scene.name)


def _prepare_lqr(law, model, system, scene) -> None:
    D = scene.damping_matrix if scene.damping is not None else np.zeros((model.nv, model.nv))
    closed = closed_form_linearisation(model, D, law.q_star)
    pinocchio = pinocchio_linearisation(system, model, D, law.q_star)
    law.spec["linearisation_error"] = linearisation_error(closed, pinocchio)
    try:
        law.K = lqr_gain(closed, np.diag(law.Q), np.diag(law.R))
    except (ValueError, np.linalg.LinAlgError) as exc:
        raise SceneError(
            scene.source,
            "effects.actuation",
            "lqr",
            f"no LQR gain about {law.equilibrium!r}: the Riccati equation has no stabilising "
            f"solution for this Q, R and linearisation ({exc})",
        ) from None
    closed_loop = np.linalg.eigvals(closed.A - closed.B @ law.K)
    law.spec["closed_loop_max_real"] = float(np.max(closed_loop.real))
