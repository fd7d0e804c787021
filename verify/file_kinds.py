"""What kind of file a user gave, and how to give a file of that kind.

A file's kind is told from its name's suffix and, for TOML, from the top-level keys that only
that kind of document holds:

============  =====================================================  ===========================
kind          told by                                                given as
============  =====================================================  ===========================
model         ``.py``; TOML with ``coordinates``, ``notation`` or    ``--analytic FILE``
              an equation (``M``, ``f``, ``qddot``, ``equations``)
description   ``.urdf``, ``.xacro``, ``.sdf``, ``.mjcf``, ``.xml``   ``--urdf FILE``
params        TOML of ``model``, ``parameters`` (and ``name``) only  ``--params FILE``
scene         TOML with ``initial``, ``time``, ``integrator``,       ``pendverify simulate FILE``
              ``effects`` or ``engine``
sweep         TOML with ``ranges``, ``base``, ``mode`` or ``count``  ``certify --sweep FILE``
trajectory    ``.npz``                                               ``render --trajectory FILE``
certificate   ``.cert.json``                                         ``pendverify recheck FILE``
============  =====================================================  ===========================

The readers of each kind call ``expect_kind`` on the document they parsed, so a parameter file
given as a scene (or a text model given as ``--params``) is told what it is and where it goes,
not which of its keys the other reader does not know.  ``pendverify.documents.file_kind`` tells
the kind of a file on disk.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from pendverify.errors import wrong_kind


@dataclass(frozen=True)
class Kind:
    """One kind of file: what it is called in messages, and how it is given."""

    noun: str
    #: the command-line flag that takes it ("" when a command takes it as its argument)
    flag: str
    #: how to give it, as a clause of a message
    given_as: str


KINDS = {
    "model": Kind("model file", "--analytic", "give it as --analytic FILE (model= in the Python API)"),
    "description": Kind("robot description", "--urdf", "give it as --urdf FILE (urdf= in the Python API)"),
    "params": Kind("parameter file", "--params", "give it as --params FILE (params= in the Python API)"),
    "scene": Kind("scene file", "", "run it with `pendverify simulate FILE` (pendverify.simulate(FILE))"),
    "sweep": Kind("sweep file", "--sweep", "certify it with `pendverify certify --sweep FILE -o DIR`"),
    "trajectory": Kind("saved run", "--trajectory", "draw it with `pendverify render --trajectory FILE`"),
    "certificate": Kind("certificate", "", "recheck it with `pendverify recheck FILE`"),
}

#: top-level TOML keys that only one kind of document holds
TOML_MARKERS = {
    "model": frozenset({"coordinates", "notation", "M", "f", "qddot", "equations", "matlab"}),
    "scene": frozenset({"initial", "time", "integrator", "effects", "engine"}),
    "sweep": frozenset({"ranges", "base", "mode", "count"}),
}
#: a parameter file's keys: all of its top level
PARAMETER_KEYS = frozenset({"model", "name", "parameters"})


def toml_kind(data: dict) -> str | None:
    """The kind of a parsed TOML document (a key of ``KINDS``), or None when its keys tell none."""
    keys = set(data)
    for kind, markers in TOML_MARKERS.items():
        if keys & markers:
            return kind
    if {"model", "parameters"} <= keys <= PARAMETER_KEYS:
        return "params"
    return None


def suffix_kind(path: str | Path) -> str | None:
    """The kind a file's name tells (None for TOML, whose kind its keys tell, and unknown suffixes)."""
    from pendverify.robot.description import SUFFIXES

    name = Path(path).name.lower()
    if name.endswith(".cert.json"):
        return "certificate"
    if name.endswith(".py"):
        return "model"
    if name.endswith(".npz"):
        return "trajectory"
    if name.endswith(SUFFIXES):
        return "description"
    return None


def expect_kind(data: dict, path: str | Path, kind: str) -> None:
    """Refuse a TOML document that is plainly another kind of file than ``kind`` (one sentence:
    what it is and how to give it); a document whose keys tell no kind is left to its reader."""
    found = toml_kind(data)
    if found is not None and found != kind:
        raise wrong_kind(path, KINDS[kind].noun, KINDS[found].noun, KINDS[found].given_as)
