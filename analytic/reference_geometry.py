"""The geometry readers of the two reference systems: their coordinate maps (and the double pendulum's
parameters) read off a URDF.

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

``READERS`` holds both under the names their models give in ``geometry_reader``
(``pendverify.robot.system.geometry_for`` looks them up).
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from pendverify.analytic.cart_double_pendulum import CartDoublePendulum
from pendverify.analytic.double_pendulum import DoublePendulum, DoublePendulumParams
from pendverify.errors import ParameterError, UrdfShapeError
from pendverify.robot.coordinates import CoordinateMap
from pendverify.robot.geometry import DEFAULT_G, GeometryReader, ModelForm, UrdfGeometry

PARALLEL_TOL = 1e-9  # |sin| of the angle between axes that count as parallel

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
    """Read the double pendulum's parameters and coordinate map off a two-revolute-joint URDF."""
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
    r1 = math.hypot(r1_along, d1)  # the closed form's r1 is the distance, which is all M sees
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
        # |ΔH1| = m1·g·|(r1 − r_along) cos θ1 + d1 sin θ1| ≤ m1·g·|c1 − the closed form's c1|
        offset = math.hypot(r1 - r1_along, d1)
        allowance = np.array([params.m1 * g * offset, 0.0])
        # relative to H1's size g·(m1 r1 + m2 (l1 + r2)); g cancels, so g = 0 is no special case
        relative = params.m1 * offset / (params.m1 * params.r1 + params.m2 * (params.l1 + params.r2))
        model_form = ModelForm(
            f"link 1's centre of mass is {abs(d1):.3g} m off the joint-1→joint-2 line "
            f"({math.atan2(d1, r1_along):.2g} rad); the closed form's H has no term for it: "
            f"up to m1·g·|offset| = {allowance[0]:.3g} N·m on H1",
            float(relative),
            allowance,
        )
    if gamma1 != 0.0 or psi2 != gamma1 or sign2 < 0:
        notes.append(
            f"angle map: θ1 = q1 {gamma1:+.6g} rad, "
            f"θ2 = {'' if sign2 > 0 else '−'}q2 {psi2 - gamma1:+.6g} rad"
        )
    return UrdfGeometry(cmap, params, model_form, notes)


def cart_double_pendulum_geometry(model: pin.Model, source: str, g: float | None = None) -> UrdfGeometry:
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
    p1 = data.oMi[2].translation  # the base is anchored at the origin (``load_description``)
    phi1, phi2 = lean(rod1), lean(rod2) - lean(rod1)
    # θ = A q + θ0 with A = [[1,0,0],[0,s1,0],[0,s1,s2]]; T = A⁻¹.
    A = np.array([[1.0, 0, 0], [0, s1, 0], [0, s1, s2]])
    theta0 = np.array([float(p1 @ rail), phi1, phi1 + phi2])
    nq = tuple(model.joints[i].nq for i in (1, 2, 3))
    return UrdfGeometry(CoordinateMap(np.linalg.inv(A), theta0, nq))


#: reader name (a model class's ``geometry_reader``) → the reader
READERS: dict[str, GeometryReader] = {
    DoublePendulum.geometry_reader: double_pendulum_geometry,
    CartDoublePendulum.geometry_reader: cart_double_pendulum_geometry,
}
