"""``potential_energy`` is optional in a model class.

A class without V loads and passes ``check``, its ``energy`` check "not run" with the reason in
the not-run vocabulary; the same class with a wrong V fails ``energy``; ``sympy`` leaves V out
with the reason, and compares the rest; ``mutate`` runs; a scene integrating the class's own
equations (engine closed_form), whose energy needs V, is refused in one line.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import pendverify
from pendverify.analytic.plugin import load_model_class
from pendverify.api import load_scene, simulate
from pendverify.cli import main
from pendverify.errors import PendverifyError

REPO = Path(__file__).resolve().parents[2]
URDF = REPO / "tests" / "analytic" / "data" / "pendulum_functions.urdf"

# the single pendulum of tests/analytic/data/pendulum_functions.py as a class: θ from hanging
# down about y, V = −m g l cos θ, G = ∂V/∂θ = m g l sin θ
PENDULUM = """\
import dataclasses

import numpy as np

from pendverify import ClosedFormModel, Energies, ParameterSet, quantity


@dataclasses.dataclass(frozen=True)
class PendulumParams(ParameterSet):
    model = "pendulum"
    m: float = quantity("mass", "bob mass [kg]")
    l: float = quantity("length", "rod length [m]")
    b: float = quantity("damping", "hinge friction [N·m·s/rad]")
    g: float = quantity("gravity", "gravity [m/s²]")


class Pendulum(ClosedFormModel):
    name = "pendulum"
    params_type = PendulumParams
    coordinates = ("theta",)
    angular = (True,)
    urdf_joints = ("hinge",)

    def mass_matrix(self, q):
        p = self.params
        return np.array([[p.m * p.l**2]])

    def coriolis_matrix(self, q, v):
        return np.zeros((1, 1))

    def gravity(self, q):
        p = self.params
        return np.array([p.m * p.g * p.l * self.math.sin(q[0])])

    def damping_matrix(self):
        return np.array([[self.params.b]])

    def energies(self, q, v, u, w):
        p = self.params
        return Energies(
            kinetic=p.m * p.l**2 * v[0] ** 2 / 2,
            potential=-p.m * p.g * p.l * self.math.cos(q[0]),
            dissipation=p.b * v[0] ** 2 / 2,
        )
"""
WITH_V = """
    def potential_energy(self, q):
        p = self.params
        return -p.m * p.g * p.l * self.math.cos(q[0])
"""
PARAMS = 'model = "pendulum"\n[parameters]\nm = 2.0\nl = 0.5\nb = 0.1\ng = 9.81\n'
NOT_RUN = "energy not run: the model gives no potential energy V(q) (Pendulum writes no potential_energy)"


def _files(tmp_path: Path, text: str) -> list[str]:
    model, params = tmp_path / "pendulum.py", tmp_path / "pendulum.toml"
    model.write_text(text)
    params.write_text(PARAMS)
    return ["--analytic", str(model), "--urdf", str(URDF), "--params", str(params)]


def test_a_class_without_v_passes_with_energy_not_run(tmp_path, capsys):
    args = _files(tmp_path, PENDULUM)
    cls = load_model_class(args[1])
    assert not cls.has_potential_energy() and "potential_energy" not in cls.hand_written()
    assert main(["check", *args, "--samples", "60"]) == 0
    out = capsys.readouterr().out
    assert "all checks pass" in out and NOT_RUN in out, out
    assert not any(line.split()[1:2] == ["energy"] for line in out.splitlines() if line.strip())


def test_the_same_class_with_v_runs_energy_and_a_wrong_v_fails_it(tmp_path, capsys):
    assert main(["check", *_files(tmp_path, PENDULUM + WITH_V), "--samples", "60"]) == 0
    out = capsys.readouterr().out
    assert "energy    " in out and NOT_RUN not in out, out
    wrong = PENDULUM + WITH_V.replace("* self.math.cos(q[0])", "* self.math.cos(q[0]) * 1.01")
    assert main(["check", *_files(tmp_path, wrong), "--samples", "60"]) == 1
    rows = [line.split() for line in capsys.readouterr().out.splitlines() if line.startswith("pendulum:")]
    failing = [row[1] for row in rows if row[-1] == "FAIL"]
    assert failing == ["energy"], failing


def test_sympy_leaves_v_out_and_compares_the_rest(tmp_path, capsys):
    args = _files(tmp_path, PENDULUM)
    assert main(["sympy", args[0], args[1]]) == 0
    out = capsys.readouterr().out
    assert "not run: the model gives no potential energy V(q) (potential_energy)" in out, out
    # the rest is compared: a wrong H still differs from ∂V/∂q of the energies' V
    wrong = _files(tmp_path, PENDULUM.replace("* self.math.sin(q[0])])", "* self.math.sin(q[0]) * 1.01])"))
    assert main(["sympy", wrong[0], wrong[1]]) == 1
    assert "DIFFERS" in capsys.readouterr().out


def test_mutate_runs_without_v(tmp_path, capsys):
    assert main(["mutate", *_files(tmp_path, PENDULUM)]) == 0
    assert "detection rate 100.0%" in capsys.readouterr().out


def test_a_scene_integrating_the_class_without_v_is_refused_in_one_line(tmp_path):
    args = _files(tmp_path, PENDULUM)
    scene = {
        "name": "pendulum",
        "model": args[1],
        "params": args[5],
        "urdf": str(URDF),
        "engine": "closed_form",
        "initial": {"q": [1.0]},
        "time": {"duration": 0.5, "sample_rate": 50.0},
        "integrator": {"method": "DOP853", "rtol": 1e-10, "atol": 1e-10},
        "effects": {"gravity": True, "damping": True},
    }
    with pytest.raises(PendverifyError) as info:
        simulate(load_scene(scene))
    message = str(info.value)
    assert "\n" not in message and "the model gives no potential energy V(q)" in message, message
    assert simulate(load_scene({**scene, "engine": "both"})).passed  # Pinocchio's energy then


def test_check_through_the_api_reports_energy_not_run(tmp_path):
    args = _files(tmp_path, PENDULUM)
    report = pendverify.check(args[1], URDF, args[5], samples=30)
    assert report.status == "pass" and "energy" not in report.checks, report
