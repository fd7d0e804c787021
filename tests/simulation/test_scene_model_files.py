"""Scenes on a user's own model: a model file (``model = "PATH.py"``), its parameters and URDF.

A model written here simulates; PD through B⁻¹ and LQR run on a model file's own matrices;
a planted Coriolis error in a plug-in breaks the work balance; the shipped plug-in scenes do
what they show; ``simulate --urdf`` gives the URDF; every error of a model file's scene is
literal.  Every model, built-in or plug-in, simulating with both engines: ``test_scenes.py``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pendverify.cli import main
from pendverify.errors import SceneError
from pendverify.simulation.scene import load_scene
from pendverify.simulation.simulate import run_scene

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"


def _scene(tmp_path: Path, model: str, body: str, name: str = "scene.toml") -> Path:
    """A scene in tmp_path naming a model file by an absolute path (the rule is: relative to the scene)."""
    path = tmp_path / name
    path.write_text(f'model = "{model}"\n{body}')
    return path


def _example(stem: str, q: list[float], engine: str = "both", effects: str = "") -> str:
    return f'''params = "{EXAMPLES / f"{stem}.toml"}"
urdf = "{EXAMPLES / f"{stem}.urdf"}"
engine = "{engine}"
[initial]
q = {q}
[time]
duration = 1.0
sample_rate = 50.0
[integrator]
method = "DOP853"
rtol = 1e-10
atol = 1e-10
[effects]
gravity = true
damping = true
{effects}'''


# --- models written here ----------------------------------------------------------------------
SUBCLASS = """
from pendverify.analytic.plugin import load_model_class

Base = load_model_class({base!r})


class Mine(Base):
{body}
"""


def _model_file(tmp_path: Path, base: Path, body: str, name: str = "mine.py") -> Path:
    path = tmp_path / name
    path.write_text(SUBCLASS.format(base=str(base), body=body))
    return path


def test_a_model_written_here_simulates(tmp_path):
    # the seed, subclassed in a model file of its own: closed form, and ABA on a URDF written here
    from pendverify.analytic import DoublePendulum  # noqa: F401  (the file imports it too)
    from pendverify.analytic.params import default_parameter_file, load_parameter_file
    from pendverify.robot.writer import urdf_for

    model = tmp_path / "my_pendulum.py"
    model.write_text(
        "from pendverify.analytic import DoublePendulum\n\n\n"
        "class MyPendulum(DoublePendulum):\n    '''The seed, as a user's own file.'''\n"
    )
    params = default_parameter_file("double_pendulum")
    (tmp_path / "dp.urdf").write_text(urdf_for(load_parameter_file(params)[2]))
    body = f'''params = "{params}"
urdf = "dp.urdf"
engine = "both"
[initial]
q = [0.4, 0.9]
[time]
duration = 1.0
[integrator]
method = "DOP853"
rtol = 1e-10
atol = 1e-10
[effects]
gravity = true
[effects.actuation]
type = "pd"
kp = [5.0, 2.0]
kd = [0.5, 0.2]
'''
    result = run_scene(load_scene(_scene(tmp_path, "my_pendulum.py", body)))
    assert result.scene.model_cls.__name__ == "MyPendulum"
    assert result.passed and result.engine_comparison.passed


def test_pd_through_b_inverse_on_the_triple_pendulum(tmp_path):
    effects = '[effects.actuation]\ntype = "pd"\nkp = [4.0, 3.0, 2.0]\nkd = [0.4, 0.3, 0.2]\n'
    path = _scene(
        tmp_path,
        str(EXAMPLES / "triple_pendulum.py"),
        _example("triple_pendulum", [0.5, 0.2, 0.1], effects=effects),
    )
    result = run_scene(load_scene(path))
    assert result.passed
    law, model = result.scene.actuation, result.dynamics.model
    q, v = result.q[10], result.v[10]
    np.testing.assert_allclose(model.input_matrix() @ law(0.0, q, v), law.kp * -q - law.kd * v, rtol=1e-12)


def test_lqr_keeps_the_triple_pendulum_inverted(tmp_path):
    effects = (
        '[effects.actuation]\ntype = "lqr"\nequilibrium = "inverted"\n'
        "Q = [100.0, 100.0, 100.0, 1.0, 1.0, 1.0]\nR = [1.0, 1.0, 1.0]\n"
    )
    pi = np.pi
    path = _scene(
        tmp_path,
        str(EXAMPLES / "triple_pendulum.py"),
        _example("triple_pendulum", [pi + 0.05, pi - 0.03, pi + 0.02], effects=effects),
    )
    result = run_scene(load_scene(path))
    assert result.passed
    assert np.max(np.abs(result.q[-1] - pi)) < 0.05
    assert float(result.notes[0].split("differ by ")[1].split()[0]) < 1e-12


def test_planted_coriolis_error_in_a_plugin_breaks_the_work_balance(tmp_path):
    flipped = _model_file(
        tmp_path,
        EXAMPLES / "cart_pole.py",
        "    def coriolis_matrix(self, q, v):\n"
        "        C = super().coriolis_matrix(q, v)\n"
        "        C[0, 1] = -C[0, 1]\n"
        "        return C\n",
    )
    actuation = '[effects.actuation]\ntype = "sine"\namplitude = [2.0]\nfrequency = 1.0\n'
    good = run_scene(
        load_scene(
            _scene(
                tmp_path,
                str(EXAMPLES / "cart_pole.py"),
                _example("cart_pole", [0.0, 0.6], "closed_form", actuation),
                "good.toml",
            )
        )
    )
    bad = run_scene(
        load_scene(
            _scene(
                tmp_path,
                str(flipped),
                _example("cart_pole", [0.0, 0.6], "closed_form", actuation),
                "bad.toml",
            )
        )
    )
    assert good.passed
    (balance,) = bad.invariants
    assert balance.name.startswith("work–energy balance") and not balance.passed


def test_shipped_plugin_scenes_pass():
    """(The cart-pole LQR scene: ``test_scenes.py``, with the built-in cart's.)"""
    damped = run_scene(load_scene(REPO / "scenes" / "damped_triple_pendulum.toml"))
    assert damped.passed and damped.engine_comparison.passed
    assert damped.energy[-1] < damped.energy[0]
    furuta = run_scene(load_scene(REPO / "scenes" / "furuta_arm_turning.toml"))  # not planar
    assert furuta.passed and furuta.engine_comparison.passed
    assert np.ptp(furuta.q[:, 0]) > 0.1 and np.ptp(furuta.q[:, 1]) > 1.0, "arm turned, pendulum fell"


def test_simulate_urdf_option_replaces_the_scenes(tmp_path, capsys):
    body = _example("cart_pole", [0.0, 0.3]).replace(f'urdf = "{EXAMPLES / "cart_pole.urdf"}"\n', "")
    path = _scene(tmp_path, str(EXAMPLES / "cart_pole.py"), body)
    assert main(["simulate", str(path), "--urdf", str(EXAMPLES / "cart_pole.urdf")]) == 0
    assert "all invariants hold" in capsys.readouterr().out


# --- literal errors ---------------------------------------------------------------------------
def _error(path: Path, engine_run: bool = False) -> str:
    with pytest.raises(SceneError) as info:
        scene = load_scene(path)
        if engine_run:
            run_scene(scene)
    return str(info.value)


def test_errors_of_the_model_key(tmp_path):
    path = _scene(tmp_path, "nope.py", "")
    assert (
        _error(path)
        == f"{path}: key 'model' = 'nope.py': model file not found (looked for {tmp_path / 'nope.py'})"
    )
    (tmp_path / "empty.py").write_text("x = 1\n")
    path = _scene(tmp_path, "empty.py", "")
    assert _error(path) == (
        f"{path}: key 'model' = 'empty.py': not a usable model file: {tmp_path / 'empty.py'}: defines "
        "no subclass of pendverify.ClosedFormModel, no functions M, C, G, no METHOD and no DYNAMICS "
        "(examples/cart_pole.py is a complete model file; docs/models.md shows each form)"
    )


def test_errors_of_params_and_urdf(tmp_path):
    model = str(EXAMPLES / "cart_pole.py")
    body = _example("cart_pole", [0.0, 0.1])
    no_params = body.replace(f'params = "{EXAMPLES / "cart_pole.toml"}"\n', "")
    path = _scene(tmp_path, model, no_params)
    assert _error(path) == (
        f"{path}: key 'params' = None: a model file has no default parameter set: "
        "give params = FILE or [parameters]"
    )
    path = _scene(tmp_path, model, no_params.replace("engine =", 'params = "default"\nengine ='))
    assert _error(path) == (
        f"{path}: key 'params' = 'default': a model file has no default parameter set: "
        "give params = FILE or [parameters]"
    )
    path = _scene(tmp_path, model, body.replace(f'"{EXAMPLES / "cart_pole.urdf"}"', '"gone.urdf"'))
    assert _error(path) == (
        f"{path}: key 'urdf' = 'gone.urdf': URDF file not found (looked for {tmp_path / 'gone.urdf'})"
    )
    path = _scene(tmp_path, model, body.replace(f'urdf = "{EXAMPLES / "cart_pole.urdf"}"\n', ""))
    assert _error(path, engine_run=True) == (
        f"{path}: key 'urdf' = None: missing key: engine both integrates ABA on a URDF, and the model "
        f"file {model} has none the project can write (give urdf = FILE or --urdf)"
    )
    lqr = '[effects.actuation]\ntype = "lqr"\nQ = [1.0, 1.0, 1.0, 1.0]\nR = [1.0]\n'
    body = _example("cart_pole", [0.0, 0.1], "closed_form", lqr).replace(
        f'urdf = "{EXAMPLES / "cart_pole.urdf"}"\n', ""
    )
    path = _scene(tmp_path, model, body)
    assert _error(path, engine_run=True) == (
        f"{path}: key 'urdf' = None: missing key: the lqr actuation linearises with Pinocchio on a URDF, "
        f"and the model file {model} has none the project can write (give urdf = FILE or --urdf)"
    )


def test_errors_of_the_effects(tmp_path):
    triple = str(EXAMPLES / "triple_pendulum.py")
    lqr = '[effects.actuation]\ntype = "lqr"\nQ = [1.0, 1.0, 1.0, 1.0, 1.0, 1.0]\nR = [1.0, 1.0, 1.0]\n'
    path = _scene(tmp_path, triple, _example("triple_pendulum", [0.1, 0.0, 0.0], effects=lqr))
    assert _error(path) == (
        f"{path}: key 'effects.actuation.equilibrium' = None: missing key: triple_pendulum has no special "
        "state 'upright'; name one of hanging, inverted, folded, horizontal, zigzag"
    )
    path = _scene(
        tmp_path, triple, _example("triple_pendulum", [0.1, 0.0, 0.0], effects=lqr + 'equilibrium = "up"\n')
    )
    assert _error(path) == (
        f"{path}: key 'effects.actuation.equilibrium' = 'up': expected a special state of triple_pendulum: "
        "one of hanging, inverted, folded, horizontal, zigzag"
    )
    pd = '[effects.actuation]\ntype = "pd"\nkp = [1.0, 1.0]\nkd = [0.1, 0.1]\n'
    path = _scene(tmp_path, str(EXAMPLES / "cart_pole.py"), _example("cart_pole", [0.0, 0.1], effects=pd))
    assert _error(path) == (
        f"{path}: key 'effects.actuation.type' = 'pd': PD acts through B⁻¹, and B of cart_pole is 2×1, "
        "not square (1 input for 2 coordinates); use lqr or an open-loop type"
    )
    singular = _model_file(
        tmp_path,
        EXAMPLES / "triple_pendulum.py",
        "    def input_matrix(self):\n        import numpy as np\n\n        return np.ones((3, 3))\n",
    )
    pd3 = '[effects.actuation]\ntype = "pd"\nkp = [1.0, 1.0, 1.0]\nkd = [0.1, 0.1, 0.1]\n'
    path = _scene(tmp_path, str(singular), _example("triple_pendulum", [0.1, 0.0, 0.0], effects=pd3))
    assert (
        _error(path) == f"{path}: key 'effects.actuation.type' = 'pd': "
        "PD acts through B⁻¹, and B of triple_pendulum is singular"
    )
    no_input = _model_file(
        tmp_path, EXAMPLES / "hanging_double_pendulum.py", "    inputs = ()\n", "passive.py"
    )
    const = '[effects.actuation]\ntype = "constant"\nvalue = []\n'
    path = _scene(tmp_path, str(no_input), _example("hanging_double_pendulum", [0.1, 0.0], effects=const))
    assert (
        _error(path) == f"{path}: key 'effects.actuation.type' = 'constant': "
        "the hanging_double_pendulum model has no input"
    )


def test_lqr_without_a_stabilising_solution_is_an_error(tmp_path):
    # no gravity, no friction: a double integrator the one cart force cannot steer in both coordinates
    lqr = '[effects.actuation]\ntype = "lqr"\nQ = [1.0, 1.0, 1.0, 1.0]\nR = [1.0]\n'
    body = _example("cart_pole", [0.0, 0.1], "aba", lqr).replace("gravity = true\ndamping = true\n", "")
    path = _scene(tmp_path, str(EXAMPLES / "cart_pole.py"), body)
    message = _error(path, engine_run=True)
    assert message.startswith(
        f"{path}: key 'effects.actuation' = 'lqr': no LQR gain about 'upright': the Riccati equation has "
        "no stabilising solution for this Q, R and linearisation ("
    )


def test_urdf_option_must_name_a_file(tmp_path, capsys):
    missing = str(tmp_path / "none.urdf")
    assert main(["simulate", str(REPO / "scenes" / "damped_triple_pendulum.toml"), "--urdf", missing]) == 2
    assert capsys.readouterr().err.startswith(
        f"pendverify: error: robot description (--urdf) not found: {missing}; check the path"
    )


def test_render_of_a_plugin_without_urdf_is_an_error(tmp_path, capsys):
    body = _example("cart_pole", [0.0, 0.3], "closed_form").replace(
        f'urdf = "{EXAMPLES / "cart_pole.urdf"}"\n', ""
    )
    path = _scene(tmp_path, str(EXAMPLES / "cart_pole.py"), body)
    assert main(["render", str(path), "-o", str(tmp_path / "x.html")]) == 2
    assert capsys.readouterr().err == (
        f"pendverify: error: {path}: key 'urdf' = None: cart_pole is drawn from its URDF: "
        "give urdf = FILE in the scene, or --urdf\n"
    )
