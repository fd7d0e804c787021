"""A Pinocchio model evaluated in a closed-form model's coordinates.

Three constructors, all through ``for_model``: ``for_model(cls, urdf)`` for any model class
and description; ``for_params(params)`` for a built-in parameter set on the URDF the project
writes for it (``pendverify.robot.writer``); ``from_urdf(name, urdf)`` for a built-in model
given by its name.  ``PinocchioSystem(model, geometry, g, source)`` itself takes a Pinocchio
model and a coordinate map already made: ``with_map`` (the same description through another
map) and the diagnosis's inertia traps (another Pinocchio model of the same description) use it.

``PinocchioSystem.for_model(cls, urdf)`` loads the description
(``pendverify.robot.description.load_description``),
asks the model's geometry reader, or its declared map, for the coordinate map
(``pendverify.robot.geometry``), and hands every quantity Pinocchio computes back
in the model's coordinates: ``at(θ, θ̇)`` for a batch of states
(``pendverify.robot.batch.PinocchioBatch``, the one evaluator), and one method per
quantity for one state, which is the batch of one.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pinocchio as pin

from pendverify.analytic import MODELS
from pendverify.analytic.reference_geometry import READERS
from pendverify.display import listed, shortened
from pendverify.errors import UnknownNameError
from pendverify.robot.batch import PinocchioBatch, finite_rows
from pendverify.robot.coordinates import CoordinateMap
from pendverify.robot.description import LoadedDescription, load_description
from pendverify.robot.finite_terms import check_finite_terms
from pendverify.robot.geometry import DEFAULT_G, MODEL_FORM_RTOL, ModelForm, UrdfGeometry, combined
from pendverify.robot.gravity_tilt import tilt_form
from pendverify.robot.joint_map import declared_geometry
from pendverify.robot.writer import urdf_for
from pendverify.validate import finite_state


def geometry_for(cls, pin_model: pin.Model, source: str, g: float | None) -> UrdfGeometry:
    """The coordinate map of model class ``cls`` to a URDF: its reader's, or the one it declares."""
    if cls.geometry_reader:
        if cls.geometry_reader not in READERS:
            raise UnknownNameError("geometry reader", cls.geometry_reader, tuple(READERS))
        return READERS[cls.geometry_reader](pin_model, source, g)
    return declared_geometry(cls, pin_model, source)


class PinocchioSystem:
    """A Pinocchio model evaluated in a closed-form model's coordinates.

    ``mass_matrix``, ``coriolis_matrix``, ``gravity``, ``bias``, ``acceleration``, the energies
    and the rest take and return the model's coordinates (``cmap`` maps them to the URDF's
    joints); ``geometry`` is what the model's reader saw in the URDF (its parameters, where it
    reads them), ``notes`` what loading noticed, ``source`` where the URDF came from.

    Made by ``for_model`` (a model class and a description); ``for_params`` and ``from_urdf`` are
    ``for_model`` for a built-in model; ``with_map`` and ``with_gravity`` derive a system from one
    already read.  The constructor takes the parts these have read.
    """

    def __init__(
        self,
        model: pin.Model,
        geometry: UrdfGeometry,
        g: float,
        source: str,
        urdf: LoadedDescription | None = None,
        model_form_rtol: float = MODEL_FORM_RTOL,
        gravity_vector=None,
        model_cls=None,
    ):
        self.model = model
        #: the closed form's gravity (m/s²) this system is evaluated with
        self.g = g
        self.model.gravity.linear = np.array([0.0, 0.0, -g] if gravity_vector is None else gravity_vector)
        self.data = model.createData()
        self.cmap = geometry.cmap
        self.geometry = geometry
        #: the description's gravity tilted off −z, a term the closed form's scalar g cannot express
        #: (``pendverify.robot.gravity_tilt``); None when Pinocchio's gravity is along −z
        self.tilt = None if gravity_vector is None else tilt_form(model, geometry.cmap, gravity_vector)
        self.source = source
        self.urdf = urdf
        #: the closed-form model class whose coordinates these are (None: not given)
        self.model_cls = model_cls
        #: the model-form threshold (``MODEL_FORM_RTOL``; ``check --model-form-rtol``)
        self.model_form_rtol = model_form_rtol
        #: a copy of the model with gravity off, and its data (Ṁ from RNEA's derivatives)
        self.model_without_gravity = model.copy()
        self.model_without_gravity.gravity.linear = np.zeros(3)
        self.data_without_gravity = self.model_without_gravity.createData()

    def __repr__(self) -> str:
        joints = listed(self.model.names[1:], 80)
        g = -float(self.model.gravity.linear[2])
        return (
            f"<PinocchioSystem {shortened(self.source, 120)}: {self.model.nv} dof (joints {joints}), "
            f"g = {g:g} m/s²>"
        )

    @classmethod
    def for_model(
        cls,
        model_cls,
        urdf: str | Path | LoadedDescription,
        g: float | None = None,
        source: str | None = None,
    ):
        """A description (path or XML text; URDF, xacro, MJCF) seen in model class ``model_cls``'s
        coordinates: the constructor ``for_params`` and ``from_urdf`` call.

        ``g`` is the gravity of the closed form; if None, the description's own (an MJCF's
        ``<option gravity>``), else Pinocchio's default 9.81 m/s².  A description whose own g
        differs from ``g`` is evaluated with ``g``, and its notes say so.

        ``urdf`` may also be a description already read (``load_description``'s result): systems
        on the same description at several g then read it once.  Each system takes its own
        copy of the Pinocchio model (it sets the model's gravity), so the description given
        is left as it was; messages name the source it was read with (``source`` is unused).
        """
        if isinstance(urdf, LoadedDescription):
            notes = list(urdf.reading_notes)
            loaded = dataclasses.replace(urdf, model=urdf.model.copy(), reading_notes=notes)
        else:
            loaded = load_description(urdf, source)
        check_finite_terms(loaded.model, loaded.source)
        own = loaded.facts.gravity
        if g is not None and own is not None and g != own:
            loaded.reading_notes.append(
                f"the description's own gravity is g = {own:g} m/s²; "
                f"it is evaluated with the closed form's g = {g:g}"
            )
        vector = loaded.facts.gravity_vector
        if g is not None and g != own:
            vector = None  # the closed form's g along −z replaces the file's gravity
        g = own if g is None else g
        geometry = geometry_for(model_cls, loaded.model, loaded.source, g)
        g = DEFAULT_G if g is None else g
        source = loaded.source
        return cls(loaded.model, geometry, g, source, loaded, gravity_vector=vector, model_cls=model_cls)

    @classmethod
    def for_params(cls, params, source: str | None = None):
        """``for_model`` on the URDF the project writes for a built-in parameter set (``robot.writer``)."""
        return cls.for_model(MODELS[params.model], urdf_for(params), params.g, source)

    @classmethod
    def from_urdf(cls, model_name: str, urdf: str | Path, g: float | None = None, source: str | None = None):
        """``for_model`` for a built-in model given by its name (``pendverify.analytic.MODELS``)."""
        return cls.for_model(MODELS[model_name], urdf, g, source)

    @property
    def allowance(self) -> np.ndarray:
        """|ΔH| per coordinate the checks allow for a term the closed form cannot express.

        The model-form bound while the term is within ``model_form_rtol``; beyond it,
        nothing: the URDF is outside the family and the checks say so by failing.
        """
        form = self.model_form
        if form is not None and form.within(self.model_form_rtol):
            return form.allowance.copy()
        return np.zeros(self.model.nv)

    def energy_allowance(self, theta) -> np.ndarray:
        """|ΔV(θ) − ΔV(0)| per state θ (N, n) a model-form term within the threshold may cause.

        A bounded term (an off-line centre of mass: |ΔV| ≤ its allowance at each end) gives
        2·Σ a; a term whose potential grows with the coordinates (a gravity tilt along a slide)
        is the integral of ΔH from 0 to θ, at most Σ a_i |θ_i| on the straight path.
        """
        a = self.allowance
        out = np.full(len(theta), 2 * float(np.sum(a)))
        form = self.model_form
        if form is not None and form.potential_grows and np.any(a):
            out = out + np.abs(np.asarray(theta, dtype=float)) @ a
        return out

    @property
    def notes(self) -> list[str]:
        """What reading the URDF noticed: parser messages, the base's offset, the map, the model form."""
        out = self.urdf.notes() if self.urdf is not None else []
        out += self.geometry.notes
        form = self.model_form
        if form is not None and form.within(self.model_form_rtol):  # beyond it, a failing row says so
            out.append(form.sentence(self.model_form_rtol))
        return out

    @property
    def model_form(self) -> ModelForm | None:
        """What of the description the closed form cannot express: the geometry reader's term and
        the gravity's tilt, as one (``pendverify.robot.geometry.combined``)."""
        return combined([self.geometry.model_form, self.tilt])

    def with_map(self, cmap: CoordinateMap) -> PinocchioSystem:
        """The same URDF seen through another coordinate map (for testing hypotheses)."""
        geometry = dataclasses.replace(self.geometry, cmap=cmap)
        gravity = self.model.gravity.linear.copy()
        return PinocchioSystem(
            self.model.copy(),
            geometry,
            -float(gravity[2]),
            self.source,
            self.urdf,
            self.model_form_rtol,
            gravity_vector=None if self.tilt is None else gravity,
            model_cls=self.model_cls,
        )

    def with_gravity(self, g: float) -> PinocchioSystem:
        """The same description at the closed form's gravity ``g`` along −z, as ``for_model`` would
        make it from the description already read: the Pinocchio model copied, the coordinate map
        read again at ``g`` (a reader's parameters and model-form terms carry g).  What a stress
        case at another g evaluates (zero gravity) without reading the description again."""
        geometry = geometry_for(self.model_cls, self.model, self.source, g)
        cls, rtol = self.model_cls, self.model_form_rtol
        return PinocchioSystem(self.model.copy(), geometry, g, self.source, self.urdf, rtol, model_cls=cls)

    def urdf_damping(self) -> np.ndarray | None:
        """The joints' <dynamics damping> (joint coordinates, Pinocchio's order), or None if no joint has one.

        Pinocchio reads a missing attribute as 0; only the strict reader knows it was absent.
        """
        if self.urdf is None:
            return None
        declared = {
            name: d.damping for name, d in self.urdf.facts.joint_dynamics.items() if d.damping is not None
        }
        if not declared:
            return None
        return np.array([declared.get(self.model.names[j], 0.0) for j in range(1, self.model.njoints)])

    def urdf_coulomb_friction(self) -> dict[str, float]:
        """{joint: <dynamics friction>} for every joint whose Coulomb friction is non-zero."""
        if self.urdf is None:
            return {}
        return {name: d.friction for name, d in self.urdf.facts.joint_dynamics.items() if d.friction}

    def at(self, theta, theta_dot=None) -> PinocchioBatch:
        """Pinocchio at states θ (N, n) and θ̇ (N, n; default zero), in the model's coordinates;
        a state that is not finite is refused by name."""
        n = self.model.nv
        theta = finite_rows("q", theta, n, self.source)
        theta_dot = np.zeros_like(theta) if theta_dot is None else finite_rows("v", theta_dot, n, self.source)
        if theta_dot.shape != theta.shape:
            raise ValueError(f"{theta.shape[0]} positions but {theta_dot.shape[0]} velocities")
        return PinocchioBatch(self, theta, theta_dot)

    def _one(self, theta, theta_dot=None) -> PinocchioBatch:
        """The batch of the one state (θ, θ̇); a state that is not finite is refused by name."""
        n = self.model.nv
        theta = finite_state("q", theta, n, self.source)
        theta_dot = np.zeros(n) if theta_dot is None else finite_state("v", theta_dot, n, self.source)
        return PinocchioBatch(self, theta[None], theta_dot[None])

    def mass_matrix(self, theta) -> np.ndarray:
        """M(θ) by CRBA, in the model's coordinates."""
        return self._one(theta).mass_matrix()[0]

    def det_mass_matrix(self, theta) -> float:
        """det of the CRBA matrix by LU (numpy), mapped to the model's coordinates."""
        return float(self._one(theta).det_mass_matrix()[0])

    def inverse_mass_matrix(self, theta) -> np.ndarray:
        """M(θ)⁻¹ by Pinocchio's computeMinverse, in the model's coordinates."""
        return self._one(theta).inverse_mass_matrix()[0]

    def bias(self, theta, theta_dot) -> np.ndarray:
        """C(θ, θ̇)·θ̇ + H(θ) by RNEA at zero acceleration, in the model's coordinates."""
        return self._one(theta, theta_dot).bias()[0]

    def gravity(self, theta) -> np.ndarray:
        """H(θ) by computeGeneralizedGravity, in the model's coordinates."""
        return self._one(theta).gravity()[0]

    def coriolis_matrix(self, theta, theta_dot) -> np.ndarray:
        """Pinocchio's Coriolis matrix C(θ, θ̇) (computeCoriolisMatrix), in the model's coordinates."""
        return self._one(theta, theta_dot).coriolis_matrix()[0]

    def mass_matrix_derivative(self, theta, theta_dot) -> np.ndarray:
        """Ṁ by Pinocchio's analytic RNEA derivatives (``PinocchioBatch.mass_matrix_derivative``)."""
        return self._one(theta, theta_dot).mass_matrix_derivative()[0]

    def acceleration(self, theta, theta_dot, tau_theta) -> np.ndarray:
        """q̈ by ABA for a generalized force given in the model's coordinates."""
        tau = finite_state("tau", tau_theta, self.model.nv, self.source)
        return self._one(theta, theta_dot).acceleration(tau[None])[0]

    def kinetic_energy(self, theta, theta_dot) -> float:
        """T(θ, θ̇) by computeKineticEnergy."""
        return float(self._one(theta, theta_dot).kinetic_energy()[0])

    def potential_energy(self, theta) -> float:
        """V(θ) by computePotentialEnergy (Pinocchio's zero)."""
        return float(self._one(theta).potential_energy()[0])
