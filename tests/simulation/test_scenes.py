"""Scenes: effects switch terms on and off, invariants hold and can fail, errors are literal."""

from __future__ import annotations

import copy
import json
import re
from pathlib import Path

import numpy as np
import pytest

from pendverify.analytic import MODELS, CartDoublePendulum, DoublePendulum
from pendverify.analytic.plugin import load_model_class
from pendverify.cli import main
from pendverify.errors import IntegrationError, SceneError
from pendverify.simulation.dynamics import build_dynamics
from pendverify.simulation.scene import load_scene, parse_scene
from pendverify.simulation.simulate import run_scene
from tests.cli_run import Done, run_main

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"
SHIPPED = sorted((REPO / "scenes").glob("*.toml"))


def dp_scene(**effects) -> dict:
    return {
        "name": "test",
        "model": "double_pendulum",
        "initial": {"q": [0.4, 0.9], "v": [0.5, -0.3]},
        "time": {"duration": 1.0, "sample_rate": 50.0},
        "integrator": {"method": "DOP853", "rtol": 1e-10, "atol": 1e-10},
        "effects": effects,
    }


def cart_scene(**effects) -> dict:
    return {
        "name": "test",
        "model": "cart_double_pendulum",
        "initial": {"q": [0.0, 0.1, -0.05], "v": [0.2, 0.0, 0.3]},
        "time": {"duration": 1.0, "sample_rate": 50.0},
        "integrator": {"method": "DOP853", "rtol": 1e-10, "atol": 1e-10},
        "effects": effects,
    }


def run(doc, engine=None):
    return run_scene(parse_scene(doc, "<test>"), engine)


# --- shipped scenes -----------------------------------------------------------------------
@pytest.mark.parametrize("path", SHIPPED, ids=[p.stem for p in SHIPPED])
def test_shipped_scene_passes_its_invariants(path):
    result = run_scene(load_scene(path))
    assert result.passed, [(i.name, i.error, i.tolerance) for i in result.invariants]
    assert np.all(np.isfinite(result.q))


@pytest.mark.parametrize(
    ("scene", "rods", "pushed_by", "engines"),
    [("cart_lqr_push", slice(1, None), 0.02, None), ("cart_pole_lqr_push", slice(1, 2), 0.01, "both")],
    ids=["built-in", "plug-in"],
)
def test_lqr_brings_the_rods_back_upright(scene, rods, pushed_by, engines):
    """The cart's two rods (built-in model) and the cart-pole's pole (a model file), pushed."""
    result = run_scene(load_scene(REPO / "scenes" / f"{scene}.toml"))
    assert result.passed
    pushed = np.max(np.abs(result.q[:, rods]))
    assert pushed > pushed_by, "the push did not move the rods"
    final = np.concatenate([result.q[-1], result.v[-1]])
    assert np.linalg.norm(final) < 1e-2, f"not back near upright: |x(T)| = {np.linalg.norm(final):.3g}"
    (note,) = result.notes
    assert "linearisation differ by" in note
    assert float(note.split("differ by ")[1].split()[0]) < 1e-12
    if engines == "both":  # the hand model's q̈ compared with ABA's along the run
        assert result.engine_comparison.passed
    else:
        assert result.engine_comparison is None


# --- effects: off means not evaluated, on means it matters ---------------------------------
def test_damping_off_evaluates_no_friction(monkeypatch):
    def forbidden(self):
        raise AssertionError("friction evaluated although damping is off")

    doc = dp_scene(gravity=True)
    scene = parse_scene(doc, "<test>")  # parsing may read the set's damping; simulating may not
    monkeypatch.setattr(DoublePendulum, "damping_matrix", forbidden)
    result = run_scene(scene)
    assert not any("friction" in t for t in result.dynamics.terms)
    assert result.invariants[0].name.startswith("energy drift")


def test_no_input_means_no_input_path(monkeypatch):
    def forbidden(self):
        raise AssertionError("input path evaluated")

    monkeypatch.setattr(CartDoublePendulum, "input_matrix", forbidden)
    monkeypatch.setattr(CartDoublePendulum, "disturbance_matrix", forbidden)
    result = run(cart_scene(gravity=True, damping=True))
    assert not any(t.startswith(("actuation", "disturbance")) for t in result.dynamics.terms)
    assert np.all(result.u == 0) and np.all(result.w == 0)


def test_gravity_off_means_zero_gravity_vector():
    dyn = build_dynamics(parse_scene(dp_scene(), "<test>"), "aba")
    q = np.array([0.3, -1.1])
    assert np.all(dyn.model.gravity(q) == 0.0)
    assert np.all(dyn.system.gravity(q) == 0.0)
    assert "gravity: off (H = 0)" in dyn.terms


@pytest.mark.parametrize(
    ("base", "effect"),
    [
        (dp_scene(), {"gravity": True}),
        (dp_scene(gravity=True), {"damping": True}),
        (dp_scene(gravity=True), {"actuation": {"type": "constant", "value": [0.5, -0.2]}}),
        (cart_scene(gravity=True), {"disturbance": {"type": "step", "time": 0.2, "value": [1.0, 0.0, 0.0]}}),
    ],
    ids=["gravity", "damping", "actuation", "disturbance"],
)
def test_each_effect_changes_the_trajectory(base, effect):
    with_effect = copy.deepcopy(base)
    with_effect["effects"].update(effect)
    a, b = run(base), run(with_effect)
    assert a.passed and b.passed
    assert np.max(np.abs(a.q[-1] - b.q[-1])) > 1e-3


@pytest.mark.parametrize(
    "actuation",
    [
        {"type": "step", "time": 0.3, "after": [1.0, 0.0]},
        {"type": "table", "times": [0.0, 0.5, 1.0], "values": [[0.0, 0.0], [1.0, -1.0], [0.0, 0.5]]},
        {"type": "pd", "kp": [20.0, 10.0], "kd": [2.0, 1.0], "target": [1.0, 0.0]},
        {"type": "sine", "amplitude": [1.0, 0.5], "frequency": 2.0},
    ],
    ids=lambda a: a["type"],
)
def test_actuation_laws_keep_the_work_balance(actuation):
    result = run(dp_scene(gravity=True, damping=True, actuation=actuation), engine="both")
    assert result.passed, [(i.name, i.error, i.tolerance) for i in result.invariants]
    assert result.invariants[0].name.startswith("work–energy balance")
    assert np.any(result.u != 0)


# --- every model, built-in or a model file -----------------------------------------------------
INITIAL_Q = {
    "double_pendulum": [0.4, 0.9],
    "cart_double_pendulum": [0.0, 0.1, -0.05],
    "cart_pole": [0.0, 0.3],
    "hanging_double_pendulum": [0.8, -0.4],
    "triple_pendulum": [1.0, 0.4, -0.3],
    "furuta_pendulum": [0.2, 0.3],
}


def _model_class(name: str):
    return MODELS[name] if name in MODELS else load_model_class(EXAMPLES / f"{name}.py")


@pytest.mark.parametrize("name", list(INITIAL_Q))
def test_each_model_simulates_with_both_engines(tmp_path, name):
    """A built-in model by name; a plug-in example by its model file, parameters and URDF."""
    q0 = INITIAL_Q[name]
    if name in MODELS:
        model_file, files = None, f'model = "{name}"\n'
    else:
        model_file = str(EXAMPLES / f"{name}.py")
        files = (
            f'model = "{model_file}"\nparams = "{EXAMPLES / f"{name}.toml"}"\n'
            f'urdf = "{EXAMPLES / f"{name}.urdf"}"\n'
        )
    amplitude = [0.3] * len(_model_class(name).inputs)
    path = tmp_path / "scene.toml"
    path.write_text(
        f'{files}engine = "both"\n[initial]\nq = {q0}\n[time]\nduration = 1.0\nsample_rate = 50.0\n'
        '[integrator]\nmethod = "DOP853"\nrtol = 1e-10\natol = 1e-10\n'
        "[effects]\ngravity = true\ndamping = true\n"
        f'[effects.actuation]\ntype = "sine"\namplitude = {amplitude}\nfrequency = 1.0\n'
    )
    result = run_scene(load_scene(path))
    assert result.scene.model == name and result.scene.model_file == model_file
    assert result.passed, [(c.name, c.error, c.tolerance) for c in result.invariants]
    assert result.invariants[0].name.startswith("work–energy balance")
    assert result.engine_comparison is not None and result.engine_comparison.passed
    assert result.q.shape == (51, len(q0)) and np.any(result.u != 0)


def test_noise_disturbance_is_seeded_and_balanced():
    noise = {"type": "noise", "std": [1.0, 0.1, 0.1], "bandwidth": 5.0, "seed": 7}
    a = run(cart_scene(gravity=True, disturbance=noise))
    b = run(cart_scene(gravity=True, disturbance=noise))
    assert a.passed
    np.testing.assert_array_equal(a.w, b.w)
    assert 0.3 < np.std(a.w[:, 0]) < 3.0


def test_rk4_uses_richardson_bound_and_passes():
    doc = dp_scene(gravity=True)
    doc["integrator"] = {"method": "rk4", "step": 0.002}
    assert run(doc).passed


# --- the invariants can fail -----------------------------------------------------------------
class WrongEnergy(DoublePendulum):
    """Potential energy off by 1e-6 relative: the drift check must see it."""

    def potential_energy(self, q):
        return super().potential_energy(q) * (1 + 1e-6)


class CoriolisSignFlip(DoublePendulum):
    """One Coriolis term with the wrong sign: the closed-form dynamics no longer conserve energy."""

    def coriolis_matrix(self, q, v):
        C = super().coriolis_matrix(q, v)
        C[1, 0] = -C[1, 0]
        return C


def test_energy_drift_detects_a_wrong_energy(monkeypatch):
    from pendverify.simulation import dynamics

    monkeypatch.setitem(dynamics.MODELS, "double_pendulum", WrongEnergy)
    result = run(dp_scene(gravity=True), engine="closed_form")
    assert not result.passed
    assert result.invariants[0].error > result.invariants[0].tolerance


def test_work_balance_detects_a_wrong_closed_form(monkeypatch):
    from pendverify.simulation import dynamics

    monkeypatch.setitem(dynamics.MODELS, "double_pendulum", CoriolisSignFlip)
    doc = dp_scene(
        gravity=True, damping=True, actuation={"type": "sine", "amplitude": [1.0, 0.5], "frequency": 1.0}
    )
    result = run(doc, engine="closed_form")
    (balance,) = result.invariants
    assert balance.name.startswith("work–energy balance")
    assert not balance.passed


def test_engine_comparison_detects_a_wrong_closed_form(monkeypatch):
    from pendverify.simulation import dynamics

    class BetaOff(DoublePendulum):
        @property
        def beta(self):
            return super().beta * (1 + 1e-6)

    monkeypatch.setitem(dynamics.MODELS, "double_pendulum", BetaOff)
    result = run(dp_scene(gravity=True), engine="both")
    assert not result.engine_comparison.passed


# --- output ---------------------------------------------------------------------------------
def test_npz_and_csv_are_written(tmp_path, capsys):
    out = tmp_path / "run.npz"
    assert (
        main(["simulate", str(REPO / "scenes" / "damped_double_pendulum.toml"), "-o", str(out), "--csv"]) == 0
    )
    text = capsys.readouterr().out
    assert "dissipation balance" in text and "friction −D·q̇" in text and "all invariants hold" in text
    data = np.load(out)
    assert {"t", "q", "v", "u", "w", "energy", "metadata"} <= set(data.files)
    meta = json.loads(str(data["metadata"]))
    assert meta["model"] == "double_pendulum" and meta["passed"] is True
    assert {"pendverify", "pinocchio", "numpy", "python"} <= set(meta["versions"])
    assert data["q"].shape == (1001, 2)
    assert (
        out.with_suffix(".csv").read_text().startswith("t,theta1,theta2,dtheta1,dtheta2,u_tau1,u_tau2,energy")
    )


def test_failed_run_leaves_no_file(tmp_path, monkeypatch):
    from pendverify.simulation import simulate as sim_module

    def boom(*args, **kwargs):
        raise RuntimeError("integrator died")

    monkeypatch.setattr(sim_module, "integrate", boom)
    out = tmp_path / "run.npz"
    # an unexpected exception is an internal error: exit status 3, and no output file
    assert main(["simulate", str(REPO / "scenes" / "damped_double_pendulum.toml"), "-o", str(out)]) == 3
    assert list(tmp_path.iterdir()) == []


# --- bad input: literal messages ---------------------------------------------------------------
def _write(tmp_path, text: str) -> str:
    path = tmp_path / "scene.toml"
    path.write_text(text)
    return str(path)


GOOD = """
model = "double_pendulum"
[initial]
q = [0.1, 0.2]
[time]
duration = 1.0
[integrator]
method = "RK45"
"""


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            ("model =", "colour = 1\nmodel ="),
            "key 'colour' = 1: unknown key; expected one of name, model, params, parameters, urdf, engine, "
            "initial, time, integrator, effects",
        ),
        (("duration = 1.0", "duration = 0.0"), "key 'time.duration' = 0.0: expected a number > 0"),
        (("duration = 1.0", "duration = -2"), "key 'time.duration' = -2: expected a number > 0"),
        (("duration = 1.0", 'duration = "long"'), "key 'time.duration' = 'long': expected a number"),
        (("duration = 1.0", "duration = nan"), "key 'time.duration' = nan: expected a finite number"),
        (
            ("q = [0.1, 0.2]", "q = [0.1, 0.2, 0.3]"),
            "key 'initial.q' = [0.1, 0.2, 0.3]: expected a list of 2 numbers, got 3",
        ),
        (("q = [0.1, 0.2]", "q = [0.1, inf]"), "key 'initial.q' = [0.1, inf]: expected finite numbers"),
        (
            ('"double_pendulum"', '"triple_pendulum"'),
            "key 'model' = 'triple_pendulum': expected one of double_pendulum, cart_double_pendulum",
        ),
        (
            ('"RK45"', '"Euler"'),
            "key 'integrator.method' = 'Euler': expected one of RK45, RK23, DOP853, Radau, BDF, LSODA, rk4",
        ),
        (('method = "RK45"', 'method = "rk4"'), "key 'integrator.step' = None: missing key"),
        (
            (GOOD, GOOD + "[effects]\nwind = true\n"),
            "key 'effects.wind' = True: unknown key; "
            "expected one of gravity, damping, actuation, disturbance",
        ),
        (
            (GOOD, GOOD + "[effects]\ngravity = -9.81\n"),
            "key 'effects.gravity' = -9.81: expected a number >= 0",
        ),
        (
            (GOOD, GOOD + '[effects.actuation]\ntype = "laser"\n'),
            "key 'effects.actuation.type' = 'laser': expected one of constant, step, sine, table, lqr, pd",
        ),
        (
            (GOOD, GOOD + '[effects.disturbance]\ntype = "impulse"\n'),
            "key 'effects.disturbance.type' = 'impulse': the double_pendulum model has no disturbance input",
        ),
        (
            (
                GOOD,
                GOOD + '[effects]\ngravity = true\n[effects.actuation]\ntype = "lqr"\nequilibrium = "zero"\n',
            ),
            "key 'effects.actuation.equilibrium' = 'zero': not an equilibrium of double_pendulum: "
            "H(q*) = [8.1, 1.73] (on theta1: 8.1 > 2.9e-14, the rounding allowance)",
        ),
    ],
)
def test_bad_scenes_get_literal_errors(tmp_path, edit, message):
    old, new = edit
    path = _write(tmp_path, GOOD.replace(old, new, 1))
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert str(info.value) == f"{path}: {message}"


def test_bad_scene_is_exit_2_with_one_line(tmp_path, capsys):
    path = _write(tmp_path, GOOD.replace("duration = 1.0", "duration = 0"))
    assert main(["simulate", path]) == 2
    assert (
        capsys.readouterr().err
        == f"pendverify: error: {path}: key 'time.duration' = 0: expected a number > 0\n"
    )


# --- bounded work: an adaptive run stops at integrator.max_steps ---------------------------------
FAST_GRAVITY = GOOD + "[effects]\ngravity = 1_000_000_000\n"


def _run_cli(*args: str) -> Done:
    """The command in-process under a hard bound on its CPU time (a run that does not stop fails)."""
    return run_main(list(args))


def test_an_adaptive_run_that_needs_too_many_steps_stops_naming_the_key_and_limit(tmp_path):
    path = _write(tmp_path, FAST_GRAVITY.replace('method = "RK45"', 'method = "RK45"\nmax_steps = 2000'))
    result = _run_cli("simulate", path, "-o", str(tmp_path / "run.npz"))
    err = result.stderr.strip()
    assert result.returncode == 2, err
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert path in err and "key 'integrator.max_steps'" in err and "more than 2000 steps" in err
    assert not (tmp_path / "run.npz").exists()


def test_report_stops_at_the_step_limit_too(tmp_path):
    scenes = tmp_path / "scenes"
    scenes.mkdir()
    (scenes / "fast.toml").write_text(
        FAST_GRAVITY.replace('method = "RK45"', 'method = "RK45"\nmax_steps = 500')
    )
    result = _run_cli(
        "report", "-o", str(tmp_path / "out"), "--scenes", str(scenes), "--no-erd", "--samples", "5"
    )
    err = result.stderr.strip()
    assert result.returncode == 2, err[-2000:]
    assert "key 'integrator.max_steps'" in err and "Traceback" not in err


def test_the_default_step_limit_is_stated_and_a_raised_one_is_used():
    from pendverify.simulation.limits import DEFAULT_MAX_STEPS

    assert (
        load_scene(REPO / "scenes" / "damped_double_pendulum.toml").integrator.max_steps == DEFAULT_MAX_STEPS
    )
    scene = parse_scene(
        dp_scene(gravity=True) | {"integrator": {"method": "DOP853", "max_steps": 5}}, "x.toml"
    )
    with pytest.raises(IntegrationError, match=r"key 'integrator.max_steps'.*more than 5 steps"):
        run_scene(scene)
    enough = parse_scene(
        dp_scene(gravity=True) | {"integrator": {"method": "DOP853", "max_steps": 5000}}, "x.toml"
    )
    assert all(r.passed for r in run_scene(enough).invariants)


@pytest.mark.parametrize(
    ("integrator", "message"),
    [
        ({"method": "RK45", "max_steps": 0}, "key 'integrator.max_steps' = 0: expected a number >= 1"),
        ({"method": "RK45", "max_steps": 2.5}, "key 'integrator.max_steps' = 2.5: expected a whole number"),
        ({"method": "rk4", "step": 0.01, "max_steps": 10}, "rk4 has a fixed step: give step, not max_steps"),
        ({"method": "RK45", "rtol": 1e-300}, "key 'integrator.rtol' = 1e-300: expected rtol >= 2.22e-14"),
    ],
)
def test_a_bad_step_limit_or_tolerance_is_refused(integrator, message):
    with pytest.raises(SceneError, match=re.escape(message)):
        parse_scene(dp_scene() | {"integrator": integrator}, "x.toml")
