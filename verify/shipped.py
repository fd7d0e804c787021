"""Where the data installed with pendverify lives: examples, scenes, sweeps, URDFs, parameters, models.

Each kind of shipped data is a folder inside the installed package, found through
``importlib.resources`` (so wherever pendverify is installed, and never in a checkout
unless that is what is installed).  In the installed layout the folders are siblings,
``pendverify/examples``, ``pendverify/scenes``, ..., which is what the scenes' relative
paths (``../examples/cart_pole.py``) rely on.  It is the repository's layout too (``urdf/``,
``examples/``, ``analytic/params/`` at the clone's root), so a shipped file's ``shipped_path``
is the path the manual names it by, and the path ``pendverify example`` copies it to.
"""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path, PurePosixPath

#: kind of shipped data -> (the package that holds it, the folder inside that package)
FOLDERS = {
    "examples": ("pendverify.examples", ""),
    "scenes": ("pendverify.scenes", ""),
    # the default problems of ``pendverify bench accuracy`` (``pendverify.bench.problems``)
    "bench": ("pendverify.scenes", "bench"),
    "sweeps": ("pendverify.sweeps", ""),
    "urdf": ("pendverify.urdf", ""),
    "params": ("pendverify.analytic", "params"),
    # the reference systems' closed forms, as Python model files
    "models": ("pendverify.analytic", ""),
}


def shipped_folder(kind: str) -> Path:
    """The installed folder of one kind of shipped data (a key of ``FOLDERS``)."""
    package, folder = FOLDERS[kind]
    root = files(package)
    return Path(str(root / folder if folder else root))


def shipped_file(kind: str, name: str) -> Path:
    """The installed file ``name`` of one kind of shipped data, e.g. ``shipped_file("scenes", "x.toml")``."""
    return shipped_folder(kind) / name


def shipped_path(kind: str, name: str) -> PurePosixPath:
    """The file's path inside the package's root folder, e.g. ``analytic/params/double_pendulum.toml``.

    That is its path in a clone and in the manual's commands (``--urdf urdf/double_pendulum.urdf``).
    """
    package, folder = FOLDERS[kind]
    return PurePosixPath(*package.split(".")[1:], *([folder] if folder else []), name)
