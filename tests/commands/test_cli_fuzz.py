"""Property-based fuzz of the command line's inputs: whatever a user gives, the contract holds.

Hypothesis writes parameter files, URDFs, scenes, model files and saved trajectories —
garbage bytes, byte-order marks, huge, tiny, NaN, negative and wrongly typed numbers,
directories where files belong, outputs under regular files or in unwritable folders —
and runs ``main([...])`` in-process (check, certify, simulate, render).  Every run must
end with status 0, 1 or 2 (a 3 is a bug to fix), no traceback, and at most one error
line (exactly one for status 2).

Seeded (``FUZZ_SEED``) and without an example database, so every run tries the same
inputs; 80 examples per command (25 for certify, whose battery is heavier) keep the
file well under a minute.  The scenes run with ``PENDVERIFY_MAX_SAMPLES`` lowered to
3000 so that no example integrates for long.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, seed, settings
from hypothesis import strategies as st

from pendverify.analytic.params import load_parameter_file
from pendverify.cli import main

REPO = Path(__file__).resolve().parents[2]
PARAMS = (REPO / "analytic" / "params" / "double_pendulum.toml").read_text()
URDF = (REPO / "urdf" / "double_pendulum.urdf").read_text()
SCENE = (REPO / "scenes" / "damped_double_pendulum.toml").read_text()
MINIMAL = REPO / "examples" / "minimal_double_pendulum.py"
MINIMAL_PARAMS = REPO / "examples" / "minimal_double_pendulum.toml"

DEFAULT_PARAMETERS = load_parameter_file(REPO / "analytic" / "params" / "double_pendulum.toml")[2].as_dict()

FUZZ_SEED = 20261129
FUZZ = settings(
    max_examples=80,
    # no deadline: an example's time depends on the machine's load, and a test never asserts time
    # (Hypothesis measures a deadline after the example returns, so it never caught a hang either:
    # the commands' own bounds do, PENDVERIFY_MAX_* and the progress they show)
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.too_slow],
)

#: numbers and non-numbers, as TOML values
TOML_VALUES = st.sampled_from(
    [
        "nan",
        "inf",
        "-inf",
        "-1.0",
        "0",
        "0.0",
        "1e300",
        "1e-300",
        "1e200",
        "1e-200",
        "9" * 400,
        "-" + "9" * 30,
        '"text"',
        "true",
        "[1.0, 2.0]",
        "{a = 1}",
        "1979-05-27",
        "2.5",
        "0.3",
    ]
)
#: numbers and non-numbers, as URDF attribute text
URDF_VALUES = st.sampled_from(
    [
        "nan",
        "inf",
        "1e400",
        "-1",
        "0",
        "1e300",
        "1e-300",
        "1e200",
        "1e30",
        "-1e30",
        "",
        " 1",
        "1,5",
        "x",
        "0.5",
    ]
)
GARBAGE = st.binary(min_size=0, max_size=200)
BOM = b"\xef\xbb\xbf"


def _text_file(valid: str, keys: list[str], values) -> st.SearchStrategy[bytes]:
    """The valid text with one key's value replaced, garbage bytes, or the text behind a BOM."""

    def replaced(choice) -> bytes:
        key, value = choice
        lines = [
            f"{key} = {value}" if line.split("=")[0].strip() == key else line for line in valid.splitlines()
        ]
        return "\n".join(lines).encode()

    return st.one_of(
        st.tuples(st.sampled_from(keys), values).map(replaced),
        GARBAGE,
        st.just(BOM + valid.encode()),
        st.just(valid.encode()[: len(valid) // 2]),
    )


PARAM_FILES = _text_file(
    PARAMS, ["m1", "m2", "l1", "l2", "r1", "I1", "I2", "b1", "g", "model", "extra"], TOML_VALUES
)
SCENE_FILES = _text_file(
    SCENE, ["duration", "sample_rate", "q", "v", "method", "rtol", "damping", "gravity", "model"], TOML_VALUES
)


@st.composite
def urdf_files(draw) -> bytes:
    """The seed URDF with one numeric attribute replaced, or garbage, or behind a BOM."""
    kind = draw(st.sampled_from(["attribute", "garbage", "bom", "truncated"]))
    if kind == "garbage":
        return draw(GARBAGE)
    if kind == "bom":
        return BOM + URDF.encode()
    if kind == "truncated":
        return URDF.encode()[: draw(st.integers(0, len(URDF)))]
    attribute = draw(
        st.sampled_from(['value="1.0"', 'ixx="0.0208"', 'izz="0.0208"', 'damping="0.05"', 'xyz="0 0.5 0"'])
    )
    name = attribute.split("=")[0]
    return URDF.replace(attribute, f'{name}="{draw(URDF_VALUES)}"', 1).encode()


MODEL_BODIES = st.sampled_from(
    [
        "import sys\nsys.exit(0)\n",
        "raise SystemExit(3)\n",
        "raise KeyError('x')\n",
        "def broken(:\n",
        "x = 1\n",
        "{base}        raise SystemExit(0)\n",
        "{base}        raise RuntimeError('M')\n",
        "{base}        return [[1.0]]\n",
        "{base}        return None\n",
        "{base}        return 'M'\n",
        "{base}        return float('nan') * Base.mass_matrix(self, q)\n",
        "{base}        return Base.mass_matrix(self, q) if abs(q[0]) < 1 else 1 / 0\n",
    ]
)
BASE = (
    "from pendverify.analytic.plugin import load_model_class\n"
    f"Base = load_model_class({str(MINIMAL)!r})\n\n\n"
    "class Mine(Base):\n    def mass_matrix(self, q):\n"
)


def model_files() -> st.SearchStrategy[bytes]:
    return st.one_of(MODEL_BODIES.map(lambda body: body.format(base=BASE).encode()), GARBAGE)


#: a directory given where a file belongs, now and then
AS_DIRECTORY = st.sampled_from([False] * 5 + [True])
#: where an output goes: a fresh file, under a regular file, a directory, an unwritable folder
#: (a fresh file most often, so that the inputs behind the output check are reached)
OUTPUTS = st.sampled_from(["fresh"] * 5 + ["under-file", "directory", "unwritable", "missing-parents"])


def _output(folder: Path, kind: str, name: str) -> str:
    blocker = folder / "blocker"
    blocker.write_text("")
    unwritable = Path("/sys") if os.geteuid() == 0 else folder / "ro"
    if unwritable != Path("/sys"):
        unwritable.mkdir(exist_ok=True)
        unwritable.chmod(0o555)
    return str(
        {
            "fresh": folder / name,
            "under-file": blocker / name,
            "directory": folder,
            "unwritable": unwritable / name,
            "missing-parents": folder / "a" / "b" / name,
        }[kind]
    )


def _input(folder: Path, name: str, content: bytes, as_directory: bool) -> str:
    path = folder / name
    if as_directory:
        path.mkdir()
    else:
        path.write_bytes(content)
    return str(path)


def run_cli(argv: list[str]) -> tuple[int, str]:
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, err.getvalue()


def assert_contract(argv: list[str]) -> int:
    code, err = run_cli(argv)
    errors = [line for line in err.splitlines() if line.startswith("pendverify:")]
    assert code in (0, 1, 2), f"exit {code} for {argv}: {err}"
    assert "Traceback" not in err, f"{argv}: {err}"
    assert len(errors) == (1 if code == 2 else 0), f"{argv}: {err}"
    return code


@contextlib.contextmanager
def workdir():
    with tempfile.TemporaryDirectory(prefix="pendverify-fuzz-") as name:
        folder = Path(name)
        try:
            yield folder
        finally:
            if (folder / "ro").exists():
                (folder / "ro").chmod(0o755)


@contextlib.contextmanager
def sample_limit(limit: str):
    old = os.environ.get("PENDVERIFY_MAX_SAMPLES")
    os.environ["PENDVERIFY_MAX_SAMPLES"] = limit
    try:
        yield
    finally:
        if old is None:
            del os.environ["PENDVERIFY_MAX_SAMPLES"]
        else:
            os.environ["PENDVERIFY_MAX_SAMPLES"] = old


def fuzz(**strategies):
    """A seeded (``FUZZ_SEED``), bounded hypothesis test over ``strategies``."""

    def wrap(test):
        return seed(FUZZ_SEED)(FUZZ(given(**strategies)(test)))

    return wrap


def contract_with_file(name: str, content: bytes, as_directory: bool, argv) -> None:
    """Write the input ``name`` (or make it a directory); assert the contract on ``argv(path, folder)``."""
    with workdir() as folder:
        assert_contract(argv(_input(folder, name, content, as_directory), folder))


@fuzz(params=PARAM_FILES, as_dir=AS_DIRECTORY, output=OUTPUTS)
def test_fuzz_check_params(params, as_dir, output):
    def argv(path, folder):
        return ["check", "--params", path, "--samples", "2", "--json", _output(folder, output, "r.json")]

    contract_with_file("p.toml", params, as_dir, argv)


@fuzz(urdf=urdf_files(), as_dir=AS_DIRECTORY, with_params=st.booleans())
def test_fuzz_check_urdf(urdf, as_dir, with_params):
    given_params = (
        ["--params", str(REPO / "analytic" / "params" / "double_pendulum.toml")] if with_params else []
    )
    contract_with_file(
        "u.urdf",
        urdf,
        as_dir,
        lambda path, _: [
            "check",
            "--model",
            "double_pendulum",
            "--urdf",
            path,
            "--samples",
            "2",
            *given_params,
        ],
    )


@fuzz(model=model_files(), as_dir=AS_DIRECTORY)
def test_fuzz_check_model_file(model, as_dir):
    urdf = str(REPO / "urdf" / "double_pendulum.urdf")
    rest = ["--urdf", urdf, "--params", str(MINIMAL_PARAMS), "--samples", "2"]
    contract_with_file("mine.py", model, as_dir, lambda path, _: ["check", "--analytic", path, *rest])


@pytest.mark.slow
@fuzz(scene=SCENE_FILES, output=OUTPUTS, html=st.booleans())
def test_fuzz_simulate(scene, output, html):
    def argv(path, folder):
        return [
            "simulate",
            path,
            "--html" if html else "-o",
            _output(folder, output, "run.html" if html else "run.npz"),
        ]

    with sample_limit("3000"):
        contract_with_file("s.toml", scene, False, argv)


@st.composite
def trajectories(draw) -> bytes:
    """A saved run: garbage, or an npz whose t, q and metadata are drawn."""
    if draw(st.booleans()):
        return draw(GARBAGE)
    n = draw(st.integers(0, 4))
    t = draw(st.sampled_from([np.linspace(0, 1, n), np.full(n, np.nan), np.zeros(n), np.array([[0.0, 1.0]])]))
    q = draw(
        st.sampled_from(
            [np.zeros((n, 2)), np.zeros(n), np.zeros((n, 5)), np.full((n, 2), np.inf), np.array("q")]
        )
    )
    metadata = draw(
        st.sampled_from(
            [
                json.dumps({"model": "double_pendulum", "parameters": DEFAULT_PARAMETERS}),
                json.dumps({"model": "double_pendulum", "parameters": {**DEFAULT_PARAMETERS, "m1": -1}}),
                '{"model": "double_pendulum"}',
                '{"model": "double_pendulum", "parameters": []}',
                '{"model": "nope"}',
                "[1, 2]",
                "not json",
                '{"model_file": "/nonexistent.py"}',
            ]
        )
    )
    buffer = io.BytesIO()
    np.savez(buffer, t=t, q=q, metadata=np.array(metadata))
    return buffer.getvalue()


@fuzz(npz=trajectories(), output=OUTPUTS)
def test_fuzz_render_trajectory(npz, output):
    contract_with_file(
        "run.npz",
        npz,
        False,
        lambda path, folder: ["render", "--trajectory", path, "-o", _output(folder, output, "x.html")],
    )


#: certify's battery is heavier than a check: fewer examples, a few states each
CERTIFY_FUZZ = settings(FUZZ, max_examples=25)


def certify_fuzz(**strategies):
    def wrap(test):
        return seed(FUZZ_SEED)(CERTIFY_FUZZ(given(**strategies)(test)))

    return wrap


@certify_fuzz(params=PARAM_FILES, as_dir=AS_DIRECTORY, output=OUTPUTS)
def test_fuzz_certify_params(params, as_dir, output):
    def argv(path, folder):
        return ["certify", path, "--samples", "4", "-o", _output(folder, output, "certified")]

    contract_with_file("p.toml", params, as_dir, argv)


@certify_fuzz(urdf=urdf_files(), as_dir=AS_DIRECTORY)
def test_fuzz_certify_urdf(urdf, as_dir):
    params = str(REPO / "analytic" / "params" / "double_pendulum.toml")

    def argv(path, folder):
        return ["certify", "--urdf", path, "--params", params, "--samples", "4", "-o", str(folder / "out")]

    contract_with_file("u.urdf", urdf, as_dir, argv)
