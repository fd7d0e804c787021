"""One list of engine names (``pendverify.simulation.engine_names``): no module writes one of its
lists out again (the command line's ``--engine`` choices, the scene reader, the engine study)."""

from __future__ import annotations

import ast
from pathlib import Path

from pendverify.simulation import engine_names

REPO = Path(__file__).resolve().parents[2]
HOME = Path("verify", "simulation", "engine_names.py")
LISTS = {
    name: frozenset(value)
    for name, value in vars(engine_names).items()
    if name.isupper() and isinstance(value, tuple)
}


def written_again(root: Path) -> list[str]:
    """``file:line (LIST)`` of each literal tuple, list or set of the package, outside the one
    home, that holds every name of one of the engine lists."""
    found = []
    for sub in ("verify", "analytic", "viz"):
        for path in sorted((root / sub).rglob("*.py")):
            if path == root / HOME:
                continue
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
                    words = {
                        e.value for e in node.elts if isinstance(e, ast.Constant) and isinstance(e.value, str)
                    }
                    found += [
                        f"{path.relative_to(root).as_posix()}:{node.lineno} ({name})"
                        for name, names in LISTS.items()
                        if names <= words
                    ]
    return found


def test_the_lists_are_what_the_engines_are():
    assert set(LISTS) == {"PINOCCHIO_ENGINES", "RHS_ENGINES", "SCENE_ENGINE_CHOICES"}
    assert LISTS["PINOCCHIO_ENGINES"] < LISTS["RHS_ENGINES"]


def test_no_engine_list_is_written_twice():
    assert written_again(REPO) == []


def test_a_list_written_again_is_found(tmp_path):
    (tmp_path / "verify" / "commands").mkdir(parents=True)
    (tmp_path / "verify" / "commands" / "run.py").write_text(
        'p.add_argument("--engine", choices=["aba", "closed_form", "both"])\n'
    )
    (tmp_path / "verify" / "other.py").write_text('ENGINES = ("aba", "closed_form")  # not a whole list\n')
    assert written_again(tmp_path) == ["verify/commands/run.py:1 (SCENE_ENGINE_CHOICES)"]
