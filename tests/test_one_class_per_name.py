"""One class per name: no two classes of the installed package share a name.

Two unrelated classes called ``Energies`` (a model's Lagrangian data, and the invariants' view
of a trajectory) make every grep, traceback and ``repr`` ambiguous.  The classes are read from
the source with ``ast`` (nothing is imported): every ``class`` statement of every module of every
package pyproject.toml lists, at module level or nested (a class defined inside a function still
names itself in its ``repr`` and in tracebacks).
"""

from __future__ import annotations

import ast
from collections import defaultdict
from pathlib import Path

from tests.test_import_graph import REPO, installed_modules

#: names two classes may still share (name → how many), each with its reason; empty: none may
ALLOWED: dict[str, int] = {}


def class_homes(modules: dict[str, Path]) -> dict[str, list[str]]:
    """{class name: the modules defining a class of that name, once per ``class`` statement}."""
    homes: dict[str, list[str]] = defaultdict(list)
    for module, path in sorted(modules.items()):
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        for node in ast.walk(tree):
            if isinstance(node, ast.ClassDef):
                homes[node.name].append(module)
    return homes


def shared_names(homes: dict[str, list[str]], allowed: dict[str, int]) -> dict[str, list[str]]:
    """The names defined more often than ``allowed`` lets them be (once, unless listed)."""
    return {name: where for name, where in homes.items() if len(where) > allowed.get(name, 1)}


def test_no_two_classes_share_a_name():
    shared = shared_names(class_homes(installed_modules()), ALLOWED)
    lines = [f"class {name} is defined in {', '.join(where)}" for name, where in shared.items()]
    assert not shared, "\n".join(lines)


def test_every_allowed_name_is_still_shared():
    """An allow-list entry whose second class is gone is stale: it would hide a new clash."""
    homes = class_homes(installed_modules())
    stale = {name: homes.get(name) for name, count in ALLOWED.items() if len(homes.get(name, [])) != count}
    assert not stale, f"stale ALLOWED entries (drop them): {stale}"


def test_a_planted_second_class_is_found(tmp_path):
    first, second = tmp_path / "first.py", tmp_path / "second.py"
    first.write_text("class Energies:\n    pass\n")
    second.write_text("def make():\n    class Energies:\n        pass\n    return Energies\n")
    homes = class_homes({"pkg.first": first, "pkg.second": second})
    assert shared_names(homes, {}) == {"Energies": ["pkg.first", "pkg.second"]}
    assert shared_names(homes, {"Energies": 2}) == {}


def test_the_walk_covers_every_folder_of_the_package():
    folders = {path.parent.relative_to(REPO).parts[0] for path in installed_modules().values()}
    assert {"verify", "analytic", "viz", "urdf", "examples"} <= folders, folders
