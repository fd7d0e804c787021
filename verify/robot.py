"""Load a URDF into Pinocchio, check its shape, and evaluate it in a model's coordinates.

Shape rules (anything else is a ``UrdfShapeError`` naming the file and the rule):

* ``double_pendulum``: a fixed base and a chain of exactly two revolute (or
  continuous) joints with parallel axes, perpendicular to gravity (−z), joint 2
  off joint 1's axis.
* ``cart_double_pendulum``: a horizontal prismatic joint followed by two revolute
  joints whose axes are parallel and perpendicular to the rail and to gravity.

The coordinate map (``pendverify.coordinates``) is read off the geometry at
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

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pinocchio as pin

from pendverify.analytic import DoublePendulumParams, ParameterSet
from pendverify.coordinates import CoordinateMap
from pendverify.errors import ParameterError, UrdfShapeError
from pendverify.validate import finite_state

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
    #: Known bound on |H_urdf − H_seed| per coordinate that the seed's form cannot
    #: represent (an off-line centre of mass); zero for URDFs inside the family.
    gravity_allowance: np.ndarray | None = None
    notes: list[str] = field(default_factory=list)


def load_model(urdf: str | Path, source: str | None = None) -> tuple[pin.Model, str]:
    """Parse a URDF file (or XML text) into a Pinocchio model; errors name the source."""
    if isinstance(urdf, Path) or (isinstance(urdf, str) and not urdf.lstrip().startswith("<")):
        path = Path(urdf)
        source = source or str(path)
        if not path.is_file():
            raise UrdfShapeError(source, "file not found")
        text = path.read_text()
    else:
        text, source = urdf, source or "<urdf text>"
    try:
        return pin.buildModelFromXML(text), source
    except (RuntimeError, ValueError) as exc:
        raise UrdfShapeError(source, f"Pinocchio cannot parse it as URDF: {exc}") from None


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

    p1, p2 = data.oMi[1].translation, data.oMi[2].translation
    c1 = data.oMi[1].act(model.inertias[1].lever)
    c2 = data.oMi[2].act(model.inertias[2].lever)
    link = plane(p2 - p1)
    l1 = float(np.linalg.norm(link))
    _require(l1 > 0, source, "joint 2 lies on joint 1's axis (l1 = 0)")
    gamma1 = math.atan2(link[1], link[0])
    along, across = link / l1, np.array([-link[1], link[0]]) / l1
    r1_along = float(plane(c1 - p1) @ along)
    d1 = float(plane(c1 - p1) @ across)  # centre of mass off the joint line
    r1 = math.hypot(r1_along, d1)  # the seed's r1 is the distance, which is all M sees
    com2 = plane(c2 - p2)
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
    allowance = np.zeros(2)
    if d1 != 0.0:
        # |ΔH1| = m1·g·|(r1 − r_along) cos θ1 + d1 sin θ1| ≤ m1·g·|c1 − seed's c1|
        allowance[0] = params.m1 * g * math.hypot(r1 - r1_along, d1)
        notes.append(
            f"link 1's centre of mass is {d1:.3g} m off the joint-1→joint-2 line "
            f"({math.atan2(d1, r1_along):.2g} rad); the seed's H cannot express this, "
            f"so H1 is allowed to differ by up to m1·g·|offset| = {allowance[0]:.3g} N·m"
        )
    if gamma1 != 0.0 or psi2 != gamma1 or sign2 < 0:
        notes.append(
            f"angle map: θ1 = q1 {gamma1:+.6g} rad, "
            f"θ2 = {'' if sign2 > 0 else '−'}q2 {psi2 - gamma1:+.6g} rad"
        )
    return UrdfGeometry(cmap, params, allowance, notes)


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

    p1, p2 = data.oMi[2].translation, data.oMi[3].translation
    c2 = data.oMi[3].act(model.inertias[3].lever)
    phi1, phi2 = lean(p2 - p1), lean(c2 - p2) - lean(p2 - p1)
    # θ = A q + θ0 with A = [[1,0,0],[0,s1,0],[0,s1,s2]]; T = A⁻¹.
    A = np.array([[1.0, 0, 0], [0, s1, 0], [0, s1, s2]])
    theta0 = np.array([float(p1 @ rail), phi1, phi1 + phi2])
    nq = tuple(model.joints[i].nq for i in (1, 2, 3))
    return UrdfGeometry(CoordinateMap(np.linalg.inv(A), theta0, nq))


class PinocchioSystem:
    """A Pinocchio model evaluated in a closed-form model's coordinates."""

    def __init__(self, model: pin.Model, geometry: UrdfGeometry, g: float, source: str):
        self.model = model
        self.model.gravity.linear = np.array([0.0, 0.0, -g])
        self.data = model.createData()
        self.cmap = geometry.cmap
        self.geometry = geometry
        self.source = source
        self._no_gravity = model.copy()
        self._no_gravity.gravity.linear = np.zeros(3)
        self._no_gravity_data = self._no_gravity.createData()

    @classmethod
    def from_urdf(cls, model_name: str, urdf: str | Path, g: float | None = None, source: str | None = None):
        model, source = load_model(urdf, source)
        if model_name == "double_pendulum":
            geometry = double_pendulum_geometry(model, source, g)
        elif model_name == "cart_double_pendulum":
            geometry = cart_double_pendulum_geometry(model, source)
        else:
            raise ValueError(f"no URDF reader for model {model_name!r}")
        return cls(model, geometry, DEFAULT_G if g is None else g, source)

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
