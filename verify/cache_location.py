"""Where pendverify caches: one folder for every cache.

``$PENDVERIFY_CACHE`` names it; else ``$XDG_CACHE_HOME/pendverify``; else
``~/.cache/pendverify`` (``docs/code-cache.md``).  The caches under it: the generated code,
``generated/`` (``pendverify.numerics.codegen.cache``, used only while it is private to its user:
``pendverify.numerics.codegen.folder``), and the Taylor references of ``bench accuracy``,
``reference-<key>.npz`` (``pendverify.numerics.reference``).  The environment is read on every
call, so a process (or a test) that changes it is followed.
"""

from __future__ import annotations

import os
from pathlib import Path

#: the environment variable that names the cache folder
CACHE_VARIABLE = "PENDVERIFY_CACHE"


def cache_root() -> Path:
    """The folder pendverify caches in (module docstring)."""
    named = os.environ.get(CACHE_VARIABLE)
    if named:
        return Path(named)
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "pendverify"
