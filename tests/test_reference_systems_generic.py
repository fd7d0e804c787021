"""No module of ``pendverify`` outside ``analytic/`` names a reference system: they run through the
generic paths, as any model does.

The two reference systems (the fixed-base and the cart double pendulum) are defined in
``analytic/``, with their URDF readers and writers; they enter the rest of the package as data
(their parameter files, the shipped scenes, sweeps and URDFs, ``analytic.MODELS``).  This test
reads the syntax tree of every module of ``verify/`` and ``viz/`` and lists:

* a module whose file is named after a reference system;
* an import of a reference system's module (``pendverify.analytic.double_pendulum``) or class;
* an identifier (a name, attribute, function, class, argument or alias) that spells a reference
  system's name (``double_pendulum``, ``DoublePendulum`` in any case, with or without ``_``);
* a string literal that is a reference system's name or module (``"cart_double_pendulum"``).

Docstrings, comments and longer strings (help text citing ``examples/double_pendulum.urdf`` or
``pendverify check --model double_pendulum``) are prose for users, not code paths, and are
not scanned.  ``ALLOWED`` holds one file, the stress catalogue: a table of the reference systems'
hard cases, data written as Python (the reason is next to it).
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

from tests.source_scan import docstring_ids

REPO = Path(__file__).resolve().parents[1]
SCANNED = ("verify", "viz")
#: the reference systems' model names, which are also their modules' names in ``analytic/``
NAMES = ("double_pendulum", "cart_double_pendulum")
MODULES = {f"pendverify.analytic.{name}" for name in NAMES}
CLASSES = {"DoublePendulum", "CartDoublePendulum", "DoublePendulumParams", "CartDoublePendulumParams"}
#: an identifier spelling a reference system's name: double_pendulum, DoublePendulum, DOUBLEPENDULUM
SPELLED = re.compile(r"double_?pendulum", re.IGNORECASE)
#: files that may still name a reference system, each with the reason
ALLOWED = {
    # the stress catalogue: the reference systems' hard cases as a data table (which model, which
    # sets, which hard states), keyed by the models' names; every case takes its model and set from it
    "verify/stress/catalogue.py",
}


def _identifiers(node: ast.AST) -> list[str]:
    if isinstance(node, ast.Name):
        return [node.id]
    if isinstance(node, ast.Attribute):
        return [node.attr]
    if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
        return [node.name]
    if isinstance(node, ast.arg):
        return [node.arg]
    if isinstance(node, ast.keyword) and node.arg:
        return [node.arg]
    if isinstance(node, ast.alias):
        return [node.name.rpartition(".")[2], node.asname or ""]
    return []


def references(source: str) -> list[tuple[int, str]]:
    """(line, what) for each place ``source`` names a reference system in code (see the module
    docstring); docstrings and prose strings aside."""
    tree = ast.parse(source)
    skip = docstring_ids(tree)
    found = []
    for node in ast.walk(tree):
        line = getattr(node, "lineno", 0)
        if isinstance(node, ast.ImportFrom) and node.module:
            modules = {node.module, *(f"{node.module}.{a.name}" for a in node.names)}
            found += [(line, f"import of {m}") for m in sorted(modules & MODULES)]
            found += [(line, f"import of {a.name}") for a in node.names if a.name in CLASSES]
        elif isinstance(node, ast.Import):
            found += [(line, f"import of {a.name}") for a in node.names if a.name in MODULES]
        elif isinstance(node, ast.Constant) and id(node) not in skip and isinstance(node.value, str):
            if node.value in NAMES or node.value in MODULES:
                found.append((line, f"string {node.value!r}"))
        found += [(line, f"identifier {name}") for name in _identifiers(node) if SPELLED.search(name)]
    return sorted(set(found))


def offences(root: Path = REPO) -> list[str]:
    found = []
    for folder in SCANNED:
        for path in sorted((root / folder).rglob("*.py")):
            rel = path.relative_to(root).as_posix()
            if rel in ALLOWED:
                continue
            if SPELLED.search(path.stem):
                found.append(f"{rel}: a module named after a reference system")
            found += [f"{rel}:{line}: {what}" for line, what in references(path.read_text(encoding="utf-8"))]
    return found


def test_no_module_outside_analytic_names_a_reference_system():
    found = offences()
    assert not found, "a reference system named outside analytic/:\n" + "\n".join(found)


def test_every_allowed_file_exists():
    """An allow-list entry for a file that is gone would hide a new file of that name."""
    assert all((REPO / rel).is_file() for rel in ALLOWED), [r for r in ALLOWED if not (REPO / r).is_file()]


@pytest.mark.parametrize(
    "code",
    [
        'if model.name == "cart_double_pendulum":\n    pass\n',
        'x = {"double_pendulum": 1}\n',
        "from pendverify.analytic import DoublePendulum\n",
        "from pendverify.analytic import double_pendulum\n",
        "import pendverify.analytic.cart_double_pendulum\n",
        "from pendverify.analytic.double_pendulum import alpha\n",
        "ok = isinstance(p, analytic.CartDoublePendulumParams)\n",
        "def double_pendulum_geometry(model):\n    pass\n",
        "urdfs = erd.double_pendulum_urdfs()\n",
        "DOUBLE_PENDULUM_DIR = 'x'\n",
        "def f(doublependulum):\n    pass\n",
    ],
)
def test_the_scan_finds_a_planted_reference(code):
    assert references(code)


@pytest.mark.parametrize(
    "code",
    [
        '"""Run ``check("double_pendulum")``."""\n',
        'EXAMPLES = ["pendverify check --model double_pendulum --samples 200"]\n',
        'SKIPPED = "its double-pendulum URDFs are skipped"\n',
        "pendulum = triple_pendulum = 1\n",
    ],
)
def test_prose_and_other_models_are_not_references(code):
    assert not references(code)


def test_the_scan_finds_a_module_named_after_a_reference_system(tmp_path):
    (tmp_path / "verify").mkdir()
    (tmp_path / "verify" / "cart_double_pendulum_cases.py").write_text("x = 1\n")
    (tmp_path / "verify" / "generic.py").write_text("y = 2\n")
    assert offences(tmp_path) == [
        "verify/cart_double_pendulum_cases.py: a module named after a reference system"
    ]
