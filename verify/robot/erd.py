"""Locate example-robot-data's double-pendulum URDFs through the installed distribution.

No machine path is written down: the files are found in the distribution's own
record of installed files (``importlib.metadata``), which works for the cmeel
wheels (data under ``cmeel.prefix/share``) and for older layouts alike.
"""

from __future__ import annotations

import importlib.metadata
from pathlib import Path

from pendverify.errors import PendverifyError, UrdfShapeError
from pendverify.robot.description import description_stem

DISTRIBUTION = "example-robot-data"
#: the built-in model whose family example-robot-data's double-pendulum URDFs belong to
MODEL = "double_pendulum"
DOUBLE_PENDULUM_DIR = "double_pendulum_description/urdf"


def double_pendulum_urdfs() -> dict[str, Path]:
    """{stem: path} of every double-pendulum URDF example-robot-data ships."""
    try:
        dist = importlib.metadata.distribution(DISTRIBUTION)
    except importlib.metadata.PackageNotFoundError:
        raise PendverifyError(f"{DISTRIBUTION} is not installed (pip install {DISTRIBUTION})") from None
    found = {}
    for record in dist.files or ():
        text = str(record).replace("\\", "/")
        if DOUBLE_PENDULUM_DIR in text and text.endswith(".urdf"):
            found[Path(text).stem] = Path(str(dist.locate_file(record))).resolve()
    if not found:
        raise PendverifyError(f"{DISTRIBUTION} {dist.version} ships no {DOUBLE_PENDULUM_DIR}/*.urdf")
    return dict(sorted(found.items()))


def resolve_urdf(spec: str) -> tuple[Path, str]:
    """(path, bundle name) of ``erd:NAME`` (example-robot-data's URDF NAME) or of a description's path
    (its stem without the format's suffixes: ``arm.urdf.xacro`` → ``arm``)."""
    if spec.startswith("erd:"):
        found = double_pendulum_urdfs()
        stem = spec[4:]
        if stem not in found:
            raise UrdfShapeError(spec, f"example-robot-data has no {stem!r}; it has {', '.join(found)}")
        return found[stem], f"erd_{stem}"
    path = Path(spec)
    if not path.is_file():
        raise UrdfShapeError(spec, "file not found")
    return path, description_stem(path)
