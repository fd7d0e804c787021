"""A coordinate map a model declares, checked against the URDF it is used with.

A plug-in model never has its map guessed from the URDF's geometry: it names the
URDF joints and gives T and θ0 of q = T (θ − θ0) (``pendverify.robot.coordinates``)::

    urdf_joints = ("cart_slider", "pole_hinge")   # the joint of each row of T
    joint_transform = ((1, 0), (0, -1))            # T (default: identity)
    joint_offset = (0.0, math.pi)                  # θ0 in the model's units (default: 0)

Rows are given in the order of ``urdf_joints`` and re-ordered here into
Pinocchio's joint order.  Every movable joint of the URDF must be named exactly
once and have one degree of freedom (revolute, continuous or prismatic);
anything else is an error naming the model file, the URDF and the joint.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pendverify.analytic.source_file import where
from pendverify.errors import PendverifyError, UrdfShapeError
from pendverify.robot.coordinates import CoordinateMap
from pendverify.robot.geometry import UrdfGeometry


def _matrix(cls, name: str, value, shape: tuple[int, ...]) -> np.ndarray:
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError):
        array = None
    if array is None or array.shape != shape or not np.all(np.isfinite(array)):
        raise PendverifyError(
            f"{where(cls)}: {cls.__name__}.{name} = {value!r} must be finite numbers of shape {shape}"
        )
    return array


def declared_geometry(cls, pin_model: pin.Model, source: str) -> UrdfGeometry:
    """The map ``cls`` declares, with its rows in Pinocchio's joint order."""
    n = len(cls.coordinates)
    declared = tuple(cls.urdf_joints)
    if not declared:
        raise PendverifyError(
            f"{where(cls)}: model {cls.name} does not say which URDF joint each coordinate is: "
            f"{cls.how_to_name_joints()}"
        )
    if len(declared) != n or len(set(declared)) != n:
        raise PendverifyError(
            f"{where(cls)}: {cls.__name__}.urdf_joints = {declared!r} must name {n} distinct joints, "
            f"one per coordinate {cls.coordinates!r}"
        )
    urdf = [pin_model.names[i] for i in range(1, pin_model.njoints)]
    for i in range(1, pin_model.njoints):
        if pin_model.joints[i].nv != 1:
            raise UrdfShapeError(
                source,
                f"joint {pin_model.names[i]} has {pin_model.joints[i].nv} degrees of freedom; "
                "a declared coordinate map needs one-degree-of-freedom joints",
            )
    missing = [j for j in declared if j not in urdf]
    extra = [j for j in urdf if j not in declared]
    if missing or extra:
        parts = []
        if missing:
            parts.append(f"{', '.join(missing)} not in the URDF")
        if extra:
            parts.append(f"the URDF's {', '.join(extra)} not declared")
        raise PendverifyError(
            f"{where(cls)} against {source}: urdf_joints {declared!r} do not match the URDF's movable "
            f"joints {tuple(urdf)!r} ({'; '.join(parts)}; fixed joints are merged)"
        )
    T = (
        np.eye(n)
        if cls.joint_transform is None
        else _matrix(cls, "joint_transform", cls.joint_transform, (n, n))
    )
    theta0 = np.zeros(n) if cls.joint_offset is None else _matrix(cls, "joint_offset", cls.joint_offset, (n,))
    if abs(np.linalg.det(T)) < 1e-12:
        raise PendverifyError(f"{where(cls)}: {cls.__name__}.joint_transform {T.tolist()} is not invertible")
    order = [declared.index(name) for name in urdf]
    nq = tuple(pin_model.joints[i].nq for i in range(1, pin_model.njoints))
    cmap = CoordinateMap(T[order], theta0, nq)
    note = (
        f"coordinate map declared by {cls.__name__}: q = T (θ − θ0) with joints {tuple(urdf)}, "
        f"T = {T[order].tolist()}, θ0 = {theta0.tolist()}"
    )
    return UrdfGeometry(cmap, notes=[note])
