"""One cache location (``pendverify.cache_location``): every cache is under ``cache_root()``, and no
other module reads the variables that name it."""

from __future__ import annotations

import re
from pathlib import Path

from pendverify.cache_location import CACHE_VARIABLE, cache_root
from pendverify.numerics import reference
from pendverify.numerics.codegen import cache as code_cache
from pendverify.numerics.codegen import folder

REPO = Path(__file__).resolve().parents[2]
HOME = Path("verify", "cache_location.py")
#: a module that reads the cache's environment variables itself (a second cache location)
READS = re.compile(r"environ(?:\.get)?\s*[\[(]\s*['\"](?:PENDVERIFY_CACHE|XDG_CACHE_HOME)['\"]")


def test_the_variable_names_the_folder_else_the_xdg_folder(monkeypatch, tmp_path):
    monkeypatch.setenv(CACHE_VARIABLE, str(tmp_path / "named"))
    assert cache_root() == tmp_path / "named"
    monkeypatch.delenv(CACHE_VARIABLE)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache_root() == tmp_path / "xdg" / "pendverify"
    monkeypatch.delenv("XDG_CACHE_HOME")
    assert cache_root() == Path.home() / ".cache" / "pendverify"


def test_every_cache_is_under_the_one_folder(monkeypatch, tmp_path):
    monkeypatch.setenv(CACHE_VARIABLE, str(tmp_path / "cache"))
    folder.forget()
    try:
        assert code_cache.cache_dir() == tmp_path / "cache" / "generated"
    finally:
        folder.forget()
    assert reference._cache_path("0" * 64).parent == tmp_path / "cache"


def second_locations(root: Path) -> list[str]:
    """The package's modules, other than the one location, that read the cache's variables."""
    return sorted(
        str(path.relative_to(root))
        for sub in ("verify", "analytic", "viz")
        for path in (root / sub).rglob("*.py")
        if path != root / HOME and READS.search(path.read_text(encoding="utf-8"))
    )


def test_no_second_cache_location():
    assert second_locations(REPO) == []


def test_a_second_cache_location_is_found(tmp_path):
    (tmp_path / "verify").mkdir()
    (tmp_path / HOME).write_text('os.environ.get("PENDVERIFY_CACHE")\n')
    (tmp_path / "verify" / "stray.py").write_text('base = os.environ.get("XDG_CACHE_HOME") or "~"\n')
    assert second_locations(tmp_path) == ["verify/stray.py"]
