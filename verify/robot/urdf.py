"""Load a URDF into Pinocchio: the names the rest of pendverify has always used.

A description in any accepted format (URDF, xacro, MJCF; SDFormat where Pinocchio has it)
is loaded by ``pendverify.robot.description.load_description``: read strictly first, then
by Pinocchio, then its fixed base anchored at the origin.  ``load_urdf`` is that function;
``LoadedUrdf`` the ``LoadedDescription`` it returns.
"""

from __future__ import annotations

from pathlib import Path

import pinocchio as pin

from pendverify.robot.description import (
    TEXT_SOURCE,
    LoadedDescription,
    is_description_text,
    load_description,
    read_text_file,
)

__all__ = [
    "URDF_TEXT_SOURCE",
    "LoadedUrdf",
    "is_urdf_text",
    "load_model",
    "load_urdf",
    "read_text_file",
]

LoadedUrdf = LoadedDescription
load_urdf = load_description
is_urdf_text = is_description_text
URDF_TEXT_SOURCE = TEXT_SOURCE


def load_model(urdf: str | Path, source: str | None = None) -> tuple[pin.Model, str]:
    """A description in Pinocchio (see ``load_description``); errors name the source."""
    loaded = load_urdf(urdf, source)
    return loaded.model, loaded.source
