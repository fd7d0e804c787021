"""One evidence type: the package defines ``pendverify.checks.evidence.Evidence`` and no second one.

A second evidence type is a class that carries an error and a tolerance next to a verdict (a
field or property named ``passed``, ``status``, ``verdict``, ``level`` or ``failed``), or one
of the four names the package once used for the concept.  The package's source is read as
syntax trees (nothing is imported or run); each finding names its file, line and class.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE_DIRS = ("verify", "analytic", "viz")
HOME = ROOT / "verify" / "checks" / "evidence.py"
OLD_NAMES = {"CheckResult", "InvariantResult", "StressResult", "BatteryItem"}
VERDICT_NAMES = {"passed", "status", "verdict", "level", "failed"}


def _members(node: ast.ClassDef) -> set[str]:
    """The names a class body defines: annotated fields, assignments and functions (properties)."""
    names = set()
    for item in node.body:
        if isinstance(item, ast.AnnAssign) and isinstance(item.target, ast.Name):
            names.add(item.target.id)
        elif isinstance(item, ast.Assign):
            names.update(t.id for t in item.targets if isinstance(t, ast.Name))
        elif isinstance(item, (ast.FunctionDef, ast.AsyncFunctionDef)):
            names.add(item.name)
    return names


def evidence_classes(source: str) -> list[tuple[int, str]]:
    """(line, class name) of every class in ``source`` that is an evidence type (module docstring)."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if not isinstance(node, ast.ClassDef):
            continue
        members = _members(node)
        parts = {part for name in members for part in name.lower().split("_")}
        has_error = bool(parts & {"err", "error", "errors"})
        has_tolerance = bool(parts & {"tol", "tolerance", "tolerances"})
        if node.name in OLD_NAMES or (has_error and has_tolerance and members & VERDICT_NAMES):
            found.append((node.lineno, node.name))
    return found


def package_files(root: Path = ROOT) -> list[Path]:
    return sorted(p for d in PACKAGE_DIRS for p in (root / d).rglob("*.py"))


def second_definitions(root: Path = ROOT) -> list[str]:
    """Every evidence type defined outside ``pendverify.checks.evidence``, as "file:line class"."""
    home = root / HOME.relative_to(ROOT)
    return [
        f"{path.relative_to(root)}:{line} {name}"
        for path in package_files(root)
        for line, name in evidence_classes(path.read_text(encoding="utf-8"))
        if path != home
    ]


def test_the_package_defines_one_evidence_type():
    assert package_files(), "no package source found"
    assert second_definitions() == []
    assert [name for _, name in evidence_classes(HOME.read_text(encoding="utf-8"))] == ["Evidence"]


PLANTED = {
    "an old name": "class StressResult:\n    pass\n",
    "error, tolerance and passed": (
        "from dataclasses import dataclass\n\n@dataclass\nclass Row:\n"
        "    max_error: float\n    tolerance: float\n    passed: bool\n"
    ),
    "error, tolerance and a status property": (
        "class Item:\n    error: float\n    tol: float\n\n    @property\n    def status(self):\n"
        "        return 'pass'\n"
    ),
}


@pytest.mark.parametrize("source", PLANTED.values(), ids=PLANTED.keys())
def test_a_planted_second_evidence_type_is_found(tmp_path, source):
    for d in PACKAGE_DIRS:
        (tmp_path / d).mkdir()
    (tmp_path / "viz" / "planted.py").write_text(source, encoding="utf-8")
    (found,) = second_definitions(tmp_path)
    assert found.startswith("viz/planted.py:")


def test_a_class_with_figures_but_no_verdict_is_not_evidence():
    source = (
        "class Judged:\n    rel_err: float\n    rel_tol: float\n\n    def ratio(self):\n        return 1.0\n"
    )
    assert evidence_classes(source) == []
