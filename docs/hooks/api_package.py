"""MkDocs hook: lay out the import package ``pendverify`` for the API reference.

The package's folders sit side by side in the checkout (``verify/`` is ``pendverify``,
``analytic/`` is ``pendverify.analytic``, ... as ``pyproject.toml``'s ``package-dir``
maps them), so griffe, which reads the source without importing it, cannot find the
sub-packages under ``verify/``.  This hook builds ``build/api-package/pendverify``: a
folder of symbolic links, one per entry of ``verify/`` plus one per mapped sub-package,
which ``mkdocs.yml`` gives mkdocstrings as its search path.  It works the same with an
editable install, a regular install or none.
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[2]
TREE = ROOT / "build" / "api-package"


def package_dirs() -> dict[str, Path]:
    """The ``package-dir`` mapping of ``pyproject.toml``: import name → folder."""
    with open(ROOT / "pyproject.toml", "rb") as handle:
        mapping = tomllib.load(handle)["tool"]["setuptools"]["package-dir"]
    return {name: ROOT / folder for name, folder in mapping.items()}


def build_tree() -> Path:
    if TREE.exists():
        shutil.rmtree(TREE)
    dirs = package_dirs()
    top = TREE / "pendverify"
    top.mkdir(parents=True)
    for entry in dirs["pendverify"].iterdir():
        if entry.name != "__pycache__":
            (top / entry.name).symlink_to(entry)
    for name, folder in dirs.items():
        parts = name.split(".")
        if len(parts) == 2:
            link = top / parts[1]
            if link.exists() or link.is_symlink():
                link.unlink()
            link.symlink_to(folder, target_is_directory=True)
    return TREE


# Built on import: MkDocs imports its hooks while it reads mkdocs.yml, before mkdocstrings
# decides which of its search paths exist.
build_tree()
