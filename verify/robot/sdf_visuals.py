"""The visual geometry of an SDFormat description, as Drake's SceneGraph holds it, for Pinocchio.

``sdf_visuals`` parses the document again into a ``MultibodyPlant`` registered with a
``SceneGraph`` (the kinematic model built by ``pendverify.robot.sdf_drake`` needs none) and
turns each body's illustration geometry into a ``pinocchio.GeometryObject`` on that body's
frame of the Pinocchio model (every body has one, welded bodies included): its pose in the
body frame (``GetPoseInFrame``), its shape (boxes, spheres, cylinders, capsules and ellipsoids,
as ``coal`` shapes) and its diffuse colour.  Meshes and half-spaces are not drawn.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pendverify.robot.sdf_drake import captured_drake_log, se3

#: the diffuse colour of a geometry that states none (Drake's own default grey)
DEFAULT_RGBA = (0.9, 0.9, 0.9, 1.0)


def _shapes():
    import coal
    from pydrake.geometry import Box, Capsule, Cylinder, Ellipsoid, Sphere

    return {
        Box: lambda s: coal.Box(s.width(), s.depth(), s.height()),
        Sphere: lambda s: coal.Sphere(s.radius()),
        Cylinder: lambda s: coal.Cylinder(s.radius(), s.length()),
        Capsule: lambda s: coal.Capsule(s.radius(), s.length()),
        Ellipsoid: lambda s: coal.Ellipsoid(s.a(), s.b(), s.c()),
    }


def sdf_visuals(model: pin.Model, text: str) -> pin.GeometryModel:
    """Drake's illustration geometry of an SDFormat document (read already) on ``model``'s body frames."""
    from pydrake.geometry import Rgba
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
    from pydrake.multibody.tree import BodyIndex
    from pydrake.systems.framework import DiagramBuilder

    plant, scene_graph = AddMultibodyPlantSceneGraph(DiagramBuilder(), 0.0)
    with captured_drake_log():
        Parser(plant).AddModelsFromString(text, "sdf")
        plant.Finalize()
    inspector = scene_graph.model_inspector()
    shapes = _shapes()
    visuals = pin.GeometryModel()
    for index in range(plant.num_bodies()):
        body = plant.get_body(BodyIndex(index))
        if not model.existFrame(body.name(), pin.FrameType.BODY):
            continue  # the world
        frame = model.frames[model.getFrameId(body.name(), pin.FrameType.BODY)]
        for geometry in plant.GetVisualGeometriesForBody(body):
            shape = inspector.GetShape(geometry)
            make = shapes.get(type(shape))
            if make is None:
                continue
            placement = frame.placement * se3(inspector.GetPoseInFrame(geometry))
            obj = pin.GeometryObject(inspector.GetName(geometry), frame.parentJoint, placement, make(shape))
            properties = inspector.GetIllustrationProperties(geometry)
            colour = Rgba(*DEFAULT_RGBA)
            if properties is not None:
                colour = properties.GetPropertyOrDefault("phong", "diffuse", colour)
            obj.meshColor = np.array([colour.r(), colour.g(), colour.b(), colour.a()])
            visuals.addGeometryObject(obj)
    return visuals
