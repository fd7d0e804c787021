"""Load a URDF into Pinocchio: read strictly first, then anchor the fixed base at the origin."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pinocchio as pin

from pendverify.errors import UrdfShapeError
from pendverify.robot.strict import UrdfFacts
from pendverify.robot.urdfdom import build_pinocchio_model


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


#: ``source`` of a URDF given as XML text rather than a file.
URDF_TEXT_SOURCE = "<urdf text>"


def is_urdf_text(urdf: str | Path) -> bool:
    """Whether ``urdf`` is the XML itself (a string starting with "<") rather than a file path."""
    return isinstance(urdf, str) and urdf.lstrip().startswith("<")


def load_urdf(urdf: str | Path, source: str | None = None) -> LoadedUrdf:
    """Read a URDF file (or XML text) strictly, parse it with Pinocchio and anchor its base at the origin."""
    if not is_urdf_text(urdf):
        path = Path(urdf)
        source = source or str(path)
        if not path.is_file():
            raise UrdfShapeError(source, "is a directory, not a file" if path.is_dir() else "file not found")
        text = read_text_file(path, source)
    else:
        text, source = urdf, source or URDF_TEXT_SOURCE
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
