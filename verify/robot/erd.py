"""Locate example-robot-data's URDFs of a built-in model's family through the installed distribution.

The model is the one whose class names example-robot-data's folder (``erd_urdf_folder``: the
double pendulum's ``double_pendulum_description/urdf``); nothing here names it.

No machine path is written down: the files are found in the distribution's own
record of installed files (``importlib.metadata``), which works for the cmeel
wheels (data under ``cmeel.prefix/share``) and for older layouts alike.

example-robot-data is an optional dependency (the ``erd`` extra).  ``installed``
says whether it is there; a check that would include its URDFs by default skips
them with ``SKIPPED`` when it is not, and naming one (``erd:NAME``) is an error then.
"""

from __future__ import annotations

import importlib.metadata
from pathlib import Path

from pendverify.analytic import MODELS
from pendverify.errors import PendverifyError, PlaceError, UrdfShapeError, folder_given, missing_file
from pendverify.robot.description import description_stem

DISTRIBUTION = "example-robot-data"
#: how to install it along with pendverify
INSTALL_HINT = "pip install 'pendverify[erd]'"
#: the built-in model whose family example-robot-data's URDFs in ``URDF_FOLDER`` belong to
MODEL = next(name for name, cls in MODELS.items() if cls.erd_urdf_folder)
URDF_FOLDER = MODELS[MODEL].erd_urdf_folder
#: a URDF argument ``erd:NAME`` names example-robot-data's URDF NAME
PREFIX = "erd:"
#: the sentence a default check reports when example-robot-data is not installed
SKIPPED = f"{DISTRIBUTION} is not installed: its double-pendulum URDFs are skipped ({INSTALL_HINT})"


def installed() -> importlib.metadata.Distribution | None:
    """example-robot-data's installed distribution, or None when it is not installed."""
    try:
        return importlib.metadata.distribution(DISTRIBUTION)
    except importlib.metadata.PackageNotFoundError:
        return None


def family_urdfs() -> dict[str, Path]:
    """{stem: path} of every URDF example-robot-data ships in ``URDF_FOLDER`` (``MODEL``'s family)."""
    dist = installed()
    if dist is None:
        raise PendverifyError(f"{DISTRIBUTION} is not installed ({INSTALL_HINT})")
    found = {}
    for record in dist.files or ():
        text = str(record).replace("\\", "/")
        if URDF_FOLDER in text and text.endswith(".urdf"):
            found[Path(text).stem] = Path(str(dist.locate_file(record))).resolve()
    if not found:
        raise PendverifyError(f"{DISTRIBUTION} {dist.version} ships no {URDF_FOLDER}/*.urdf")
    return dict(sorted(found.items()))


def is_erd_spec(spec: object) -> bool:
    """Whether a URDF argument names one of example-robot-data's URDFs (``erd:NAME``)."""
    return isinstance(spec, str) and spec.startswith(PREFIX)


def erd_urdf(spec: str) -> tuple[str, Path]:
    """(NAME, path) of ``erd:NAME``; an error naming ``spec`` when example-robot-data is not
    installed or has no URDF of that name (the message lists the ones it has)."""
    if installed() is None:
        raise PlaceError(spec, f"{DISTRIBUTION} is not installed ({INSTALL_HINT})")
    found = family_urdfs()
    stem = spec[len(PREFIX) :]
    if stem not in found:
        raise UrdfShapeError(spec, f"example-robot-data has no {stem!r}; it has {', '.join(found)}")
    return stem, found[stem]


def resolve_urdf(spec: str) -> tuple[Path, str]:
    """(path, bundle name) of ``erd:NAME`` (example-robot-data's URDF NAME: ``erd_NAME``) or of a
    description's path (its stem without the format's suffixes: ``arm.urdf.xacro`` → ``arm``)."""
    if is_erd_spec(spec):
        stem, path = erd_urdf(spec)
        return path, f"erd_{stem}"
    path = Path(spec)
    if path.is_dir():
        raise folder_given(spec, "robot description")
    if not path.is_file():
        raise missing_file(spec, "robot description")
    return path, description_stem(path)
