"""Property-based fuzz of `render --trajectory RUN.npz`: whatever the npz holds, the contract holds.

Hypothesis writes npz files with random arrays (shapes, dtypes: floats, ints, bools, complex,
strings, bytes, dates, objects), arrays left out, and metadata that is random JSON, JSON nested
deeply, not JSON, or a run's metadata with its values swapped for wrong ones — among them a
``model_file`` naming a Python file that writes a marker when imported.  Each example runs
``main(["render", "--trajectory", ...])`` in-process and must end with status 0, 1 or 2 (never
3), no traceback, exactly one error line for status 2, and the marker absent: a saved run never
runs code.

Seeded (``FUZZ_SEED``), no example database; ``PENDVERIFY_MAX_FRAMES`` and
``PENDVERIFY_MAX_SAMPLES`` are lowered so that no example renders for long.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import tempfile
from pathlib import Path

import numpy as np
import tomllib
from hypothesis import HealthCheck, given, seed, settings
from hypothesis import strategies as st

from pendverify.analytic.params import load_parameter_file
from pendverify.cli import main

REPO = Path(__file__).resolve().parents[2]
DEFAULT_PARAMETERS = load_parameter_file(REPO / "analytic" / "params" / "double_pendulum.toml")[2].as_dict()
TEXT_MODEL = str(REPO / "examples" / "minimal_double_pendulum_text.toml")
MINIMAL_PARAMETERS = tomllib.loads((REPO / "examples" / "minimal_double_pendulum.toml").read_text())[
    "parameters"
]
URDF = str(REPO / "urdf" / "double_pendulum.urdf")
FUZZ_SEED = 20261201
LIMITS = {"PENDVERIFY_MAX_FRAMES": "400", "PENDVERIFY_MAX_SAMPLES": "2000"}
#: the planted model file: importing it writes the marker beside it
PLANTED = "open(__file__ + '.marker', 'w').close()\n"
#: how the metadata names the planted file before the test writes its path in
PLANTED_NAME = "@planted@/evil.py"

NUMBERS = st.sampled_from([0.0, 1.0, -1.0, 0.5, 1e300, -1e300, 1e-300, np.nan, np.inf, -np.inf, 3.0])
DTYPES = st.sampled_from(
    ["<f8", "<f4", "<f2", ">f8", "<i8", "|i1", "<u4", "|b1", "<c16", "<U3", "|S2", "<M8[s]", "O"]
)
SHAPES = st.lists(st.integers(0, 6), min_size=0, max_size=3).map(tuple)


@st.composite
def arrays(draw) -> np.ndarray:
    """A random array: any of ``DTYPES``, any small shape, values from ``NUMBERS``."""
    dtype, shape = draw(DTYPES), draw(SHAPES)
    values = np.array(draw(st.lists(NUMBERS, min_size=1, max_size=4)))
    filled = np.resize(values, shape) if shape else values[0]
    with np.errstate(all="ignore"):
        if dtype == "O":
            return np.array(filled, dtype=object)
        if dtype[1] in "USM":
            return np.full(shape, "1", dtype=dtype) if dtype[1] != "M" else np.zeros(shape, dtype=dtype)
        if dtype[1] in "iub":
            return np.nan_to_num(np.asarray(filled), nan=0, posinf=1, neginf=-1).astype(dtype)
        return np.asarray(filled).astype(dtype)


#: runs as ``simulate -o`` writes them: a built-in model's, a Python model file's (the planted
#: one: refused without --analytic) and a text model's (read)
BASE_RUNS = [
    {"model": "double_pendulum", "parameters": DEFAULT_PARAMETERS},
    {
        "model": "minimal_double_pendulum",
        "model_file": PLANTED_NAME,
        "urdf": URDF,
        "parameters": MINIMAL_PARAMETERS,
    },
    {
        "model": "minimal_double_pendulum",
        "model_file": TEXT_MODEL,
        "urdf": URDF,
        "parameters": MINIMAL_PARAMETERS,
    },
]
#: values a metadata key is set to
METADATA_VALUES = st.sampled_from(
    [
        None,
        5,
        -1.5,
        "",
        "nope",
        "double_pendulum",
        "cart_double_pendulum",
        "minimal_double_pendulum",
        PLANTED_NAME,
        PLANTED_NAME + ".toml",
        TEXT_MODEL,
        "a\0b.py",
        "x" * 5000,
        "/",
        URDF,
        "<robot/>",
        "/nonexistent.urdf",
        [],
        {},
        [1, 2],
        {"m1": "x"},
        {**DEFAULT_PARAMETERS, "m1": -1},
        {**DEFAULT_PARAMETERS, "m1": float("nan")},
        DEFAULT_PARAMETERS,
        MINIMAL_PARAMETERS,
    ]
)
METADATA_KEYS = st.sampled_from(["model", "model_file", "urdf", "parameters", "scene"])
RAW_METADATA = st.sampled_from(["not json", "[" * 5000, "{" * 100_000, "", "[1, 2]", "null", '"text"'])


@st.composite
def saved_runs(draw) -> dict[str, object]:
    """The members of an npz: a run as ``simulate -o`` writes it, then up to four changes drawn.

    The metadata names the planted model file as ``PLANTED_NAME``, replaced by its path when written.
    """
    meta = dict(draw(st.sampled_from(BASE_RUNS)))
    span = draw(st.sampled_from([1.0, 0.5, 2.0]))
    t = np.linspace(0.0, span, 20)
    members: dict[str, object] = {"t": t, "q": np.column_stack([np.sin(t), np.cos(t)])}
    raw, dropped = None, set()
    for change in draw(st.lists(st.integers(0, 7), max_size=4)):
        if change == 0:
            members["t"] = draw(arrays())
        elif change == 1:
            members["q"] = draw(arrays())
        elif change == 2:
            samples = draw(st.integers(0, 3) | st.integers(2, 40))
            members["t"] = np.linspace(0.0, draw(st.sampled_from([1e9, 1e300, -1.0, 0.0, 100.0])), samples)
            members["q"] = np.zeros((samples, draw(st.integers(1, 3))))
        elif change in (3, 4):
            meta[draw(METADATA_KEYS)] = draw(METADATA_VALUES)
        elif change == 5:
            meta.pop(draw(METADATA_KEYS), None)
        elif change == 6:
            raw = draw(RAW_METADATA)
        else:
            dropped.add(draw(st.sampled_from(["t", "q", "metadata"])))
    members["metadata"] = raw if raw is not None else json.dumps(meta)
    return {name: value for name, value in members.items() if name not in dropped}


@contextlib.contextmanager
def environment(values: dict[str, str]):
    old = {k: os.environ.get(k) for k in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for key, value in old.items():
            if value is None:
                del os.environ[key]
            else:
                os.environ[key] = value


def write_npz(path: Path, members: dict, planted: Path) -> None:
    """The npz of ``members``, the metadata's ``PLANTED_NAME`` replaced by the planted file's path."""
    arrays = dict(members)
    if "metadata" in arrays:
        arrays["metadata"] = np.array(
            arrays["metadata"].replace(PLANTED_NAME, json.dumps(str(planted))[1:-1])
        )
    np.savez(path, **arrays)


@seed(FUZZ_SEED)
# no deadline: an example's time depends on the machine's load, and a test never asserts time
@settings(max_examples=120, deadline=None, database=None, suppress_health_check=[HealthCheck.too_slow])
@given(members=saved_runs())
def test_fuzz_render_trajectory_never_runs_code_and_keeps_the_contract(members):
    with tempfile.TemporaryDirectory(prefix="pendverify-fuzz-") as name, environment(LIMITS):
        folder = Path(name)
        planted = folder / "evil.py"
        planted.write_text(PLANTED + (REPO / "examples" / "minimal_double_pendulum.py").read_text())
        (folder / "evil.py.toml").write_text(PLANTED)
        path = folder / "run.npz"
        write_npz(path, members, planted)
        err = io.StringIO()
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
            code = main(["render", "--trajectory", str(path), "-o", str(folder / "run.html")])
        text = err.getvalue()
        errors = [line for line in text.splitlines() if line.startswith("pendverify:")]
        assert code in (0, 1, 2), f"exit {code}: {text}"
        assert "Traceback" not in text, text
        assert len(errors) == (1 if code == 2 else 0), text
        assert all(len(line) < 600 for line in errors), text
        assert not (folder / "evil.py.marker").exists(), "the model file the npz names was imported"
