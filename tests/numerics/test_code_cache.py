"""The generated-code cache never runs what it did not write, and never changes a verdict.

Each test plants one problem in a copy of a warm cache (``docs/code-cache.md``): a
module with an index that agrees with it but was not signed with the user's cache key,
the same in a folder open to others or owned by someone else, a numba index pickle that
would write a marker file when loaded, a truncated numba data file, a full disk, a cache
path that is a file, a truncated reference.  Planted code would write ``MARKER``; the
tests assert it is absent, that the run succeeds, and what was regenerated.
"""

from __future__ import annotations

import hashlib
import importlib.metadata
import json
import os
import pickle
import shutil
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pytest

from pendverify.analytic import MODELS
from pendverify.analytic.params import default_parameter_file, load_parameter_file
from pendverify.errors import FileAccessError
from pendverify.numerics import generate, reference
from pendverify.numerics.codegen import cache as code_cache
from pendverify.numerics.codegen import folder as code_folder

REPO = Path(__file__).resolve().parents[2]
TIMEOUT = 240

_CHILD = """
import json, sys
import numpy as np
from pendverify.analytic import MODELS
from pendverify.analytic.params import default_parameter_file, load_parameter_file
from pendverify.numerics import generate
model = MODELS["double_pendulum"](load_parameter_file(default_parameter_file("double_pendulum"))[2])
system = generate.GeneratedSystem.from_model(model)
out = system.rhs(np.array([0.3, -0.2, 0.5, 0.1])).tolist()
stats = system.module._rhs.stats
print(json.dumps(dict(origin=system.kernel.origin, path=str(system.kernel.path), out=out,
                      hits=sum(stats.cache_hits.values()), misses=sum(stats.cache_misses.values()))))
"""


def _child(base: Path, **env) -> tuple[dict, str]:
    """Run ``_CHILD`` on the cache ``base``: (its JSON line, its stderr); it must exit 0."""
    environment = dict(os.environ, PENDVERIFY_CACHE=str(base), **env)
    argv = [sys.executable, "-c", _CHILD]
    done = subprocess.run(argv, env=environment, capture_output=True, text=True, timeout=TIMEOUT)
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1]), done.stderr


@pytest.fixture(scope="module")
def warm(tmp_path_factory) -> tuple[Path, dict]:
    """A cache holding the double pendulum's module and numba's compiled ``_rhs``, and what it gives."""
    base = tmp_path_factory.mktemp("warm") / "cache"
    first, _ = _child(base)
    assert first["origin"] == "generated" and first["misses"] == 1
    return base, first


@pytest.fixture
def cache(warm, tmp_path) -> Path:
    """A copy of the warm cache (modes kept) for one test to plant in."""
    base = tmp_path / "cache"
    shutil.copytree(warm[0], base)
    return base


MARKER_CODE = "open({marker!r}, 'w').write('planted code ran')\n"


class _Planted:
    """Pickles to a call of ``open(marker, 'w')``: unpickling it creates the marker file."""

    def __init__(self, marker: Path):
        self.marker = str(marker)

    def __reduce__(self):
        return (open, (self.marker, "w"))


def _key_of_double_pendulum() -> str:
    return code_cache.model_key(MODELS["double_pendulum"])


def _plant_module_and_index(generated: Path, marker: Path, sign_with: bytes | None) -> Path:
    """A module that writes ``marker`` and an index of the double pendulum's key naming it, its
    SHA-256 agreeing; signed with ``sign_with`` (None: the index format of before, unsigned)."""
    import hmac

    source = MARKER_CODE.format(marker=str(marker)) + "N = 2\nPARAMETERS = ()\n"
    digest = hashlib.sha256(source.encode()).hexdigest()
    (generated / f"rhs_double_pendulum_{digest[:24]}.py").write_text(source)
    key = _key_of_double_pendulum()
    for old in generated.glob(f"index_rhs_{key[:24]}.*"):
        old.unlink()
    if sign_with is None:
        (generated / f"index_rhs_{key[:24]}.txt").write_text(digest + "\n")
        return generated
    record = {"key": key, "sha256": digest, "pendverify": importlib.metadata.version("pendverify")}
    text = json.dumps(record, sort_keys=True, separators=(",", ":"))
    mac = hmac.new(sign_with, text.encode(), hashlib.sha256).hexdigest()
    (generated / f"index_rhs_{key[:24]}.json").write_text(f"{text}\n{mac}\n")
    return generated


def test_a_warm_cache_is_read_and_nothing_compiles_again(warm, cache):
    """The real entry still verifies: read from disk, numba's code loaded (no compilation)."""
    second, err = _child(cache)
    assert second["origin"] == "disk" and (second["hits"], second["misses"]) == (1, 0), second
    assert second["out"] == warm[1]["out"] and "note" not in err
    modes = {p: p.stat().st_mode & 0o777 for p in (cache, cache / "generated")}
    assert set(modes.values()) == {0o700}, modes


@pytest.mark.slow
@pytest.mark.parametrize("signature", ["unsigned", "another key"])
def test_a_planted_module_with_a_matching_index_is_never_imported(cache, tmp_path, signature):
    marker = tmp_path / "MARKER"
    _plant_module_and_index(cache / "generated", marker, None if signature == "unsigned" else b"x" * 32)
    result, _ = _child(cache)
    assert not marker.exists(), "the planted module ran"
    assert result["origin"] == "generated"  # the index did not verify: the model was read again
    # the index is rewritten, signed: the next process reads the real module from disk again
    again, _ = _child(cache)
    assert again["origin"] == "disk" and not marker.exists()


@pytest.mark.slow
@pytest.mark.parametrize("breach", ["writable by others", "owned by another user"])
def test_a_cache_folder_others_can_write_is_not_used(cache, tmp_path, breach):
    """Even with the user's own key copied in (a valid signature), a folder that is not private is
    not read: the run generates into a temporary folder, and says so in one line."""
    marker = tmp_path / "MARKER"
    generated = cache / "generated"
    secret = (generated / "cache.key").read_bytes()
    _plant_module_and_index(generated, marker, secret)
    if breach == "writable by others":
        generated.chmod(0o777)
        rule = "writable by group or others (mode 0777)"
    else:
        os.chown(generated, 54321, -1)
        rule = "owned by user id 54321"
    result, err = _child(cache)
    assert not marker.exists(), "the planted module ran"
    assert result["origin"] == "generated" and not result["path"].startswith(str(cache))
    lines = [line for line in err.splitlines() if "code cache" in line]
    assert len(lines) == 1 and str(generated) in lines[0] and rule in lines[0], err
    assert "private to its user" in lines[0]
    assert not Path(result["path"]).exists()  # the temporary folder is removed at exit


def _numba_file(generated: Path, function: str, suffix: str) -> Path:
    found = sorted((generated / "__pycache__").glob(f"rhs_double_pendulum_*.{function}-*{suffix}"))
    assert found, f"no numba {suffix} for {function}"
    return found[0]


def test_a_planted_numba_index_pickle_is_never_loaded(warm, cache, tmp_path):
    marker = tmp_path / "MARKER"
    nbi = _numba_file(cache / "generated", "_rhs", ".nbi")
    nbi.write_bytes(pickle.dumps(_Planted(marker)) + b"garbage")
    result, _ = _child(cache)
    assert not marker.exists(), "numba unpickled the planted index"
    assert result["origin"] == "disk" and result["misses"] == 1  # the planted file was deleted: compiled
    assert result["out"] == warm[1]["out"]
    again, _ = _child(cache)  # numba's new files were recorded: loaded, not compiled
    assert (again["hits"], again["misses"]) == (1, 0), again


@pytest.mark.slow
@pytest.mark.parametrize("damage", ["truncated .nbc", "garbage .nbi", "unrecorded .nbc"])
def test_damaged_numba_files_are_compiled_again(warm, cache, damage):
    generated = cache / "generated"
    if damage == "truncated .nbc":
        nbc = _numba_file(generated, "_rhs", ".nbc")
        nbc.write_bytes(nbc.read_bytes()[: nbc.stat().st_size // 2])
    elif damage == "garbage .nbi":
        _numba_file(generated, "_rhs", ".nbi").write_bytes(b"\x80\x04garbage")
    else:  # a file numba's index would name, that no process of this user recorded
        nbc = _numba_file(generated, "_rhs", ".nbc")
        nbc.with_name(nbc.name.replace(".1.nbc", ".2.nbc")).write_bytes(nbc.read_bytes())
    result, err = _child(cache)
    assert result["out"] == warm[1]["out"] and "note" not in err
    assert result["misses"] == (0 if damage == "unrecorded .nbc" else 1), result
    again, _ = _child(cache)
    assert (again["hits"], again["misses"]) == (1, 0), again


# --- a cache that cannot be written ------------------------------------------------------------------
# (fixture fresh_cache: conftest.py)


def test_a_full_disk_generates_into_a_temporary_folder(fresh_cache, monkeypatch, capsys):
    real = code_cache.write_atomic

    def full(path, data):
        if Path(path).is_relative_to(fresh_cache):
            raise FileAccessError(str(path), "write", "No space left on device")
        return real(path, data)

    monkeypatch.setattr(code_cache, "write_atomic", full)
    k = code_cache.kernel(MODELS["double_pendulum"])
    assert k.origin == "generated" and not k.path.is_relative_to(fresh_cache) and k.path.is_file()
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(fresh_cache) in err[0] and "No space left on device" in err[0], err


def test_a_full_disk_everywhere_is_one_line_naming_the_folder(fresh_cache, monkeypatch):
    def full(path, data):
        raise FileAccessError(str(path), "write", "No space left on device")

    monkeypatch.setattr(code_cache, "write_atomic", full)
    with pytest.raises(FileAccessError) as caught:
        code_cache.kernel(MODELS["double_pendulum"])
    line = str(caught.value)
    assert "\n" not in line and "pendverify-code-" in line and "No space left on device" in line


def test_a_cache_path_that_is_a_file_uses_a_temporary_folder(tmp_path, monkeypatch, capsys):
    afile = tmp_path / "not-a-folder"
    afile.write_text("")
    monkeypatch.delenv("PENDVERIFY_CACHE")
    monkeypatch.setenv("XDG_CACHE_HOME", str(afile))
    code_folder.forget()
    try:
        used = code_cache.cache_dir()
        assert used.is_dir() and not used.is_relative_to(afile)
        assert code_cache.cache_dir() == used  # decided once per process
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and str(afile) in err[0] and "Not a directory" in err[0], err
    finally:
        code_folder.forget()


def _certify_items(out: Path, env: dict) -> tuple[dict, str]:
    params = REPO / "analytic" / "params" / "double_pendulum.toml"
    argv = [sys.executable, "-m", "pendverify", "certify", str(params), "-o", str(out / "bundle")]
    argv += ["--samples", "40", "--json", str(out / "items.json"), "--quiet"]
    done = subprocess.run(argv, env=env, capture_output=True, text=True, timeout=TIMEOUT)
    assert done.returncode == 0, done.stderr
    items = json.loads((out / "items.json").read_text())["items"]
    return {i["name"]: (i.get("engine"), i["passed"], i["samples"]) for i in items}, done.stderr


@pytest.mark.slow
def test_certify_with_an_unusable_cache_issues_the_same_items(tmp_path):
    """``PENDVERIFY_CACHE`` naming a file: every invariant on the engine of a normal run,
    ``invariant:gravity:engines`` included, and one line saying where the code went."""
    (tmp_path / "normal").mkdir()
    (tmp_path / "unusable").mkdir()
    normal, _ = _certify_items(tmp_path / "normal", dict(os.environ))
    afile = tmp_path / "cache-file"
    afile.write_text("")
    unusable, err = _certify_items(tmp_path / "unusable", dict(os.environ, PENDVERIFY_CACHE=str(afile)))
    assert "invariant:gravity:engines" in normal
    assert unusable == normal
    assert [line for line in err.splitlines() if "code cache" in line and str(afile) in line], err


def test_the_battery_stops_rather_than_change_engine_when_no_folder_can_be_written(monkeypatch):
    """A cache error reaches the command as its one line: the battery does not fall back to ABA."""
    from pendverify.certify import simulations
    from pendverify.simulation import compiled_scene

    def unwritable(scene):
        raise FileAccessError("/nowhere/generated/rhs.py", "write", "Read-only file system")

    monkeypatch.setattr(compiled_scene, "compile_scene", unwritable)
    scene = types.SimpleNamespace()  # compile_scene fails before it reads the scene
    with pytest.raises(FileAccessError):
        simulations.run_battery_scene(scene, "robot.urdf", None)


# --- the Taylor reference cache ----------------------------------------------------------------------
@pytest.fixture
def small_problem(tmp_path, monkeypatch):
    monkeypatch.setenv("PENDVERIFY_CACHE", str(tmp_path / "cache"))
    model = MODELS["double_pendulum"](load_parameter_file(default_parameter_file("double_pendulum"))[2])
    fast = generate.GeneratedSystem.from_model(model)
    x0 = np.array([0.3, -0.2, 0.5, 0.1])
    grid = np.linspace(0.0, 0.05, 3)
    return (fast, x0, 0.05, grid), tmp_path / "cache"


@pytest.mark.parametrize("damage", ["truncated", "garbage", "another key's"])
def test_a_damaged_reference_is_computed_again(small_problem, damage):
    problem, base = small_problem
    first = reference.reference(*problem, digits=12, check_digits=16)
    (path,) = base.glob("reference-*.npz")
    again = reference.reference(*problem, digits=12, check_digits=16)
    assert again.cached and np.array_equal(again.hi, first.hi)
    data = path.read_bytes()
    if damage == "truncated":
        path.write_bytes(data[: len(data) // 2])
    elif damage == "garbage":
        path.write_bytes(b"PK\x03\x04" + b"\x00" * 64)
    else:
        other = reference.reference(problem[0], problem[1], 0.04, np.linspace(0, 0.04, 3), 12, 16)
        (other_path,) = (p for p in base.glob("reference-*.npz") if p != path)
        shutil.copy(other_path, path)
        assert not other.cached
    redone = reference.reference(*problem, digits=12, check_digits=16)
    assert not redone.cached and np.array_equal(redone.hi, first.hi)
    assert reference.reference(*problem, digits=12, check_digits=16).cached  # rewritten


def test_a_reference_that_cannot_be_cached_is_returned_with_a_note(small_problem, monkeypatch, capsys):
    problem, _ = small_problem

    def full(path, data):
        raise FileAccessError(str(path), "write", "No space left on device")

    monkeypatch.setattr(reference, "write_atomic", full)
    capsys.readouterr()
    ref = reference.reference(*problem, digits=12, check_digits=16)
    assert not ref.cached and np.all(np.isfinite(ref.hi))
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "No space left on device" in err[0], err


_LIMITED = """
import resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write beyond the limit fails (EFBIG), as on a full disk
resource.setrlimit(resource.RLIMIT_FSIZE, (int(sys.argv[1]), int(sys.argv[1])))
from pendverify.cli import main
sys.exit(main(sys.argv[2:]))
"""


def _limited(base: Path, limit: int, *argv: str) -> subprocess.CompletedProcess:
    """``pendverify ARGV`` with files limited to ``limit`` bytes, on the cache ``base``."""
    env = dict(os.environ, PENDVERIFY_CACHE=str(base))
    command = [sys.executable, "-c", _LIMITED, str(limit), *argv]
    return subprocess.run(command, env=env, capture_output=True, text=True, timeout=TIMEOUT)


def test_certify_on_a_disk_too_full_for_any_code_is_one_line_exit_2(tmp_path):
    params = str(REPO / "analytic" / "params" / "double_pendulum.toml")
    out = str(tmp_path / "out")
    done = _limited(tmp_path / "cache", 4096, "certify", params, "-o", out, "--samples", "40")
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr and "internal error" not in done.stderr
    error = [line for line in done.stderr.splitlines() if line.startswith("pendverify: error:")]
    assert len(error) == 1 and "pendverify-code-" in error[0] and "File too large" in error[0], done.stderr
    assert str(tmp_path / "cache" / "generated") in done.stderr  # the note names the cache folder


def test_numba_that_cannot_write_its_cache_runs_uncached_with_a_note(warm, tmp_path):
    """Files limited to a size the module fits in and numba's machine code of ``_rhs`` does not
    (≈ 21 and 26 kB): it runs, uncached."""
    module_size = Path(warm[1]["path"]).stat().st_size
    code_size = _numba_file(Path(warm[1]["path"]).parent, "_rhs", ".nbc").stat().st_size
    assert module_size < code_size
    size = (module_size + code_size) // 2
    limit = "import resource, signal; signal.signal(signal.SIGXFSZ, signal.SIG_IGN); "
    limit += f"resource.setrlimit(resource.RLIMIT_FSIZE, ({size}, {size}))\n"
    env = dict(os.environ, PENDVERIFY_CACHE=str(tmp_path / "cache"))
    done = subprocess.run(
        [sys.executable, "-c", limit + _CHILD], env=env, capture_output=True, text=True, timeout=TIMEOUT
    )
    assert done.returncode == 0 and "Traceback" not in done.stderr, done.stderr
    result = json.loads(done.stdout.strip().splitlines()[-1])
    assert result["out"] == warm[1]["out"] and result["misses"] == 1
    notes = [line for line in done.stderr.splitlines() if "numba cannot write its cache" in line]
    assert len(notes) == 1 and "File too large" in notes[0], done.stderr
