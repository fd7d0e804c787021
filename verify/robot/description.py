"""Robot descriptions in Pinocchio, whatever their format: one entry point, ``load_description``.

A description is a file path or the XML text itself (a string starting with "<").  Its
format (``FORMATS``) is decided before anything is read into Pinocchio:

* **xacro** — a file named ``*.xacro`` (``*.urdf.xacro`` too), or XML with an element or
  attribute in xacro's namespace: expanded by the ``xacro`` package with its ``xacro:arg``
  defaults (``pendverify.robot.xacro_expand``), then read as URDF; errors name the xacro file.
* **URDF** — root ``<robot>``: read strictly (``pendverify.robot.strict``), then by Pinocchio's
  URDF reader (``pendverify.robot.urdfdom``).
* **MJCF** — root ``<mujoco>``: its numbers read strictly, compiled by MuJoCo, copied into
  Pinocchio and cross-checked against MuJoCo (``pendverify.robot.mjcf``); its text is the file's
  with includes in place.
* **SDFormat** — root ``<sdf>``: its numbers read strictly, parsed by Drake (the optional extra
  ``pendverify[sdf]``; without it, refused naming the extra), copied into Pinocchio and
  cross-checked against Drake (``pendverify.robot.sdf``).

MuJoCo and Drake are imported only when a file of theirs is read.  (A ``pinocchio.Model`` given
to the Python API becomes a ``LoadedDescription`` in ``pendverify.robot.pinocchio_model``.)

Whatever the format, the model's fixed base is then moved to the origin (``anchor_base``)
and the result is one ``LoadedDescription``: the model, the facts Pinocchio does not keep
(joint damping and friction as written, an MJCF's gravity), the text that was read (for
xacro: the URDF it expanded to), notes, and for an MJCF where each number came from
(``origins``).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pinocchio as pin

from pendverify.display import shortened
from pendverify.errors import UrdfShapeError, folder_given, missing_file, unreadable_file
from pendverify.robot.strict import DescriptionFacts
from pendverify.robot.urdfdom import build_pinocchio_model
from pendverify.robot.xacro_expand import XACRO_SUFFIXES, expand_xacro, uses_xacro
from pendverify.robot.xml_reading import MAX_XML_CHARACTERS, XmlDocument, ignored_extensions, read_xml

#: format → the root element it has (xacro: the URDF's, after expansion)
FORMATS = {"urdf": "robot", "xacro": "robot", "mjcf": "mujoco", "sdf": "sdf"}
#: name suffixes a description file's stem leaves out (longest first)
SUFFIXES = (".urdf.xacro", ".mjcf.xml", ".xacro", ".urdf", ".mjcf", ".sdf", ".xml")
#: ``source`` of a description given as XML text rather than a file
TEXT_SOURCE = "<urdf text>"
#: format → what its reader is called in messages ("pinocchio": a model given as an object,
#: ``pendverify.robot.pinocchio_model``)
READERS = {"urdf": "URDF", "xacro": "URDF", "mjcf": "MJCF", "sdf": "SDFormat", "pinocchio": "Pinocchio"}
#: format → the suffix of a file that holds its verified text (xacro: the URDF it expanded to)
FILE_SUFFIXES = {"urdf": ".urdf", "xacro": ".urdf", "mjcf": ".mjcf.xml", "sdf": ".sdf"}


@dataclass
class LoadedDescription:
    """A robot description in Pinocchio, read strictly first, its base at the origin."""

    model: pin.Model
    source: str
    #: the text Pinocchio read: the file's, or for xacro the URDF it expanded to
    text: str
    facts: DescriptionFacts
    #: distance of the fixed base from the world origin in the file [m]
    base_offset: float = 0.0
    #: what the readers (urdfdom, Pinocchio's MJCF reader, xacro) logged
    log: list[str] = field(default_factory=list)
    #: "urdf", "xacro", "mjcf", "sdf" or "pinocchio"
    format: str = "urdf"
    #: what reading the file noticed (defaults applied, armature, ...)
    reading_notes: list[str] = field(default_factory=list)
    #: "<body or joint name>.<quantity>" (and "gravity") → where the number came from
    #: (``pendverify.robot.mjcf_origins``); filled for MJCF only, empty for other formats
    origins: dict[str, str] = field(default_factory=dict)
    #: the visual geometry given with a Pinocchio model (None: built from ``text`` when drawn)
    visual_model: pin.GeometryModel | None = None
    #: the file's XML from its one parse (``xml_reading.read_xml``; None for a Pinocchio model)
    xml: XmlDocument | None = None

    def notes(self) -> list[str]:
        out = [f"Pinocchio's {READERS[self.format]} parser logged: {line}" for line in self.log]
        out += self.reading_notes
        if self.base_offset > 0:
            out.append(
                f"the fixed base stands {self.base_offset:.6g} m from the world origin; it is evaluated "
                "at the origin (a fixed base's dynamics do not depend on where it stands)"
            )
        return out


def is_description_text(description: str | Path) -> bool:
    """Whether ``description`` is the XML itself (a string starting with "<") rather than a file path."""
    return isinstance(description, str) and description.lstrip().startswith("<")


def description_stem(path: str | Path) -> str:
    """A description file's name without its format's suffix: ``arm.urdf.xacro`` → ``arm``."""
    name = Path(path).name
    for suffix in SUFFIXES:
        if name.lower().endswith(suffix) and len(name) > len(suffix):
            return name[: -len(suffix)]
    return Path(path).stem


def description_format(text: str, path: Path | None, source: str) -> str:
    """The format of a description (see the module docstring); anything else is refused."""
    return format_of(read_xml(text, source).root, path, source)


def format_of(root: ET.Element, path: Path | None, source: str) -> str:
    """The format of a description whose XML is ``root`` (see ``description_format``)."""
    if (path is not None and path.name.lower().endswith(XACRO_SUFFIXES)) or uses_xacro(root):
        return "xacro"
    local = root.tag.rsplit("}", 1)[-1]  # a default namespace (Drake's URDFs) names no format
    for fmt, tag in FORMATS.items():
        if local == tag:
            return fmt
    raise UrdfShapeError(
        source,
        f"the root element is <{shortened(root.tag, 60)}>: pendverify reads URDF (<robot>), xacro (*.xacro), "
        "MJCF (<mujoco>) and SDFormat (<sdf>)",
    )


def load_description(description: str | Path, source: str | None = None) -> LoadedDescription:
    """Read a description file (or XML text) strictly, build its Pinocchio model, anchor its base."""
    path = None
    if not is_description_text(description):
        path = Path(description)
        source = source or str(path)
        if path.is_dir():
            raise folder_given(source, "robot description")
        if not path.is_file():
            raise missing_file(source, "robot description")
        text = read_text_file(path, source)
    else:
        text, source = str(description), source or TEXT_SOURCE
    document = read_xml(text, source)
    fmt = format_of(document.root, path, source)
    notes: list[str] = []
    origins: dict[str, str] = {}
    if fmt == "xacro":
        text, log = expand_xacro(text, path, source, document)
        try:
            model, facts, urdf_log = build_pinocchio_model(text, source)
        except UrdfShapeError as exc:
            raise UrdfShapeError(exc.source, f"{exc.problem} (in the URDF xacro expanded it to)") from None
        notes.append("expanded by xacro, with the defaults of its xacro:arg arguments")
        notes += [f"xacro printed: {line}" for line in log]
        log = urdf_log
    elif fmt == "urdf":
        model, facts, log = build_pinocchio_model(text, source, document)
        ignored = ignored_extensions(document)
        if ignored:
            listed = ", ".join(f"<{name}>" + (f" ×{n}" if n > 1 else "") for name, n in ignored.items())
            notes.append(
                f"extension elements urdfdom ignores, so the model leaves them out: {shortened(listed, 300)}"
            )
    elif fmt == "mjcf":
        from pendverify.robot.mjcf import build_mjcf_model  # imports MuJoCo: only for an MJCF

        model, reading, log = build_mjcf_model(text, source, path)
        facts, notes, origins, text = reading.facts, reading.notes, reading.origins, reading.text
    else:
        from pendverify.robot.sdf import build_sdf_model  # Drake's reader: only for an SDF

        model, facts, log = build_sdf_model(text, source)
    offset = anchor_base(model)
    return LoadedDescription(model, source, text, facts, offset, log, fmt, notes, origins, xml=document)


def urdf_text(description: str | Path, purpose: str, source: str | None = None) -> str:
    """The URDF text of a description (a xacro file expanded); other formats refused naming ``purpose``."""
    loaded = load_description(description, source)
    if loaded.format not in ("urdf", "xacro"):
        raise UrdfShapeError(
            loaded.source,
            f"an {READERS[loaded.format]} description, but {purpose} rewrites a URDF's numbers: "
            "give a URDF or xacro file",
        )
    return loaded.text


def text_suffix(text: str) -> str:
    """The file suffix for a description's verified text (``.urdf``, ``.mjcf.xml``, ``.sdf``)."""
    return FILE_SUFFIXES[description_format(text, None, TEXT_SOURCE)]


def anchor_base(model: pin.Model) -> float:
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


def read_text_file(path: Path, source: str) -> str:
    """A user's text file as UTF-8 (a byte-order mark allowed), at most ``MAX_XML_CHARACTERS`` bytes
    read (so at most that many characters); anything else is one clear error."""
    try:
        with path.open("rb") as handle:
            data = handle.read(MAX_XML_CHARACTERS + 1)
        if len(data) > MAX_XML_CHARACTERS:
            limit = MAX_XML_CHARACTERS
            raise UrdfShapeError(source, f"larger than the limit of {limit} bytes for a description")
        return data.decode("utf-8-sig")
    except IsADirectoryError:
        raise folder_given(source, "robot description") from None
    except UnicodeDecodeError as exc:
        raise UrdfShapeError(source, f"not UTF-8 text (byte {exc.start}: {exc.reason})") from None
    except FileNotFoundError:
        raise missing_file(source, "robot description") from None
    except OSError as exc:
        raise unreadable_file(source, "robot description", exc.strerror or str(exc)) from None
