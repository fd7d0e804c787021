"""One reader for every TOML document: ``pendverify.documents`` alone parses TOML.

A second TOML reader (a module importing ``tomllib`` or ``tomli`` and parsing a document its own
way) is what this guards against: every parameter file, scene, sweep, text model and shipped
catalogue goes through ``pendverify.documents`` (its schema style and its error sentences).
"""

from __future__ import annotations

import ast
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
PACKAGE = ("verify", "analytic", "viz", "urdf")
READER = Path("verify", "documents.py")


def toml_imports(path: Path, root: Path) -> list[str]:
    """Where ``path`` imports a TOML parser (``tomllib``, ``tomli``), as ``file:line``."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        names = []
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            names = [node.module or ""]
        if any(n.split(".")[0] in ("tomllib", "tomli") for n in names):
            found.append(f"{path.relative_to(root).as_posix()}:{node.lineno}")
    return found


def second_readers(root: Path = REPO) -> list[str]:
    """Every TOML parser import of the package outside the one reader."""
    return [
        hit
        for folder in PACKAGE
        for path in sorted((root / folder).rglob("*.py"))
        if path != root / READER
        for hit in toml_imports(path, root)
    ]


def test_only_the_reader_parses_toml():
    assert second_readers() == []


def test_the_reader_is_what_the_guard_exempts():
    assert toml_imports(REPO / READER, REPO), "the reader's own import is what the guard looks for"


def test_a_second_reader_is_found(tmp_path):
    (tmp_path / "verify").mkdir()
    (tmp_path / READER).write_text("import tomllib\n")
    (tmp_path / "verify" / "stray.py").write_text("def f():\n    import tomli as t\n    return t\n")
    (tmp_path / "verify" / "other.py").write_text("x = 1\nfrom tomllib import loads\n")
    assert second_readers(tmp_path) == ["verify/other.py:2", "verify/stray.py:2"]
