"""The file that defines a model or parameter class: its Python source, or a text model's file.

``where(cls)`` names it in error messages (the module's name when there is no file).

A text model's classes live in a stand-in module (``pendverify.analytic.text_model``)
that names its text file in ``TEXT_FILE`` and has no ``__file__``: tools that take a
module's ``__file__`` for Python source (``inspect.getsource``, Hypothesis's search
for constants in local modules) would otherwise parse the TOML, LaTeX and all, as
Python.
"""

from __future__ import annotations

import inspect
import sys

#: the attribute of a text model's stand-in module that holds the text file's path
TEXT_FILE = "text_model_file"
#: the attribute that holds the paths of the other files the text model reads (its ``.m`` files)
COMPANION_FILES = "text_model_companions"


def defining_file(cls: type) -> str:
    """The path of the file that defines ``cls``; TypeError or OSError as ``inspect.getfile``."""
    text_file = getattr(sys.modules.get(cls.__module__), TEXT_FILE, None)
    if text_file is not None:
        return text_file
    return inspect.getfile(cls)


def where(cls: type) -> str:
    """The file that defines a class (for error messages), or its module's name."""
    try:
        return defining_file(cls)
    except (TypeError, OSError):  # pragma: no cover - classes built at run time
        return cls.__module__
