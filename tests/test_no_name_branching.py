"""Outside the seed-specific code, nothing branches on a model's name or on a seed's class.

Every command takes any model (issue 12): the seeds' names and classes may appear only
in ``analytic/`` (where the seeds are defined), in the seed-specific URDF readers and
writers, in example-robot-data's table (its URDFs are double pendulums) and in the
seed-specific stress cases.  The test reads every module's syntax tree and lists each
string literal equal to a seed's name and each use of a seed's class elsewhere;
docstrings (examples of usage) are not code and are skipped.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
SEED_NAMES = {"double_pendulum", "cart_double_pendulum"}
SEED_CLASSES = {"DoublePendulum", "CartDoublePendulum", "DoublePendulumParams", "CartDoublePendulumParams"}
#: where the seeds may be named: their definitions and the code that exists only for them
ALLOWED = {
    "verify/robot/erd.py",  # example-robot-data's double pendulums are the double_pendulum seed
    # the seed-specific stress cases (``pendverify stress`` without --analytic) and their sets;
    # any model's hard cases are ``stress/generic.py`` and ``stress/singular.py``
    "verify/stress/catalogue.py",
    "verify/stress/cases.py",
    "verify/stress/sim_cases.py",
    "verify/stress/seed_params.py",
    "verify/stress/trust_study.py",  # the cart's m1 → 0 study that measured the trust rule
}
SCANNED = ("verify", "viz")


def _docstrings(tree: ast.AST) -> set[int]:
    ids = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
                ids.add(id(body[0].value))
    return ids


def seed_references(source: str) -> list[tuple[int, str]]:
    """(line, what) for each seed name literal and seed class use in ``source``, docstrings aside."""
    tree = ast.parse(source)
    skip = _docstrings(tree)
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and node.value in SEED_NAMES and id(node) not in skip:
            found.append((node.lineno, repr(node.value)))
        elif isinstance(node, ast.Name) and node.id in SEED_CLASSES:
            found.append((node.lineno, node.id))
        elif isinstance(node, ast.Attribute) and node.attr in SEED_CLASSES:
            found.append((node.lineno, node.attr))
        elif isinstance(node, ast.ImportFrom):
            found += [(node.lineno, a.name) for a in node.names if a.name in SEED_CLASSES]
    return sorted(set(found))


def test_no_code_outside_the_seeds_branches_on_their_names():
    offences = []
    for folder in SCANNED:
        for path in sorted((REPO / folder).rglob("*.py")):
            rel = path.relative_to(REPO).as_posix()
            if rel in ALLOWED:
                continue
            offences += [f"{rel}:{line}: {what}" for line, what in seed_references(path.read_text())]
    assert not offences, "seed-specific code outside the seeds:\n" + "\n".join(offences)


@pytest.mark.parametrize(
    "code",
    [
        'if model.name == "cart_double_pendulum":\n    pass\n',
        'x = {"double_pendulum": 1}\n',
        "from pendverify.analytic import DoublePendulum\n",
        "ok = isinstance(p, analytic.CartDoublePendulumParams)\n",
    ],
)
def test_the_scan_finds_a_planted_branch(code):
    assert seed_references(code)


def test_docstrings_are_not_code():
    assert not seed_references('"""Run ``check("double_pendulum")``."""\n')


def test_every_sub_package_is_installed():
    """pyproject lists the packages explicitly (the folders are mapped onto ``pendverify``):
    a sub-package missing there works in a checkout and is absent from a wheel."""
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib

    config = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]
    roots = {folder: name for name, folder in config["package-dir"].items()}
    found = set()
    for folder, name in roots.items():
        for init in (REPO / folder).rglob("__init__.py"):
            rel = init.parent.relative_to(REPO / folder).parts
            found.add(".".join((name, *rel)))
    assert found == set(config["packages"]), found ^ set(config["packages"])
