"""Pinocchio's MJCF reader run on text the strict MJCF reader accepted, its output captured.

``build_mjcf_model`` reads the text strictly (``pendverify.robot.mjcf_strict``), writes that
same text to a temporary file (Pinocchio's Python bindings read MJCF from a file only; the
kinematic model needs no mesh, so the file's folder does not matter) and runs
``pinocchio.buildModelFromMJCF`` on it with file descriptors 1 and 2 captured.  Then it
checks that Pinocchio built what the strict reader read: the same joints in the same order,
and for each the same damping, armature and friction loss (MuJoCo's reading of the default
classes); any difference is refused rather than verified.
"""

from __future__ import annotations

import os
import tempfile

import numpy as np
import pinocchio as pin

from pendverify.errors import UrdfShapeError
from pendverify.robot.mjcf_strict import MjcfReading, read_mjcf_strictly
from pendverify.robot.urdfdom import build_from_file, capture_output


def build_mjcf_model(text: str, source: str) -> tuple[pin.Model, MjcfReading, list[str]]:
    """(model, strict reading, Pinocchio's printed lines) of an MJCF document; errors name ``source``."""
    reading = read_mjcf_strictly(text, source)
    model, log = build_from_file(pin.buildModelFromMJCF, text, "model.xml", source, "MJCF")
    _same_as_read(model, reading, source)
    return model, reading, log


def mjcf_visuals(model: pin.Model, text: str) -> pin.GeometryModel:
    """The visual geometry of an MJCF document (read already by ``build_mjcf_model``) for ``model``."""
    with tempfile.TemporaryDirectory(prefix="pendverify-mjcf-") as folder:
        path = os.path.join(folder, "model.xml")
        with open(path, "w", encoding="utf-8") as handle:
            handle.write(text)
        with capture_output((1, 2)):
            return pin.buildGeomFromMJCF(model, path, pin.GeometryType.VISUAL)


def _same_as_read(model: pin.Model, reading: MjcfReading, source: str) -> None:
    built = [model.names[j] for j in range(1, model.njoints)]
    if built != reading.joints:
        raise UrdfShapeError(
            source,
            f"Pinocchio's MJCF reader built the joints {built}, the file declares {reading.joints}; refused",
        )
    for j, name in enumerate(built, start=1):
        v = model.joints[j].idx_v
        pinocchio = (float(model.damping[v]), float(model.armature[v]), float(model.friction[v]))
        if not np.array_equal(pinocchio, reading.dynamics[name]):
            raise UrdfShapeError(
                source,
                f"joint {name!r}: Pinocchio's MJCF reader gives (damping, armature, frictionloss) = "
                f"{pinocchio}, MuJoCo's reading of the file {reading.dynamics[name]}; refused",
            )
