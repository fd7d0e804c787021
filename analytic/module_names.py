"""The module names a user's model files are imported under: ``pendverify.plugins.<stem>``.

A Python model file (``pendverify.analytic.plugin``) and a text or LaTeX model file
(``pendverify.analytic.text_model``, whose classes live in a stand-in module) are both
named here, so that a class's ``__module__`` says which file it came from.
"""

from __future__ import annotations

import keyword
import re
import sys
from pathlib import Path

#: the package name model files are imported under (not a package on disk: the modules are made here)
NAMESPACE = "pendverify.plugins"
#: resolved path of each model file imported so far → its module name
_MODULE_NAMES: dict[str, str] = {}


def module_name(path: str | Path) -> str:
    """The module name of model file ``path``: ``pendverify.plugins.<stem>``.

    The stem is made a valid identifier (other characters become ``_``; a leading digit or a
    keyword gets an ``_``); a file at another resolved path with the same stem gets ``<stem>_2``,
    ``<stem>_3``, ...; the same resolved path always gets the same name.
    """
    resolved = str(Path(path).resolve())
    if resolved in _MODULE_NAMES:
        return _MODULE_NAMES[resolved]
    stem = re.sub(r"[^0-9A-Za-z_]", "_", Path(path).stem) or "model"
    if stem[0].isdigit() or keyword.iskeyword(stem):
        stem = f"_{stem}"
    taken = {*_MODULE_NAMES.values(), *sys.modules}
    name, n = f"{NAMESPACE}.{stem}", 2
    while name in taken:
        name, n = f"{NAMESPACE}.{stem}_{n}", n + 1
    _MODULE_NAMES[resolved] = name
    return name
