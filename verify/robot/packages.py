"""ROS packages without ROS: ``$(find PKG)`` and ``package://PKG/...`` resolved to folders.

A *package* is a folder holding a ``package.xml`` whose ``<name>`` names it, as catkin and
ament define it.  ``find_package(name)`` looks for one, in this order (the first found wins):

1. the folders of ``--package-path DIR`` (``package_path`` in the Python API), in the order given;
2. the folders of the ``ROS_PACKAGE_PATH`` environment variable (ROS 1; ``os.pathsep``-separated);

   each of these folders is a package itself or is searched below, as rospack crawls it: at
   most ``MAX_DEPTH`` folders deep and ``MAX_FOLDERS`` folders in all, never below a package,
   skipping hidden folders and those holding a ``CATKIN_IGNORE``, ``COLCON_IGNORE`` or
   ``AMENT_IGNORE`` marker;
3. ``PREFIX/share/PKG`` for each ``PREFIX`` of the ``AMENT_PREFIX_PATH`` environment variable
   (ROS 2: an installed package's share folder carries its name).

A package that is in none of them is one ``UrdfShapeError`` naming it and the folders searched.
A ``package.xml`` that is not XML, or names no package, is not a package (rospack skips it too).

The ``--package-path`` folders are a setting of the calling context (``package_path``, a context
manager over a ``contextvars.ContextVar``): the command line enters it around the whole command,
the Python API's ``pendverify.ros_packages`` around the caller's block, so that every reader of a
description (xacro's ``$(find)``, the visuals' ``package://`` meshes) sees the same folders
without an argument threaded through every function that takes a URDF.  A context variable is
seen by the thread that set it (and by ``contextvars.copy_context`` runs), not by other processes.
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import re
from collections import deque
from collections.abc import Iterable, Iterator
from pathlib import Path
from xml.sax.saxutils import escape

from pendverify.errors import PlaceError, UrdfShapeError
from pendverify.robot.xml_reading import parse_xml

#: the scheme of a ROS resource URI: ``package://PKG/path/in/the/package``
PACKAGE_SCHEME = "package://"
#: folders below a search folder that are looked into (ws/src/group/pkg is 3 deep)
MAX_DEPTH = 6
#: folders looked into below one search folder at most (so that a search of ``/`` ends)
MAX_FOLDERS = 20_000
#: files that stop a crawl into a folder, as catkin, colcon and ament honour them
IGNORE_MARKERS = ("CATKIN_IGNORE", "COLCON_IGNORE", "AMENT_IGNORE")
#: how the option is called, in messages
OPTION = "--package-path DIR (pendverify.ros_packages(DIR) in Python)"

_FOLDERS: contextvars.ContextVar[tuple[Path, ...]] = contextvars.ContextVar("package_path", default=())


@contextlib.contextmanager
def package_path(folders: Iterable[str | os.PathLike] | None) -> Iterator[tuple[Path, ...]]:
    """Search ``folders`` for packages (before the environment's) inside the ``with`` block.

    Each folder must exist; one that does not is a ``PlaceError`` naming it."""
    checked = []
    for folder in folders or ():
        path = Path(folder).expanduser()
        if not path.is_dir():
            raise PlaceError(
                str(folder), "a package folder (--package-path, ros_packages) that is not a folder"
            )
        checked.append(path.resolve())
    token = _FOLDERS.set(tuple(checked))
    try:
        yield tuple(checked)
    finally:
        _FOLDERS.reset(token)


def search_folders() -> list[tuple[Path, str]]:
    """(folder, where it came from) in search order: ``--package-path``, ``ROS_PACKAGE_PATH``,
    ``AMENT_PREFIX_PATH`` (its ``share`` folders)."""
    out = [(path, "--package-path") for path in _FOLDERS.get()]
    out += [(Path(p), "ROS_PACKAGE_PATH") for p in _split(os.environ.get("ROS_PACKAGE_PATH", ""))]
    out += [(Path(p) / "share", "AMENT_PREFIX_PATH") for p in _split(os.environ.get("AMENT_PREFIX_PATH", ""))]
    return out


def find_package(name: str, source: str) -> Path:
    """The folder of package ``name`` (see the module docstring); an error naming it and the folders
    searched, ``source`` being the description that asked for it."""
    for folder, origin in search_folders():
        found = _in_share(folder, name) if origin == "AMENT_PREFIX_PATH" else _crawl(folder, name)
        if found is not None:
            return found
    raise UrdfShapeError(source, not_found(name))


def resolve_uri(uri: str, source: str) -> str:
    """A ``package://PKG/rest`` URI as the absolute path of ``rest`` in package PKG's folder;
    any other string as it is."""
    if not uri.startswith(PACKAGE_SCHEME):
        return uri
    name, _, rest = uri[len(PACKAGE_SCHEME) :].partition("/")
    if not name:
        raise UrdfShapeError(source, f"{uri!r} names no package (package://PKG/path)")
    return str(find_package(name, source) / rest)


#: a ``filename`` attribute holding a ``package://`` URI (a URDF's ``<mesh>``), either quote
_FILENAME_URI = re.compile(r"""(\bfilename\s*=\s*)(["'])(package://[^"'<>]*)\2""")


def resolve_package_uris(text: str, source: str) -> str:
    """``text`` with each ``filename="package://PKG/..."`` attribute made an absolute path (``resolve_uri``).

    What Pinocchio's geometry reader is given: its own ``package_dirs`` search takes a package's
    folder name for its name, where a package is named by its ``package.xml``."""

    def absolute(match: re.Match) -> str:
        path = escape(resolve_uri(match.group(3), source), {'"': "&quot;"})
        return f'{match.group(1)}"{path}"'

    return _FILENAME_URI.sub(absolute, text)


def not_found(name: str) -> str:
    """The sentence for a package that no searched folder holds."""
    searched = search_folders()
    where = (
        "searched " + ", ".join(f"{folder} ({origin})" for folder, origin in searched)
        if searched
        else "no package folders were given and ROS_PACKAGE_PATH and AMENT_PREFIX_PATH are not set"
    )
    return (
        f"ROS package {name!r} not found: {where}; a package is a folder holding a package.xml whose "
        f"<name> is {name}: give the folder that holds it with {OPTION}"
    )


def package_name(folder: Path) -> str | None:
    """The ``<name>`` of the ``package.xml`` in ``folder``, or None (no file, not XML, no name)."""
    manifest = folder / "package.xml"
    if not manifest.is_file():
        return None
    try:
        root = parse_xml(manifest.read_text(encoding="utf-8-sig"), str(manifest))
    except (UrdfShapeError, OSError, UnicodeDecodeError):
        return None
    text = root.findtext("name")
    return text.strip() if text and text.strip() else None


def _split(value: str) -> list[str]:
    return [p for p in value.split(os.pathsep) if p]


def _in_share(share: Path, name: str) -> Path | None:
    candidate = share / name
    return candidate if candidate.is_dir() else None


def _crawl(folder: Path, name: str) -> Path | None:
    """Breadth first below ``folder`` (itself included), bounded as the module docstring says."""
    queue, visited = deque([(folder, 0)]), 0
    while queue:
        here, depth = queue.popleft()
        visited += 1
        if visited > MAX_FOLDERS:
            return None
        found = package_name(here)
        if found is not None:
            if found == name:
                return here
            continue  # never below a package
        if depth >= MAX_DEPTH:
            continue
        try:
            children = sorted(p for p in here.iterdir() if p.is_dir() and not p.name.startswith("."))
        except OSError:
            continue
        queue.extend((c, depth + 1) for c in children if not any((c / m).exists() for m in IGNORE_MARKERS))
    return None
