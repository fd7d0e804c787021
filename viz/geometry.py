"""The URDF's visuals as meshcat objects, posed by Pinocchio's forward kinematics.

The geometry on screen is the geometry that was verified: the URDF text comes
from ``pendverify.robot.writer.urdf_for`` (the same writer the checks and the
simulator use), or is the URDF a scene names (a model file's, ``VisualSystem.for_model``);
Pinocchio parses its ``<visual>`` elements (a mesh's ``package://PKG/...`` file found in its ROS
package, ``pendverify.robot.packages``) into a visual
``GeometryModel``, and ``pinocchio.visualize.MeshcatVisualizer`` turns every
``GeometryObject`` (box, cylinder, sphere, with the URDF material colour) into a
meshcat object at ``<root>/visuals/<geometry name>``.  Poses come from
``forwardKinematics`` + ``updateGeometryPlacements`` at the Pinocchio
configuration ``cmap.configuration(θ)`` of the model coordinates θ.

A URDF visual without a material (Pinocchio would draw it near-white, unseen on
the light grey background) takes the colour of its link from ``LINK_COLOURS``:
one colour per link, in the order the links' visuals come, so that neighbouring
links differ.  MJCF geoms keep their own colours (MuJoCo's default is mid grey).

A moving body without any visual geometry (a dynamics-only description) is drawn as a
skeleton, ``pendverify.viz.skeleton``: joint markers, rods between joints, centres of mass,
and ``VisualSystem.notes`` says so.

Only the poses of geometries attached to a moving joint are animated; those on
the world (the pendulum's pivot block, the cart's rail) are placed once.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from pendverify.analytic import ParameterSet
from pendverify.robot.jacobian import joint_jacobians
from pendverify.robot.packages import resolve_package_uris
from pendverify.robot.pinocchio_model import FORMAT as PINOCCHIO_FORMAT
from pendverify.robot.system import PinocchioSystem
from pendverify.robot.writer import urdf_for
from pendverify.viz.skeleton import with_skeleton

ROOT = "pendverify"


UP = np.array([0.0, 0.0, 1.0])

#: RGBA of the links whose URDF visuals name no material, one per link in turn (blue, orange,
#: green, red, violet, brown, pink, olive, teal): all dark enough to stand out on light grey
LINK_COLOURS = (
    (0.12, 0.47, 0.71, 1.0),
    (0.89, 0.47, 0.13, 1.0),
    (0.17, 0.63, 0.17, 1.0),
    (0.84, 0.15, 0.16, 1.0),
    (0.58, 0.40, 0.74, 1.0),
    (0.55, 0.34, 0.29, 1.0),
    (0.89, 0.47, 0.76, 1.0),
    (0.50, 0.50, 0.13, 1.0),
    (0.09, 0.75, 0.81, 1.0),
)


def colour_links_without_material(visual_model: pin.GeometryModel) -> None:
    """Give every visual that has no URDF material its link's colour from ``LINK_COLOURS``.

    Pinocchio's URDF reader marks a visual whose material it read (given colour or a
    named one defined in the file) with ``overrideMaterial``; the others keep
    Pinocchio's default near-white and are painted here, the same colour for every
    visual of one link."""
    link_index: dict[int, int] = {}
    for obj in visual_model.geometryObjects:
        if obj.overrideMaterial:
            continue
        k = link_index.setdefault(obj.parentFrame, len(link_index))
        obj.meshColor = np.array(LINK_COLOURS[k % len(LINK_COLOURS)])


def _urdf_visuals(model: pin.Model, urdf: str, source: str = "<URDF>") -> pin.GeometryModel:
    urdf = resolve_package_uris(urdf, source)  # package://PKG/... meshes: files in their package
    visual_model = pin.buildGeomFromUrdfString(model, urdf, pin.GeometryType.VISUAL)
    colour_links_without_material(visual_model)
    return visual_model


@dataclass
class VisualSystem:
    """A Pinocchio model with its visual geometry and the coordinate map of its closed form."""

    system: PinocchioSystem
    visual_model: pin.GeometryModel
    visual_data: pin.GeometryData
    urdf: str
    #: what drawing it noticed (a skeleton drawn where the description has no visual geometry)
    notes: tuple[str, ...] = ()

    @classmethod
    def _drawn(cls, system: PinocchioSystem, visual_model: pin.GeometryModel, urdf: str) -> VisualSystem:
        """The system with its visuals, a skeleton added where a moving body has none
        (``pendverify.viz.skeleton``)."""
        visual_model, notes = with_skeleton(system.model, visual_model, LINK_COLOURS, system.source)
        return cls(system, visual_model, visual_model.createData(), urdf, notes)

    @classmethod
    def from_params(cls, params: ParameterSet) -> VisualSystem:
        """The system whose URDF ``urdf_for(params)`` writes, with its visuals."""
        urdf = urdf_for(params)
        system = PinocchioSystem.from_urdf(params.model, urdf, params.g, f"<URDF of {params.model}>")
        return cls._drawn(system, _urdf_visuals(system.model, urdf), urdf)

    @classmethod
    def for_model(cls, model_cls, urdf: str | Path, g: float | None = None) -> VisualSystem:
        """A given description (path or XML text: URDF, xacro, MJCF) with its visuals, seen in
        ``model_cls``'s coordinates.

        The way a model file (plug-in) is drawn: its URDF is the one the simulation integrated.
        """
        system = PinocchioSystem.for_model(model_cls, urdf, g)
        loaded = system.urdf  # the verified text: a xacro file's is the URDF it expanded to
        if loaded.visual_model is not None:  # given with a Pinocchio model
            visual_model = loaded.visual_model.copy()
        elif loaded.format == PINOCCHIO_FORMAT and not loaded.text:  # a bare model: nothing to draw
            visual_model = pin.GeometryModel()
        elif loaded.format == "mjcf":
            from pendverify.robot.mjcf import mjcf_visuals  # imports MuJoCo: only for an MJCF

            visual_model = mjcf_visuals(system.model, loaded.text, loaded.source)
        elif loaded.format == "sdf":
            from pendverify.robot.sdf_visuals import sdf_visuals

            visual_model = sdf_visuals(system.model, loaded.text)
        else:
            visual_model = _urdf_visuals(system.model, loaded.text, loaded.source)
        return cls._drawn(system, visual_model, loaded.text)

    @property
    def objects(self) -> list[pin.GeometryObject]:
        return list(self.visual_model.geometryObjects)

    def node(self, obj: pin.GeometryObject) -> str:
        """The meshcat path of a geometry object, as Pinocchio's MeshcatVisualizer names it."""
        return f"{ROOT}/visuals/{obj.name}"

    def moving(self) -> list[pin.GeometryObject]:
        """Geometry objects attached to a joint (not to the world)."""
        return [o for o in self.objects if o.parentJoint != 0]

    def load_into(self, vis) -> None:
        """Send every visual to a meshcat visualizer through Pinocchio's MeshcatVisualizer."""
        from pinocchio.visualize import MeshcatVisualizer

        viz = MeshcatVisualizer(self.system.model, visual_model=self.visual_model)
        viz.initViewer(viewer=vis)
        viz.loadViewerModel(rootNodeName=ROOT)

    def placements(self, theta: np.ndarray) -> list[np.ndarray]:
        """The 4×4 world pose of every geometry object at model coordinates θ."""
        model, data = self.system.model, self.system.data
        q = self.system.cmap.configuration(np.asarray(theta, dtype=float))
        pin.forwardKinematics(model, data, q)
        pin.updateGeometryPlacements(model, data, self.visual_model, self.visual_data)
        return [self.visual_data.oMg[i].homogeneous.copy() for i in range(len(self.objects))]

    def tip_point(self) -> tuple[int, np.ndarray]:
        """(geometry index, point in that geometry's frame) of the tip of the last link.

        The tip is the far end of the last joint's cylinder (a coal cylinder runs
        along its local z); without a cylinder, the last joint's origin.
        """
        last = max(o.parentJoint for o in self.objects)
        for i, obj in enumerate(self.objects):
            if obj.parentJoint == last and type(obj.geometry).__name__ == "Cylinder":
                return i, np.array([0.0, 0.0, obj.geometry.halfLength])
        i = next(i for i, o in enumerate(self.objects) if o.parentJoint == last)
        return i, self.objects[i].placement.inverse().translation  # the joint's origin

    def radius(self, obj: pin.GeometryObject) -> float:
        """A bounding radius of a primitive about its own origin, in [m]."""
        geom = obj.geometry
        kind = type(geom).__name__
        if kind == "Box":
            return float(np.linalg.norm(geom.halfSide))
        if kind == "Cylinder":
            return float(np.hypot(geom.halfLength, geom.radius))
        if kind == "Sphere":
            return float(geom.radius)
        return 0.0

    def view_normal(self) -> np.ndarray:
        """Unit vector from the system towards the camera: the plane of motion seen face on.

        For a cart, the rail's direction points to the right of the screen; for a
        fixed-base chain, the horizontal h = up × a of ``pendverify.robot.system`` does.
        The first joint that fixes a plane decides: a hinge (its axis), or a slider whose rail
        is not vertical; a vertical slider (a lift) moves in every vertical plane, so the
        joints after it decide, and a robot of vertical sliders alone is seen along −y.
        """
        model, data = self.system.model, self.system.data
        motions = joint_jacobians(model, data, pin.neutral(model))
        for motion in motions.T:  # each joint's motion: linear part for a slider, angular for a hinge
            normal = np.cross(motion[:3], UP) if np.linalg.norm(motion[3:]) == 0.0 else motion[3:]
            size = np.linalg.norm(normal)  # then up × normal = the rail's direction, or h
            if size > 1e-9 * max(np.linalg.norm(motion), 1.0):
                return normal / size
        return np.array([0.0, -1.0, 0.0])
