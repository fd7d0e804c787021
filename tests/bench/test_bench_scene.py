"""``pendverify bench accuracy --scene``: the benchmark on a user's scene (a model file with its
parameters and URDF), the refusals, and the default problems (``scenes/bench``) left as they were.
No test looks at a wall time."""

from __future__ import annotations

import csv
import io
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from pendverify.bench import workprecision
from pendverify.bench.problems import build_problem, engine_rhs, scene_problems, shipped_problems
from pendverify.cli import main
from tests.bench.test_bench import SMALL, run_quick

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
REFERENCE_MARGIN = 1000.0
ENGINE_RTOL = 1e-12

CART_POLE = f"""
name = "cart-pole swing"
model = "{EXAMPLES / "cart_pole.py"}"
params = "{EXAMPLES / "cart_pole.toml"}"
urdf = "{EXAMPLES / "cart_pole.urdf"}"

[initial]
q = [0.0, 1.0]
v = [0.0, 0.0]

[time]
duration = 5.0

[integrator]
method = "rk4"   # the benchmark chooses its own integrators
step = 0.01

[effects]
gravity = true
{{extra}}
"""
LQR = """damping = true
[effects.actuation]
type = "lqr"
equilibrium = "upright"
Q = [10.0, 100.0, 1.0, 10.0]
R = [0.1]
"""
PUSHED = (
    LQR
    + """[effects.disturbance]
type = "impulse"
time = 0.5
width = 0.02
impulse = [0.05]
"""
)

TINY = replace(
    SMALL,
    name="test scene",
    ensemble_size=8,
    ensemble_variants=("threads",),
    scene_horizon=1.0,  # s: the scene's state problem (its duration is 5 s)
    scene_long=20.0,  # s: its energy-only run
)


def write_scene(folder: Path, name: str, extra: str = "") -> Path:
    path = folder / f"{name}.toml"
    path.write_text(CART_POLE.replace("{extra}", extra))
    return path


@pytest.fixture(scope="module")
def bench(tmp_path_factory):
    """The CLI once on a conservative cart-pole scene, --quick with the tiny configuration."""
    folder = tmp_path_factory.mktemp("bench_scene")
    scene = write_scene(folder, "cart_pole_swing")
    status, results = run_quick(["--scene", str(scene), "-o", str(folder / "out")], TINY)
    return status, folder / "out", results


@pytest.mark.slow
def test_scene_run_writes_its_problems(bench):
    status, out, results = bench
    assert status == 0
    assert (out / "work_precision.png").read_bytes().startswith(b"\x89PNG")
    rows = list(csv.DictReader(io.StringIO((out / "work_precision.csv").read_text())))
    assert {r["problem"] for r in rows} == {"cart_pole_swing", "cart_pole_swing_long"}
    assert {p.key: (p.metric, p.duration) for p in results.problems} == {
        "cart_pole_swing": ("state", 1.0),  # min(the scene's 5 s, the configuration's horizon)
        "cart_pole_swing_long": ("energy", 20.0),
    }
    assert results.config.anchor == "cart_pole_swing"
    assert "cart_pole_swing" in (out / "work_precision.md").read_text()


@pytest.mark.slow
def test_every_method_family_has_points(bench):
    results = bench[2]
    for problem, methods in (
        ("cart_pole_swing", ["DOP853 (fast path)", *(f"{m} (scipy)" for m in TINY.scipy_methods)]),
        ("cart_pole_swing", list(TINY.fixed)),
        ("cart_pole_swing_long", ["DOP853 (fast path)", *TINY.long_fixed]),
    ):
        for method in methods:
            pts = [p for p in results.points if p.problem == problem and p.method == method and p.ok]
            assert pts, f"{problem=} {method=}: no point"
            assert all(p.plotted_error > 0 for p in pts), (problem, method)
    energy = [p for p in results.points if p.metric == "energy"]
    assert energy and all(p.plotted_error == p.energy_max for p in energy)
    assert not [p for p in energy if "scipy" in p.method]


@pytest.mark.slow
def test_references_bound_below_the_smallest_error(bench):
    results = bench[2]
    assert set(results.references) == {"cart_pole_swing"}
    assert results.smallest_error() / results.largest_reference_bound() >= REFERENCE_MARGIN


@pytest.mark.slow
def test_anchor_studies_run_on_the_scene(bench):
    results = bench[2]
    assert results.single is not None and results.single.problem == "cart_pole_swing"
    assert results.single.fast is not None and results.single.scipy is not None
    assert {r.problem for r in results.engines} == {"cart_pole_swing"}
    # continuous pole joint: aba through the coordinate map; no crba/minverse rows
    assert any(r.engine.startswith("aba (cos/sin") for r in results.engines)
    assert len(results.ensemble) == 2  # scipy on the checked members, the fast path on all cores
    for key, invariants, _ in results.invariants:
        assert key == "cart_pole_swing" and invariants and all(i.passed for i in invariants)


def test_a_time_varying_scene_is_refused_in_one_line(tmp_path, capsys):
    scene = write_scene(tmp_path, "pushed", PUSHED)
    status = main(["bench", "accuracy", "--scene", str(scene), "--quick", "-o", str(tmp_path / "out")])
    err = capsys.readouterr().err.strip()
    assert status == 2
    assert len(err.splitlines()) == 1, err
    assert str(scene) in err and "time-varying" in err, err
    assert not (tmp_path / "out").exists()


def test_the_aba_of_a_continuous_joint_matches_the_generated_field(tmp_path):
    """Forced (friction + LQR) cart-pole: the cos/sin aba and the compiled closed form agree."""
    config, specs = scene_problems(write_scene(tmp_path, "lqr", LQR), TINY)
    assert list(specs) == ["lqr"] and config.horizons == {"lqr": 1.0}  # not conservative: no energy run
    problem = build_problem(specs["lqr"], 1.0, 4)
    rhs = engine_rhs(problem, "aba")
    assert engine_rhs(problem, "minverse") is None
    for x in np.random.default_rng(3).uniform(-2, 2, (10, 4)):
        expected = problem.fast.rhs(x)
        err = np.max(np.abs(rhs.fun(0.0, x) - expected) / np.maximum(1.0, np.abs(expected)))
        assert err <= ENGINE_RTOL, (x, err)


def test_the_default_problems_are_unchanged():
    quick = workprecision.QUICK
    assert quick.horizons == {"mild": 5.0, "chaotic": 2.0, "cart_lqr": 3.0, "long": 200.0}
    assert workprecision.FULL.horizons == {"mild": 10.0, "chaotic": 2.0, "cart_lqr": 5.0, "long": 1000.0}
    assert (quick.anchor, quick.engine_problems) == ("chaotic", ("chaotic",))
    assert workprecision.FULL.engine_problems == ("chaotic", "cart_lqr")
    problems = workprecision.make_problems(quick)
    assert [(p.key, p.duration, p.metric) for p in problems] == [
        ("mild", 5.0, "state"),
        ("chaotic", 2.0, "state"),
        ("cart_lqr", 3.0, "state"),
        ("long", 200.0, "energy"),
    ]
    assert {k: s.metric for k, s in shipped_problems(quick.energy_only).items()} == {
        "mild": "state",
        "chaotic": "state",
        "cart_lqr": "state",
        "long": "energy",
    }
    mild, chaotic, cart, long = problems
    assert mild.x0.tolist() == long.x0.tolist() == [-math.pi / 2 + 0.5, 0.3, 0.0, 0.0]
    assert mild.scene.model == long.scene.model and mild.scene.params == long.scene.params
    assert mild.fast.packed().tolist() == long.fast.packed().tolist()  # the same field and force law
    assert chaotic.x0.tolist() == [2.0, 2.5, 0.0, 0.0] and chaotic.conservative
    assert cart.x0.tolist() == [0.0, 0.1, -0.05, 0.2, 0.0, 0.3]
    assert [p.title for p in problems] == [
        "double pendulum, mild swing",
        "double pendulum, chaotic",
        "cart double pendulum, LQR",
        "long conservative run (energy)",
    ]
    assert not cart.conservative  # friction and LQR on the cart
