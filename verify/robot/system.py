"""A Pinocchio model evaluated in a closed-form model's coordinates: one constructor, ``for_model``.

``PinocchioSystem.for_model(cls, urdf)`` loads the URDF (``pendverify.robot.urdf``),
asks the model's geometry reader, or its declared map, for the coordinate map
(``pendverify.robot.geometry``), and hands every quantity Pinocchio computes back
in the model's coordinates.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pinocchio as pin

from pendverify.analytic import MODELS
from pendverify.display import listed, shortened
from pendverify.robot import seed_geometry  # noqa: F401  (registers the reference systems' readers)
from pendverify.robot.coordinates import CoordinateMap
from pendverify.robot.geometry import MODEL_FORM_RTOL, UrdfGeometry, reader
from pendverify.robot.joint_map import declared_geometry
from pendverify.robot.seed_geometry import DEFAULT_G
from pendverify.robot.urdf import LoadedUrdf, load_urdf
from pendverify.robot.writer import urdf_for
from pendverify.validate import finite_state


def geometry_for(cls, pin_model: pin.Model, source: str, g: float | None) -> UrdfGeometry:
    """The coordinate map of model class ``cls`` to a URDF: its reader's, or the one it declares."""
    if cls.geometry_reader:
        return reader(cls.geometry_reader)(pin_model, source, g)
    return declared_geometry(cls, pin_model, source)


class PinocchioSystem:
    """A Pinocchio model evaluated in a closed-form model's coordinates.

    ``mass_matrix``, ``coriolis_matrix``, ``gravity``, ``bias``, ``acceleration``, the energies
    and the rest take and return the model's coordinates (``cmap`` maps them to the URDF's
    joints); ``geometry`` is what the model's reader saw in the URDF (its parameters, where it
    reads them), ``notes`` what loading noticed, ``source`` where the URDF came from.
    """

    def __init__(
        self,
        model: pin.Model,
        geometry: UrdfGeometry,
        g: float,
        source: str,
        urdf: LoadedUrdf | None = None,
        model_form_rtol: float = MODEL_FORM_RTOL,
    ):
        self.model = model
        self.model.gravity.linear = np.array([0.0, 0.0, -g])
        self.data = model.createData()
        self.cmap = geometry.cmap
        self.geometry = geometry
        self.source = source
        self.urdf = urdf
        #: the model-form threshold (``MODEL_FORM_RTOL``; ``check --model-form-rtol``)
        self.model_form_rtol = model_form_rtol
        self._no_gravity = model.copy()
        self._no_gravity.gravity.linear = np.zeros(3)
        self._no_gravity_data = self._no_gravity.createData()

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
        urdf: str | Path | LoadedUrdf,
        g: float | None = None,
        source: str | None = None,
    ):
        """The one constructor: a description (path or XML text; URDF, xacro, MJCF) seen in model
        class ``model_cls``'s coordinates.

        ``g`` is the gravity of the closed form; if None, the description's own (an MJCF's
        ``<option gravity>``), else Pinocchio's default 9.81 m/s².  A description whose own g
        differs from ``g`` is evaluated with ``g``, and its notes say so.

        ``urdf`` may also be a description already read (``load_urdf``'s result): systems
        on the same description at several g then read it once.  Each system takes its own
        copy of the Pinocchio model (it sets the model's gravity), so the description given
        is left as it was; messages name the source it was read with (``source`` is unused).
        """
        if isinstance(urdf, LoadedUrdf):
            notes = list(urdf.reading_notes)
            loaded = dataclasses.replace(urdf, model=urdf.model.copy(), reading_notes=notes)
        else:
            loaded = load_urdf(urdf, source)
        own = loaded.facts.gravity
        if g is not None and own is not None and g != own:
            loaded.reading_notes.append(
                f"the description's own gravity is g = {own:g} m/s²; "
                f"it is evaluated with the closed form's g = {g:g}"
            )
        g = own if g is None else g
        geometry = geometry_for(model_cls, loaded.model, loaded.source, g)
        return cls(loaded.model, geometry, DEFAULT_G if g is None else g, loaded.source, loaded)

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
        form = self.geometry.model_form
        if form is not None and form.within(self.model_form_rtol):
            return form.allowance.copy()
        return np.zeros(self.model.nv)

    @property
    def notes(self) -> list[str]:
        """What reading the URDF noticed: parser messages, the base's offset, the map, the model form."""
        out = self.urdf.notes() if self.urdf is not None else []
        out += self.geometry.notes
        form = self.geometry.model_form
        if form is not None and form.within(self.model_form_rtol):  # beyond it, a failing row says so
            out.append(form.sentence(self.model_form_rtol))
        return out

    def with_map(self, cmap: CoordinateMap) -> PinocchioSystem:
        """The same URDF seen through another coordinate map (for testing hypotheses)."""
        geometry = dataclasses.replace(self.geometry, cmap=cmap)
        g = -float(self.model.gravity.linear[2])
        return PinocchioSystem(self.model.copy(), geometry, g, self.source, self.urdf, self.model_form_rtol)

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

    def _qv(self, theta, theta_dot=None):
        # Pinocchio turns a NaN angle into NaN results without a word: refuse it here.
        n = self.model.nv
        q = self.cmap.configuration(finite_state("q", theta, n, self.source))
        v = (
            np.zeros(n)
            if theta_dot is None
            else self.cmap.velocity(finite_state("v", theta_dot, n, self.source))
        )
        return q, v

    @staticmethod
    def _symmetric(upper: np.ndarray) -> np.ndarray:
        # Pinocchio's C++ fills only the upper triangle of M and M⁻¹ (one matrix, or a stack)
        return np.triu(upper) + np.swapaxes(np.triu(upper, 1), -1, -2)

    def mass_matrix(self, theta) -> np.ndarray:
        """M(θ) by CRBA, in the model's coordinates."""
        q, _ = self._qv(theta)
        return self.cmap.matrix_to_model(self._symmetric(pin.crba(self.model, self.data, q)))

    def det_mass_matrix(self, theta) -> float:
        """det of the CRBA matrix by LU (numpy), mapped to the model's coordinates."""
        q, _ = self._qv(theta)
        return (
            float(np.linalg.det(self._symmetric(pin.crba(self.model, self.data, q)))) * self.cmap.det_factor
        )

    def inverse_mass_matrix(self, theta) -> np.ndarray:
        """M(θ)⁻¹ by Pinocchio's computeMinverse, in the model's coordinates."""
        q, _ = self._qv(theta)
        return self.cmap.inverse_to_model(self._symmetric(pin.computeMinverse(self.model, self.data, q)))

    def bias(self, theta, theta_dot) -> np.ndarray:
        """C(θ, θ̇)·θ̇ + H(θ) by RNEA at zero acceleration, in the model's coordinates."""
        q, v = self._qv(theta, theta_dot)
        return self.cmap.force_to_model(pin.rnea(self.model, self.data, q, v, np.zeros(self.model.nv)))

    def gravity(self, theta) -> np.ndarray:
        """H(θ) by computeGeneralizedGravity, in the model's coordinates."""
        q, _ = self._qv(theta)
        return self.cmap.force_to_model(pin.computeGeneralizedGravity(self.model, self.data, q))

    def coriolis_matrix(self, theta, theta_dot) -> np.ndarray:
        """Pinocchio's Coriolis matrix C(θ, θ̇) (computeCoriolisMatrix), in the model's coordinates."""
        q, v = self._qv(theta, theta_dot)
        return self.cmap.matrix_to_model(pin.computeCoriolisMatrix(self.model, self.data, q, v))

    def mass_matrix_derivative(self, theta, theta_dot) -> np.ndarray:
        """Ṁ by Pinocchio's analytic RNEA derivatives, independent of its Coriolis matrix.

        With gravity off and v = 0, τ(q, 0, a) = M(q) a, so ∂τ/∂q(q, 0, e_j) · q̇ = Ṁ e_j.
        """
        q, v = self._qv(theta, theta_dot)
        m, d = self._no_gravity, self._no_gravity_data
        zero = np.zeros(m.nv)
        columns = []
        for j in range(m.nv):
            e_j = np.zeros(m.nv)
            e_j[j] = 1.0
            dtau_dq, _, _ = pin.computeRNEADerivatives(m, d, q, zero, e_j)
            columns.append(dtau_dq @ v)
        return self.cmap.matrix_to_model(np.column_stack(columns))

    def acceleration(self, theta, theta_dot, tau_theta) -> np.ndarray:
        """q̈ by ABA for a generalized force given in the model's coordinates."""
        q, v = self._qv(theta, theta_dot)
        tau = self.cmap.force_to_joints(finite_state("tau", tau_theta, self.model.nv, self.source))
        a = pin.aba(self.model, self.data, q, v, tau)
        return self.cmap.acceleration_to_model(a)

    def kinetic_energy(self, theta, theta_dot) -> float:
        """T(θ, θ̇) by computeKineticEnergy."""
        q, v = self._qv(theta, theta_dot)
        return float(pin.computeKineticEnergy(self.model, self.data, q, v))

    def potential_energy(self, theta) -> float:
        """V(θ) by computePotentialEnergy (Pinocchio's zero)."""
        q, _ = self._qv(theta)
        return float(pin.computePotentialEnergy(self.model, self.data, q))
