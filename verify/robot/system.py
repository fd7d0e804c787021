"""Load a URDF into Pinocchio, check its shape, and evaluate it in a model's coordinates.

Shape rules (anything else is a ``UrdfShapeError`` naming the file and the rule):

* ``double_pendulum``: a fixed base and a chain of exactly two revolute (or
  continuous) joints with parallel axes, perpendicular to gravity (−z), joint 2
  off joint 1's axis.
* ``cart_double_pendulum``: a horizontal prismatic joint followed by two revolute
  joints whose axes are parallel and perpendicular to the rail and to gravity.

The coordinate map (``pendverify.robot.coordinates``) is read off the geometry at
q = 0, so any zero and any axis sign are accepted: for the double pendulum θ1 is
the direction of joint 2 seen from joint 1, measured from the horizontal
h = up × a (a: joint 1's axis) towards up; θ1 + θ2 is the direction of link 2's
centre of mass seen from joint 2.  For the cart, θi is the direction of rod i
(joint 1 → joint 2, joint 2 → centre of mass of rod 2) measured from upright
towards the rail's axis.

``PinocchioSystem`` evaluates the algorithms and hands every quantity back in
the model's coordinates.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pinocchio as pin

from pendverify.analytic import MODELS, DoublePendulumParams, ParameterSet
from pendverify.errors import ParameterError, UrdfShapeError
from pendverify.robot.coordinates import CoordinateMap
from pendverify.robot.strict import UrdfFacts, build_pinocchio_model
from pendverify.validate import finite_state

#: Largest relative size (|ΔH_i| / Σ|terms of H_i|) of a term the closed form cannot express
#: for which a URDF still counts as inside the model's family.  1e-4 passes mesh-derived
#: centres of mass rounded at the micrometre (example-robot-data: 7.6e-6) and fails
#: a 0.1 mm offset on a 0.5 m pendulum; ``pendverify check --model-form-rtol`` sets it.
MODEL_FORM_RTOL = 1e-4
PARALLEL_TOL = 1e-9  # |sin| of the angle between axes that count as parallel
DEFAULT_G = 9.81  # m/s², Pinocchio's default, used when a URDF alone is given

_REVOLUTE = {"JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned"}
_CONTINUOUS = {
    "JointModelRUBX",
    "JointModelRUBY",
    "JointModelRUBZ",
    "JointModelRevoluteUnboundedUnaligned",
}
_PRISMATIC = {"JointModelPX", "JointModelPY", "JointModelPZ", "JointModelPrismaticUnaligned"}


def _kind(joint) -> str:
    name = joint.shortname()
    if name in _REVOLUTE or name in _CONTINUOUS:
        return "revolute"
    if name in _PRISMATIC:
        return "prismatic"
    return name.removeprefix("JointModel")


@dataclass
class UrdfGeometry:
    """What the URDF's geometry says, in a model's terms."""

    cmap: CoordinateMap
    #: Parameters read off the URDF (double pendulum only; None for the cart).
    params: ParameterSet | None = None
    #: A term of the URDF the closed form cannot express (an off-line centre of
    #: mass); None for URDFs inside the family.
    model_form: ModelForm | None = None
    notes: list[str] = field(default_factory=list)


@dataclass
class ModelForm:
    """A URDF slightly outside a closed form's family: a term the closed form cannot express.

    ``relative`` is the term's size over the size of the quantity it enters
    (|ΔH_i| / Σ|terms of H_i|); ``allowance`` the bound on |ΔH| per coordinate that
    the checks may add while ``relative`` stays within the threshold
    (``MODEL_FORM_RTOL``, ``pendverify check --model-form-rtol``).
    """

    what: str
    relative: float
    allowance: np.ndarray

    def within(self, rtol: float) -> bool:
        return self.relative <= rtol

    def sentence(self, rtol: float) -> str:
        """What the term is, how large, and what the threshold makes of it."""
        if self.within(rtol):
            verdict = f"within the model-form threshold {rtol:g}: the checks allow for it"
        else:
            verdict = (
                f"above the model-form threshold {rtol:g} (--model-form-rtol): the URDF lies outside "
                "the closed form's family, and no allowance is made"
            )
        return f"{self.what}; that is {self.relative:.3g} of H1, {verdict}"


def _anchor_base(model: pin.Model) -> float:
    """Move each joint fixed to the world so that it sits at the origin; return the largest shift.

    A fixed base's dynamics do not depend on where it stands (gravity is uniform;
    V changes by a constant), but Pinocchio expresses spatial inertias about the
    world origin, so a base 1 km away makes its terms 1e6 times larger than the
    result and rounds them accordingly.  Only the translation of the placements
    of joints whose parent is the world changes; their rotation, which orients
    the robot against gravity, stays.
    """
    shift = 0.0
    for j in range(1, model.njoints):
        if model.parents[j] == 0:
            placement = model.jointPlacements[j]
            shift = max(shift, float(np.linalg.norm(placement.translation)))
            model.jointPlacements[j] = pin.SE3(placement.rotation, np.zeros(3))
    return shift


@dataclass
class LoadedUrdf:
    """A URDF in Pinocchio, read strictly first (``pendverify.robot.strict``), its base at the origin."""

    model: pin.Model
    source: str
    text: str
    facts: UrdfFacts
    #: distance of the fixed base from the world origin in the file [m]
    base_offset: float = 0.0
    #: what Pinocchio's parser logged while reading the file
    log: list[str] = field(default_factory=list)

    def notes(self) -> list[str]:
        out = [f"Pinocchio's URDF parser logged: {line}" for line in self.log]
        if self.base_offset > 0:
            out.append(
                f"the fixed base stands {self.base_offset:.6g} m from the world origin; it is evaluated "
                "at the origin (a fixed base's dynamics do not depend on where it stands)"
            )
        return out


def load_urdf(urdf: str | Path, source: str | None = None) -> LoadedUrdf:
    """Read a URDF file (or XML text) strictly, parse it with Pinocchio and anchor its base at the origin."""
    if isinstance(urdf, Path) or (isinstance(urdf, str) and not urdf.lstrip().startswith("<")):
        path = Path(urdf)
        source = source or str(path)
        if not path.is_file():
            raise UrdfShapeError(source, "file not found")
        text = read_text_file(path, source)
    else:
        text, source = urdf, source or "<urdf text>"
    model, facts, log = build_pinocchio_model(text, source)
    offset = _anchor_base(model)
    return LoadedUrdf(model, source, text, facts, offset, log)


def load_model(urdf: str | Path, source: str | None = None) -> tuple[pin.Model, str]:
    """A URDF in Pinocchio (see ``load_urdf``); errors name the source."""
    loaded = load_urdf(urdf, source)
    return loaded.model, loaded.source


def read_text_file(path: Path, source: str) -> str:
    """A user's text file as UTF-8 (a byte-order mark allowed); anything else is one clear error."""
    try:
        return path.read_bytes().decode("utf-8-sig")
    except IsADirectoryError:
        raise UrdfShapeError(source, "is a directory, not a file") from None
    except UnicodeDecodeError as exc:
        raise UrdfShapeError(source, f"not UTF-8 text (byte {exc.start}: {exc.reason})") from None
    except OSError as exc:
        raise UrdfShapeError(source, f"cannot be read: {exc.strerror}") from None


def _frames_at_zero(model: pin.Model):
    data = model.createData()
    q0 = pin.neutral(model)
    pin.forwardKinematics(model, data, q0)
    pin.computeJointJacobians(model, data, q0)
    return data


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _require(cond: bool, source: str, problem: str) -> None:
    if not cond:
        raise UrdfShapeError(source, problem)


def _check_chain(model: pin.Model, source: str, kinds: list[str]) -> None:
    found = [_kind(model.joints[i]) for i in range(1, model.njoints)]
    _require(
        found == kinds,
        source,
        f"expected a chain of joints {' → '.join(kinds)}, found {' → '.join(found) or 'none'} "
        "(fixed joints are merged)",
    )
    for i in range(2, model.njoints):
        _require(
            model.parents[i] == i - 1,
            source,
            f"joint {model.names[i]} is not a child of {model.names[i - 1]}",
        )


def _up(model: pin.Model) -> np.ndarray:
    return np.array([0.0, 0.0, 1.0])


def double_pendulum_geometry(model: pin.Model, source: str, g: float | None = None) -> UrdfGeometry:
    """Read the seed-000 parameters and coordinate map off a two-revolute-joint URDF."""
    _check_chain(model, source, ["revolute", "revolute"])
    data = _frames_at_zero(model)
    up = _up(model)
    a1, a2 = _unit(data.J[3:, 0]), _unit(data.J[3:, 1])
    _require(
        np.linalg.norm(np.cross(a1, a2)) < PARALLEL_TOL,
        source,
        f"joint axes {a1.round(6).tolist()} and {a2.round(6).tolist()} are not parallel: not a planar chain",
    )
    _require(
        abs(a1 @ up) < PARALLEL_TOL,
        source,
        f"joint axis {a1.round(6).tolist()} is not horizontal: the chain does not swing in a vertical plane",
    )
    horizontal = np.cross(up, a1)
    sign2 = 1.0 if a1 @ a2 > 0 else -1.0

    def plane(v: np.ndarray) -> np.ndarray:
        return np.array([v @ horizontal, v @ up])

    # Local frames only: joint 2 seen from joint 1 and each centre of mass from its own
    # joint, rotated into the world's orientation (rotations do not grow with distance).
    R1, R2 = data.oMi[1].rotation, data.oMi[2].rotation
    link = plane(R1 @ model.jointPlacements[2].translation)
    l1 = float(np.linalg.norm(link))
    _require(l1 > 0, source, "joint 2 lies on joint 1's axis (l1 = 0)")
    gamma1 = math.atan2(link[1], link[0])
    along, across = link / l1, np.array([-link[1], link[0]]) / l1
    com1 = plane(R1 @ model.inertias[1].lever)
    r1_along = float(com1 @ along)
    d1 = float(com1 @ across)  # centre of mass off the joint line
    r1 = math.hypot(r1_along, d1)  # the seed's r1 is the distance, which is all M sees
    com2 = plane(R2 @ model.inertias[2].lever)
    r2 = float(np.linalg.norm(com2))
    psi2 = math.atan2(com2[1], com2[0]) if r2 > 0 else gamma1

    def axis_inertia(j: int, axis: np.ndarray) -> float:
        local = data.oMi[j].rotation.T @ axis
        return float(local @ model.inertias[j].inertia @ local)

    g = DEFAULT_G if g is None else g
    damping = np.asarray(model.damping, dtype=float)
    values = dict(
        m1=model.inertias[1].mass,
        m2=model.inertias[2].mass,
        l1=l1,
        l2=2 * r2 if r2 > 0 else l1,
        r1=r1,
        r2=r2,
        I1=axis_inertia(1, a1),
        I2=axis_inertia(2, a1),
        b1=float(damping[0]) if damping.size else 0.0,
        b2=float(damping[1]) if damping.size else 0.0,
        g=g,
    )
    try:
        params = DoublePendulumParams.from_mapping(values, source)
    except ParameterError as exc:
        raise ParameterError(source, exc.key, exc.value, exc.rule + " (as read off the URDF)") from None
    nq = tuple(model.joints[i].nq for i in (1, 2))
    cmap = CoordinateMap(np.diag([1.0, sign2]), np.array([gamma1, psi2 - gamma1]), nq)
    notes = []
    model_form = None
    if d1 != 0.0:
        # |ΔH1| = m1·g·|(r1 − r_along) cos θ1 + d1 sin θ1| ≤ m1·g·|c1 − seed's c1|
        allowance = np.array([params.m1 * g * math.hypot(r1 - r1_along, d1), 0.0])
        h1_scale = g * (params.m1 * params.r1 + params.m2 * (params.l1 + params.r2))
        model_form = ModelForm(
            f"link 1's centre of mass is {abs(d1):.3g} m off the joint-1→joint-2 line "
            f"({math.atan2(d1, r1_along):.2g} rad); the seed's H has no term for it: "
            f"up to m1·g·|offset| = {allowance[0]:.3g} N·m on H1",
            float(allowance[0] / h1_scale),
            allowance,
        )
    if gamma1 != 0.0 or psi2 != gamma1 or sign2 < 0:
        notes.append(
            f"angle map: θ1 = q1 {gamma1:+.6g} rad, "
            f"θ2 = {'' if sign2 > 0 else '−'}q2 {psi2 - gamma1:+.6g} rad"
        )
    return UrdfGeometry(cmap, params, model_form, notes)


def cart_double_pendulum_geometry(model: pin.Model, source: str) -> UrdfGeometry:
    """The coordinate map of a cart with two rods: absolute angles from upright."""
    _check_chain(model, source, ["prismatic", "revolute", "revolute"])
    data = _frames_at_zero(model)
    up = _up(model)
    rail = _unit(data.J[:3, 0])
    _require(
        abs(rail @ up) < PARALLEL_TOL,
        source,
        f"the rail axis {rail.round(6).tolist()} is not horizontal",
    )
    expected = np.cross(up, rail)  # turning about it leans a rod from up towards the rail axis
    a1, a2 = _unit(data.J[3:, 1]), _unit(data.J[3:, 2])
    for name, a in (("pole 1", a1), ("pole 2", a2)):
        _require(
            np.linalg.norm(np.cross(a, expected)) < PARALLEL_TOL,
            source,
            f"{name} axis {a.round(6).tolist()} is not perpendicular to the rail and to gravity",
        )
    s1, s2 = (1.0 if a @ expected > 0 else -1.0 for a in (a1, a2))

    def lean(v: np.ndarray) -> float:
        return math.atan2(v @ rail, v @ up)

    # rod 1 (joint 1 → joint 2) and rod 2 (joint 2 → its centre of mass), in local frames
    rod1 = data.oMi[2].rotation @ model.jointPlacements[3].translation
    rod2 = data.oMi[3].rotation @ model.inertias[3].lever
    p1 = data.oMi[2].translation  # the base is anchored at the origin (``load_urdf``)
    phi1, phi2 = lean(rod1), lean(rod2) - lean(rod1)
    # θ = A q + θ0 with A = [[1,0,0],[0,s1,0],[0,s1,s2]]; T = A⁻¹.
    A = np.array([[1.0, 0, 0], [0, s1, 0], [0, s1, s2]])
    theta0 = np.array([float(p1 @ rail), phi1, phi1 + phi2])
    nq = tuple(model.joints[i].nq for i in (1, 2, 3))
    return UrdfGeometry(CoordinateMap(np.linalg.inv(A), theta0, nq))


class PinocchioSystem:
    """A Pinocchio model evaluated in a closed-form model's coordinates."""

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

    @classmethod
    def from_urdf(cls, model_name: str, urdf: str | Path, g: float | None = None, source: str | None = None):
        """A built-in model's URDF (path or XML text), seen through that model's ``urdf_geometry``."""
        loaded = load_urdf(urdf, source)
        geometry = MODELS[model_name].urdf_geometry(loaded.model, loaded.source, g)
        return cls(loaded.model, geometry, DEFAULT_G if g is None else g, loaded.source, loaded)

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
        # Pinocchio's C++ fills only the upper triangle of M and M⁻¹.
        return np.triu(upper) + np.triu(upper, 1).T

    def mass_matrix(self, theta) -> np.ndarray:
        q, _ = self._qv(theta)
        return self.cmap.matrix_to_model(self._symmetric(pin.crba(self.model, self.data, q)))

    def det_mass_matrix(self, theta) -> float:
        """det of the CRBA matrix by LU (numpy), mapped to the model's coordinates."""
        q, _ = self._qv(theta)
        return (
            float(np.linalg.det(self._symmetric(pin.crba(self.model, self.data, q)))) * self.cmap.det_factor
        )

    def inverse_mass_matrix(self, theta) -> np.ndarray:
        q, _ = self._qv(theta)
        return self.cmap.inverse_to_model(self._symmetric(pin.computeMinverse(self.model, self.data, q)))

    def bias(self, theta, theta_dot) -> np.ndarray:
        q, v = self._qv(theta, theta_dot)
        return self.cmap.force_to_model(pin.rnea(self.model, self.data, q, v, np.zeros(self.model.nv)))

    def gravity(self, theta) -> np.ndarray:
        q, _ = self._qv(theta)
        return self.cmap.force_to_model(pin.computeGeneralizedGravity(self.model, self.data, q))

    def coriolis_matrix(self, theta, theta_dot) -> np.ndarray:
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
        q, v = self._qv(theta, theta_dot)
        return float(pin.computeKineticEnergy(self.model, self.data, q, v))

    def potential_energy(self, theta) -> float:
        q, _ = self._qv(theta)
        return float(pin.computePotentialEnergy(self.model, self.data, q))
