"""SDFormat read by Drake (the optional extra ``pendverify[sdf]``) and handed to Pinocchio at full precision.

Drake's parser reads the document into a continuous ``MultibodyPlant`` (``Finalize()``d); the
Pinocchio model is built from the plant, joint by joint in the tree's order from the world:

* a Drake joint connects frame F (fixed on the parent body P, ``X_PF``) to frame M (fixed on the
  child body C, ``X_CM``); its motion is ``X_FM(q)``, a rotation about (revolute) or a
  translation along (prismatic) the joint's axis, expressed in F, equal to the identity at q = 0.
  So ``X_PC(q) = X_PF · X_FM(q) · X_CM⁻¹``.
* Pinocchio's joint frame is M.  Each Drake body B is carried by one Pinocchio joint J with a
  fixed pose ``X_JB`` (the world: joint 0, the identity); a joint's placement in its parent
  joint's frame is ``X_JP · X_PF``, and the child body's pose in the new joint's frame is
  ``X_MC = X_CM⁻¹``.  A weld carries its child body on the parent's joint, with
  ``X_JC = X_JP · X_PF · X_FM · X_CM⁻¹`` (its inertia appended to that joint; a body welded to
  the world takes no part in the dynamics).
* axes: ``revolute_axis()``/``translation_axis()`` in F (= M at q = 0): a joint along +x, +y or
  +z is Pinocchio's RX/RY/RZ (PX/PY/PZ), any other axis RevoluteUnaligned (PrismaticUnaligned),
  as Pinocchio's URDF reader does;
* each body's mass, centre of mass and rotational inertia about the centre of mass
  (``default_spatial_inertia()`` shifted to the centre of mass), expressed in the frame of the
  Pinocchio joint that carries it;
* joint damping ``default_damping()`` into ``model.damping``; the plant's gravity vector into
  ``model.gravity``.

Refused, with the reason: joints other than revolute, prismatic and weld (Pinocchio's
reference systems have no ball, planar or universal joint here); a body Drake makes free
(no joint to the world: Drake adds a floating joint); a joint actuator with a reflected rotor
inertia (``drake:rotor_inertia``, it changes M); more than one joint into one body (a closed chain).

Before any verdict, Drake's own dynamics are compared with Pinocchio's on ``CROSS_CHECK_STATES``
seeded states, in Pinocchio's coordinate order (Drake's q and v indices mapped through each
joint's ``position_start``/``velocity_start``): M by ``CalcMassMatrix`` against ``crba``, and
the bias ``C·v + g`` against ``rnea(q, v, 0)``.  Drake writes ``M v̇ + C(q, v) v = τ_g(q) + τ``:
``CalcBiasTerm`` is ``C v`` and ``CalcGravityGeneralizedForces`` is ``τ_g``, on the right-hand
side, so Pinocchio's bias is ``C v − τ_g``.  The tolerance: every entry of M is a sum over at
most n bodies of terms no larger than ``m_b R² + ‖I_b‖`` (R: the largest distance of a joint or
centre of mass from the origin at that state), the bias a sum of terms no larger than
``(m_b R² + ‖I_b‖ + m_b R)·‖v‖²∞ + m_b |g| (R + 1)``; each algorithm forms each term in a few
dozen floating-point operations, so the two agree to ``CROSS_CHECK_ULPS · n · ε`` times that
scale.  That is ~1e-12 relative: a disagreement beyond it is a conversion error, not rounding,
and the file is refused with the difference.

Drake logs through spdlog, which pydrake routes to Python's ``logging`` logger ``drake``; while
the file is read that logger's records are captured (not printed) and become the description's
log.  pydrake is imported only when an SDFormat file is read.
"""

from __future__ import annotations

import logging
from contextlib import contextmanager

import numpy as np
import pinocchio as pin

from pendverify.errors import UrdfShapeError

INSTALL_HINT = "pip install 'pendverify[sdf]'"
#: seeded states the cross-check compares Drake and Pinocchio on
CROSS_CHECK_STATES = 5
CROSS_CHECK_SEED = 20260301
#: multiples of n·ε of a term's scale that two double-precision algorithms may differ by (see above)
CROSS_CHECK_ULPS = 64.0
_UNIT_AXES = {0: "X", 1: "Y", 2: "Z"}


def import_drake(source: str):
    """pydrake's parser and plant, or the one line naming the extra to install."""
    try:
        from pydrake.multibody.parsing import Parser
        from pydrake.multibody.plant import MultibodyPlant
    except ImportError:
        raise UrdfShapeError(
            source,
            f"an SDFormat description (<sdf>): reading it needs the optional extra: {INSTALL_HINT}",
        ) from None
    return Parser, MultibodyPlant


def build_from_drake(text: str, source: str) -> tuple[pin.Model, list[str]]:
    """(Pinocchio model, Drake's log lines) of an SDFormat document; see the module docstring."""
    Parser, MultibodyPlant = import_drake(source)
    plant = MultibodyPlant(0.0)
    with captured_drake_log() as log:
        try:
            Parser(plant).AddModelsFromString(text, "sdf")
            plant.Finalize()
        except Exception as exc:  # Drake's parser reports every problem as a RuntimeError
            reason = " ".join(str(exc).split())
            raise UrdfShapeError(source, f"Drake cannot read it as SDFormat: {reason}") from None
    model, order = _pinocchio_model(plant, source)
    cross_check(plant, model, order, source)
    return model, log


def _pinocchio_model(plant, source: str) -> tuple[pin.Model, list]:
    """The Pinocchio model of a finalised plant, and its Drake joints in Pinocchio's joint order."""
    from pydrake.multibody.tree import JointIndex

    joints = [plant.get_joint(JointIndex(i)) for i in range(plant.num_joints())]
    into: dict[int, object] = {}
    for joint in joints:
        child = int(joint.child_body().index())
        if child in into:
            raise UrdfShapeError(
                source, f"body {joint.child_body().name()!r} has two joints into it (a closed chain); refused"
            )
        into[child] = joint
    model = pin.Model()
    model.name = plant.GetModelInstanceName(joints[0].model_instance()) if joints else "sdf"
    model.gravity.linear = np.array(plant.gravity_field().gravity_vector(), dtype=float)
    carried = {int(plant.world_body().index()): (0, pin.SE3.Identity())}  # body → (joint, X_JB)
    order, damping = [], []
    pending = list(joints)
    while pending:
        ready = [j for j in pending if int(j.parent_body().index()) in carried]
        if not ready:
            names = ", ".join(repr(j.name()) for j in pending)
            raise UrdfShapeError(source, f"joints {names} do not reach the world; refused")
        for joint in ready:
            pending.remove(joint)
            parent_joint, X_JP = carried[int(joint.parent_body().index())]
            X_PF = se3(joint.frame_on_parent().GetFixedPoseInBodyFrame())
            X_CM = se3(joint.frame_on_child().GetFixedPoseInBodyFrame())
            child = joint.child_body()
            kind = joint.type_name()
            if kind == "weld":
                X_JC = X_JP * X_PF * se3(joint.X_FM()) * X_CM.inverse()
                carried[int(child.index())] = (parent_joint, X_JC)
                model.addBodyFrame(child.name(), parent_joint, X_JC, -1)  # where its visuals hang
                if parent_joint != 0:
                    model.appendBodyToJoint(parent_joint, _inertia(child, X_JC), pin.SE3.Identity())
                continue
            if kind == "quaternion_floating":
                raise UrdfShapeError(
                    source,
                    f"body {child.name()!r} has no joint to the world: Drake makes it free-floating; refused",
                )
            if kind not in ("revolute", "prismatic"):
                raise UrdfShapeError(
                    source,
                    f"joint {joint.name()!r} is {kind}: pendverify reads revolute, prismatic and fixed ones",
                )
            axis = np.array(
                joint.revolute_axis() if kind == "revolute" else joint.translation_axis(), dtype=float
            )
            jid = model.addJoint(parent_joint, _joint_model(kind, axis), X_JP * X_PF, joint.name())
            X_MC = X_CM.inverse()
            model.appendBodyToJoint(jid, _inertia(child, X_MC), pin.SE3.Identity())
            model.addBodyFrame(child.name(), jid, X_MC, model.addJointFrame(jid, -1))
            carried[int(child.index())] = (jid, X_MC)
            order.append(joint)
            damping.append(float(joint.default_damping()))
    for actuator in (plant.get_joint_actuator(i) for i in plant.GetJointActuatorIndices()):
        reflected = actuator.default_rotor_inertia() * actuator.default_gear_ratio() ** 2
        if reflected != 0:
            raise UrdfShapeError(
                source,
                f"actuator {actuator.name()!r} has a reflected rotor inertia of {reflected:g} kg·m²: "
                "it changes M, and pendverify reads none; refused",
            )
    model.damping = np.array(damping)
    return model, order


def se3(pose) -> pin.SE3:
    matrix = pose.GetAsMatrix4()
    return pin.SE3(np.array(matrix[:3, :3]), np.array(matrix[:3, 3]))


def _joint_model(kind: str, axis: np.ndarray):
    for i, letter in _UNIT_AXES.items():
        if np.array_equal(axis, np.eye(3)[i]):
            return getattr(pin, f"JointModel{'R' if kind == 'revolute' else 'P'}{letter}")()
    if kind == "revolute":
        return pin.JointModelRevoluteUnaligned(axis)
    return pin.JointModelPrismaticUnaligned(axis)


def _inertia(body, X_JB: pin.SE3) -> pin.Inertia:
    """Body B's inertia (mass, centre of mass, rotational inertia about it) in the frame of joint J."""
    spatial = body.default_spatial_inertia()
    com = np.array(spatial.get_com(), dtype=float)
    about_com = spatial.Shift(com).CalcRotationalInertia().CopyToFullMatrix3()
    R = X_JB.rotation
    return pin.Inertia(float(spatial.get_mass()), X_JB.act(com), R @ np.array(about_com) @ R.T)


def cross_check(plant, model: pin.Model, order: list, source: str) -> None:
    """Drake's M and bias against Pinocchio's at seeded states (see the module docstring)."""
    n = model.nv
    if n == 0:
        return
    q_index = np.array([j.position_start() for j in order])
    v_index = np.array([j.velocity_start() for j in order])
    context = plant.CreateDefaultContext()
    data = model.createData()
    rng = np.random.default_rng(CROSS_CHECK_SEED)
    revolute = np.array([j.type_name() == "revolute" for j in order])
    for _ in range(CROSS_CHECK_STATES):
        q = np.where(revolute, rng.uniform(-np.pi, np.pi, n), rng.uniform(-1.0, 1.0, n))
        v = rng.uniform(-2.0, 2.0, n)
        q_drake, v_drake = np.zeros(plant.num_positions()), np.zeros(plant.num_velocities())
        q_drake[q_index], v_drake[v_index] = q, v
        plant.SetPositions(context, q_drake)
        plant.SetVelocities(context, v_drake)
        M_drake = plant.CalcMassMatrix(context)[np.ix_(v_index, v_index)]
        bias_drake = (plant.CalcBiasTerm(context) - plant.CalcGravityGeneralizedForces(context))[v_index]
        M_pin = pin.crba(model, data, q)
        M_pin = np.triu(M_pin) + np.triu(M_pin, 1).T
        bias_pin = pin.rnea(model, data, q, v, np.zeros(n))
        scale_M, scale_bias = _scales(model, data, q, v)
        for what, a, b, scale in (
            ("M", M_pin, M_drake, scale_M),
            ("the bias", bias_pin, bias_drake, scale_bias),
        ):
            tolerance = CROSS_CHECK_ULPS * n * np.finfo(float).eps * scale
            difference = float(np.max(np.abs(a - b)))
            if not difference <= tolerance:
                raise UrdfShapeError(
                    source,
                    f"Pinocchio's model of Drake's plant disagrees with Drake on {what} by {difference:.3g} "
                    f"(tolerance {tolerance:.3g}) at q = {np.round(q, 6).tolist()}: refused",
                )


def _scales(model: pin.Model, data: pin.Data, q: np.ndarray, v: np.ndarray) -> tuple[float, float]:
    """The scales of M's and the bias's terms at (q, v) (module docstring): Σ_b m_b R² + ‖I_b‖, and
    Σ_b (m_b R² + ‖I_b‖ + m_b R)·‖v‖²∞ + m_b |g| (R + 1), R the largest distance of a joint or a
    centre of mass from the origin."""
    pin.forwardKinematics(model, data, q)
    bodies = range(1, model.njoints)
    reach = max(
        max(float(np.linalg.norm(data.oMi[j].act(model.inertias[j].lever))) for j in bodies),
        max(float(np.linalg.norm(data.oMi[j].translation)) for j in bodies),
    )
    masses = np.array([model.inertias[j].mass for j in bodies])
    inertias = np.array([np.linalg.norm(model.inertias[j].inertia, 2) for j in bodies])
    g = float(np.linalg.norm(model.gravity.linear))
    inertial = masses * reach**2 + inertias
    speed = float(np.max(np.abs(v))) ** 2
    scale_M = float(np.sum(inertial))
    scale_bias = float(np.sum((inertial + masses * reach) * speed + masses * g * (reach + 1.0)))
    tiny = np.finfo(float).tiny
    return max(scale_M, tiny), max(scale_bias, tiny)


class _Collect(logging.Handler):
    """A logging handler that keeps each record's message as one line."""

    def __init__(self) -> None:
        super().__init__()
        self.lines: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.lines.append(" ".join(record.getMessage().split()))


@contextmanager
def captured_drake_log():
    """Records of Python's ``drake`` logger (pydrake's spdlog sink) as lines, kept from the terminal:
    the logger's own handlers (pydrake may add one) are set aside meanwhile."""
    logger = logging.getLogger("drake")
    collect = _Collect()
    handlers, propagate = list(logger.handlers), logger.propagate
    logger.handlers = [collect]
    logger.propagate = False
    try:
        yield collect.lines
    finally:
        logger.handlers = handlers
        logger.propagate = propagate
