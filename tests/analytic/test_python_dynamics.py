"""Dynamics given as Python code: ẋ = f(x, u), ẋ = f(t, x, u) or q̈ = qddot(q, v, u), with a declaration.

Gymnasium's cart-pole (``step``) and acrobot (``_dsdt``, the "book" variant) are written as model
files the way a user copies them out of the installed gymnasium source (the arithmetic as it stands
there, ``self.<constant>`` become keyword parameters, the constants' values read from the env
objects), and verified by aba against URDFs built from those constants
(``tests/analytic/gym_robots.py``); a planted error in each fails.  Both signatures f(x, u) and
f(t, x, u) work through a model file and through the API; a function whose ẋ does not start
with q̇, one that raises, one that returns the wrong size and a declaration that does not fit
the function are each refused in one line; ``show``, ``sympy`` and ``mutate`` refuse in one line.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import pendverify
from pendverify.api import load_model, load_scene, read_model, stress
from pendverify.cli import main
from pendverify.errors import PendverifyError
from tests.analytic.gym_robots import acrobot_urdf, cart_pole_urdf
from tests.error_message import one_error

gymnasium = pytest.importorskip("gymnasium")
from gymnasium.envs.classic_control.acrobot import AcrobotEnv  # noqa: E402
from gymnasium.envs.classic_control.cartpole import CartPoleEnv  # noqa: E402

SAMPLES = 60  # the zero state plus 60 random states and inputs

# cartpole.py, step(): the lines from `x, x_dot, theta, theta_dot = self.state` to `xacc`, with
# self.total_mass and self.polemass_length as the env defines them in __init__ and self.gravity
# named g (pendverify sets Pinocchio's gravity from a parameter g)
CART_POLE = """\
import numpy as np


def cart_pole(state, u, *, masscart, masspole, length, g):
    total_mass = masspole + masscart
    polemass_length = masspole * length
    x, x_dot, theta, theta_dot = state
    force = u[0]
    costheta = np.cos(theta)
    sintheta = np.sin(theta)
    temp = (force + polemass_length * np.square(theta_dot) * sintheta) / total_mass
    thetaacc = (g * sintheta - costheta * temp) / (
        length * (4.0 / 3.0 - masspole * np.square(costheta) / total_mass)
    )
    xacc = temp - polemass_length * thetaacc * costheta / total_mass
    return [x_dot, xacc, theta_dot, thetaacc]


DYNAMICS = cart_pole
DECLARATION = {
    "name": "gym_cart_pole",
    "dynamics": "f(x, u)",
    "coordinates": {"x": "position", "theta": "angle"},
    "state": ["x", "dx", "theta", "dtheta"],  # gymnasium's layout
    "inputs": ["force"],
    "B": [["1"], ["0"]],
    "parameters": {
        "masscart": {"kind": "mass"},
        "masspole": {"kind": "mass"},
        "length": {"kind": "offset"},
        "g": {"kind": "gravity"},
    },
    "urdf": {"joints": ["slider", "hinge"]},
}
"""

# acrobot.py, _dsdt() (book): s_augmented split into the state s and the torque a; g = 9.8 as there
ACROBOT = """\
from math import cos, pi, sin


def dsdt(t, s, u, *, m1, m2, l1, lc1, lc2, I1, I2, g):
    a = u[0]
    theta1 = s[0]
    theta2 = s[1]
    dtheta1 = s[2]
    dtheta2 = s[3]
    d1 = m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * cos(theta2)) + I1 + I2
    d2 = m2 * (lc2**2 + l1 * lc2 * cos(theta2)) + I2
    phi2 = m2 * lc2 * g * cos(theta1 + theta2 - pi / 2.0)
    phi1 = (
        -m2 * l1 * lc2 * dtheta2**2 * sin(theta2)
        - 2 * m2 * l1 * lc2 * dtheta2 * dtheta1 * sin(theta2)
        + (m1 * lc1 + m2 * l1) * g * cos(theta1 - pi / 2)
        + phi2
    )
    ddtheta2 = (
        a + d2 / d1 * phi1 - m2 * l1 * lc2 * dtheta1**2 * sin(theta2) - phi2
    ) / (m2 * lc2**2 + I2 - d2**2 / d1)
    ddtheta1 = -(d2 * ddtheta2 + phi1) / d1
    return dtheta1, dtheta2, ddtheta1, ddtheta2


DYNAMICS = dsdt
DECLARATION = {
    "name": "gym_acrobot",
    "dynamics": "f(t, x, u)",
    "coordinates": {"theta1": "angle", "theta2": "angle"},
    "inputs": ["a"],
    "B": [["0"], ["1"]],
    "parameters": {
        "m1": {"kind": "mass"}, "m2": {"kind": "mass"}, "l1": {"kind": "length"},
        "lc1": {"kind": "offset"}, "lc2": {"kind": "offset"},
        "I1": {"kind": "inertia"}, "I2": {"kind": "inertia"}, "g": {"kind": "gravity"},
    },
    "urdf": {"joints": ["joint1", "joint2"]},
}
"""


def cart_pole_values() -> dict[str, float]:
    env = CartPoleEnv()
    return dict(masscart=env.masscart, masspole=env.masspole, length=env.length, g=env.gravity)


def acrobot_values() -> dict[str, float]:
    env = AcrobotEnv()
    assert env.book_or_nips == "book"
    return dict(
        m1=env.LINK_MASS_1, m2=env.LINK_MASS_2, l1=env.LINK_LENGTH_1, lc1=env.LINK_COM_POS_1,
        lc2=env.LINK_COM_POS_2, I1=env.LINK_MOI, I2=env.LINK_MOI, g=9.8,  # _dsdt's own g = 9.8
    )  # fmt: skip


SYSTEMS = {
    "cart-pole": (CART_POLE, lambda: cart_pole_urdf(CartPoleEnv()), cart_pole_values),
    "acrobot": (ACROBOT, lambda: acrobot_urdf(AcrobotEnv()), acrobot_values),
}


def files(tmp_path: Path, system: str, old: str = "", new: str = "") -> tuple[Path, Path, dict]:
    """The model file (with ``old`` replaced by ``new``), its URDF and its parameter values."""
    source, urdf_text, values = SYSTEMS[system]
    assert old in source
    model = tmp_path / f"{system.replace('-', '_')}_dynamics.py"
    model.write_text(source.replace(old, new))
    urdf = tmp_path / f"{system}.urdf"
    urdf.write_text(urdf_text())
    return model, urdf, values()


def _notes(report) -> str:
    return " ".join(n for ns in report.notes.values() for n in ns)


@pytest.mark.parametrize("system", SYSTEMS)
def test_gymnasiums_code_verifies_by_aba_and_says_what_did_not_run(system, tmp_path):
    report = pendverify.check(*files(tmp_path, system), samples=SAMPLES)
    assert report.status == "pass", report
    assert report.checks == ("aba",)
    notes = _notes(report)
    for check in ("crba", "rnea", "gravity", "energy"):
        assert check in notes
    assert "its inputs do not span the coordinates" in notes
    assert "evaluated numerically only" in notes and "are the URDF's" in notes


@pytest.mark.parametrize(
    "system, old, new",
    [
        ("cart-pole", "4.0 / 3.0", "5.0 / 3.0"),  # the rod's 4/3 made 5/3
        ("cart-pole", "force = u[0]", "force = 2 * u[0]"),  # the force counted twice
        ("acrobot", "+ I1 + I2", "+ I1 + 2 * I2"),  # link 2's inertia doubled in d1
        # gymnasium's "nips" variant: ddθ2 without the term m2 l1 lc2 θ̇1² sin θ2
        ("acrobot", " - m2 * l1 * lc2 * dtheta1**2 * sin(theta2)", ""),
    ],
)
def test_a_planted_error_fails_aba(system, old, new, tmp_path):
    report = pendverify.check(*files(tmp_path, system, old, new), samples=SAMPLES, explain=False)
    assert report["aba"].status == "fail", report


def _acrobot_namespace(tmp_path) -> dict:
    model, _, _ = files(tmp_path, "acrobot")
    namespace: dict = {"__file__": str(model)}
    exec(compile(model.read_text(), str(model), "exec"), namespace)  # the test's own code
    return namespace


@pytest.mark.parametrize("signature", ["f(t, x, u)", "f(x, u)", "qddot(q, v, u)"])
def test_each_signature_works_through_the_api(signature, tmp_path):
    namespace = _acrobot_namespace(tmp_path)
    dsdt = namespace["dsdt"]
    wrapped = {
        "f(t, x, u)": dsdt,
        "f(x, u)": lambda x, u, **p: dsdt(0.0, x, u, **p),
        "qddot(q, v, u)": lambda q, v, u, **p: dsdt(0.0, [*q, *v], u, **p)[2:],
    }[signature]
    declaration = {**namespace["DECLARATION"], "dynamics": signature}
    urdf = tmp_path / "acrobot.urdf"
    report = pendverify.check(wrapped, urdf, acrobot_values(), samples=SAMPLES, declaration=declaration)
    assert report.status == "pass", report


def _refusal(tmp_path, system: str, old: str, new: str) -> str:
    model, urdf, values = files(tmp_path, system, old, new)
    with pytest.raises(PendverifyError) as info:
        pendverify.check(model, urdf, values, samples=SAMPLES)
    message = str(info.value)
    assert "\n" not in message, message
    return message


def test_a_rate_that_is_not_q_dot_is_refused_with_the_state(tmp_path):
    message = _refusal(tmp_path, "cart-pole", "return [x_dot, xacc,", "return [x_dot + 1e-3, xacc,")
    assert "cart_pole_dynamics.py: DYNAMICS cart_pole(x, u) returned ẋ whose entries" in message
    assert "not q̇ = [0.0, 0.0] (at q = [0.0, 0.0], u = [0.0])" in message


def test_a_function_that_raises_is_one_line_naming_the_file_line_and_exception(tmp_path):
    message = _refusal(tmp_path, "acrobot", "    a = u[0]\n", "    a = float(u[0]) / 0\n")
    assert "acrobot_dynamics.py, line 5: DYNAMICS dsdt(t, x, u) raised ZeroDivisionError" in message


def test_a_function_returning_the_wrong_size_is_refused(tmp_path):
    message = _refusal(tmp_path, "acrobot", "return dtheta1, dtheta2,", "return 0.0, dtheta1, dtheta2,")
    assert "DYNAMICS dsdt(t, x, u) must return 4 numbers; it returned an array of shape (5,)" in message


@pytest.mark.parametrize(
    "old, new, words",
    [
        ('"dynamics": "f(t, x, u)"', '"dynamics": "f(x, u)"', "dsdt cannot be called as f(x, u, m1=…"),
        (", I1, I2, g):", ", I1, I2):", "dsdt cannot be called as f(t, x, u, m1=…"),
        ('"dynamics": "f(t, x, u)"', '"dynamics": "f(x)"', "key 'dynamics': 'f(x)': must be one of"),
        ('"inputs": ["a"],', '"inputs": ["a"], "state": ["theta1"],', "key 'state': must list x's entries"),
        ('"B": [["0"], ["1"]],', "", "key 'B': missing: the model declares inputs a"),
        ('"B": [["0"], ["1"]]', '"B": [["0"], ["theta1"]]', "key 'B[1,0]': unknown name 'theta1'"),
        ("DECLARATION = {", "DECLARED = {", "defines DYNAMICS but no DECLARATION"),
        ('"g": {"kind": "gravity"}', '"G": {"kind": "gravity"}', "key 'parameters.G': name the gravity g"),
    ],
)
def test_a_declaration_that_does_not_fit_is_refused_in_one_line(old, new, words, tmp_path):
    model, _, _ = files(tmp_path, "acrobot", old, new)
    with pytest.raises(PendverifyError) as info:
        load_model(model)
    headline, _, _ = one_error(str(info.value))  # an expression's error carries its caret
    assert words in headline, str(info.value)


def test_a_function_without_a_declaration_is_refused():
    def f(x, u):
        return x

    with pytest.raises(PendverifyError, match=r"a function \(f\) needs a declaration"):
        load_model(f)


def test_show_sympy_and_mutate_refuse_in_one_line(tmp_path, capsys):
    model, urdf, values = files(tmp_path, "cart-pole")
    with pytest.raises(PendverifyError, match=r"its q̈ is Python code .*evaluated numerically only"):
        read_model(model)
    params = tmp_path / "params.toml"
    lines = "".join(f"{k} = {v}\n" for k, v in values.items())
    params.write_text(f'model = "gym_cart_pole"\n[parameters]\n{lines}')
    for argv in (
        ["show", str(model)],
        ["sympy", "--analytic", str(model)],
        ["mutate", "--analytic", str(model), "--urdf", str(urdf), "--params", str(params)],
    ):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err.strip()
        assert "\n" not in err and "evaluated numerically only" in err, (argv, err)


def test_the_function_is_evaluated_with_the_parameters_by_keyword(tmp_path):
    """The values reach the function: a different pole mass changes q̈ as gymnasium's would."""
    model, _, values = files(tmp_path, "cart-pole")
    cls = load_model(model)
    env = CartPoleEnv()
    env.reset(seed=0)
    env.state = np.array([0.1, -0.2, 0.3, 0.4])
    x, x_dot, theta, theta_dot = env.state
    env.step(1)  # euler: x_dot' = x_dot + tau * xacc, theta_dot' = theta_dot + tau * thetaacc
    expected = (np.array([env.state[1], env.state[3]]) - [x_dot, theta_dot]) / env.tau
    got = cls(cls.params_type(**values)).acceleration(
        np.array([x, theta]), np.array([x_dot, theta_dot]), np.array([env.force_mag]), np.zeros(0)
    )
    # both are gymnasium's arithmetic; the env's difference of float64 states of size ~1 over
    # tau = 0.02 loses about 50 ε of the rates' size, so 1e-12 of the accelerations' size is ample
    assert np.allclose(got, expected, rtol=1e-12, atol=1e-12 * np.max(np.abs(expected))), (got, expected)


def _params_file(tmp_path: Path, values: dict) -> Path:
    params = tmp_path / "params.toml"
    lines = "".join(f"{k} = {v}\n" for k, v in values.items())
    params.write_text(f'model = "gym_cart_pole"\n[parameters]\n{lines}')
    return params


def test_stress_runs_without_the_near_singular_case_and_says_why(tmp_path):
    model, urdf, values = files(tmp_path, "cart-pole")
    report = stress(model, urdf, _params_file(tmp_path, values), quick=True)
    names = [r.name for r in report.results]
    assert "nominal" in names and not any("near-singular" in n for n in names), names
    assert "no near-singular case: GymCartPole gives q̈ alone, no M" in " ".join(report.notes)
    assert next(r for r in report.results if r.name == "nominal").passed


def test_simulate_refuses_a_model_without_M_in_one_line(tmp_path):
    model, urdf, values = files(tmp_path, "cart-pole")
    scene = {
        "name": "cart-pole",
        "model": str(model),
        "params": str(_params_file(tmp_path, values)),
        "urdf": str(urdf),
        "initial": {"q": [0.0, 0.1]},
        "time": {"duration": 1.0, "sample_rate": 50.0},
        "integrator": {"method": "DOP853", "rtol": 1e-10, "atol": 1e-10},
    }
    with pytest.raises(PendverifyError) as info:
        load_scene(scene)
    message = str(info.value)
    assert "\n" not in message and "GymCartPole gives q̈ alone (no M, H, V)" in message, message
