"""certify and recheck on model files: the source travels in the certificate, sweeps rewrite the URDF."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from pendverify.certify.certificate import digest_of
from pendverify.cli import main

from .test_certify import _certs

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
FAST = ["--samples", "20"]
PLUGINS = ("cart_pole", "hanging_double_pendulum", "triple_pendulum", "furuta_pendulum")

SINGLE_PENDULUM = """
import dataclasses
import numpy as np
from pendverify.analytic import ClosedFormModel
from pendverify.analytic.parameter_set import ParameterSet, quantity


@dataclasses.dataclass(frozen=True)
class SingleParams(ParameterSet):
    model = "single_pendulum"
    m: float = quantity("mass", "mass [kg]")
    r: float = quantity("offset", "pivot to centre of mass [m]")
    I: float = quantity("inertia", "inertia about the centre of mass [kg·m²]")
    b: float = quantity("damping", "pivot friction [N·m·s/rad]")
    g: float = quantity("gravity", "[m/s²]")


class Single(ClosedFormModel):
    name = "single_pendulum"
    params_type = SingleParams
    coordinates = ("phi",)
    angular = (True,)
    inputs = ("tau",)
    urdf_joints = ("joint1",)

    def mass_matrix(self, q):
        p = self.params
        return np.array([[p.I + p.m * p.r**2]])

    def coriolis_matrix(self, q, v):
        return np.zeros((1, 1))

    def gravity(self, q):
        p = self.params
        return np.array([p.m * p.g * p.r * self.math.sin(q[0])])

    def potential_energy(self, q):
        p = self.params
        return -p.m * p.g * p.r * self.math.cos(q[0])

    def damping_matrix(self):
        return np.array([[self.params.b]])

    def input_matrix(self):
        return np.array([[1.0]])
"""
SINGLE_URDF = """<?xml version="1.0"?>
<robot name="single">
  <link name="base"/>
  <joint name="joint1" type="revolute">
    <parent link="base"/><child link="link1"/>
    <origin xyz="0 0 0" rpy="0 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-1e9" upper="1e9" effort="1e9" velocity="1e9"/>
    <dynamics damping="0.02"/>
  </joint>
  <link name="link1">
    <inertial>
      <origin xyz="0 0 -0.3" rpy="0 0 0"/>
      <mass value="0.5"/>
      <inertia ixx="0.004" ixy="0" ixz="0" iyy="0.004" iyz="0" izz="0"/>
    </inertial>
  </link>
</robot>
"""
SINGLE_PARAMS = """model = "single_pendulum"
[parameters]
m = 0.5
r = 0.3
I = 0.004
b = 0.02
g = 9.81
"""


def example(name: str) -> list[str]:
    return [
        "--analytic",
        str(EXAMPLES / f"{name}.py"),
        "--urdf",
        str(EXAMPLES / f"{name}.urdf"),
        "--params",
        str(EXAMPLES / f"{name}.toml"),
    ]


@pytest.mark.parametrize("name", PLUGINS)
def test_example_is_certified_and_rechecked(name, tmp_path, capsys):
    assert main(["certify", *example(name), "-o", str(tmp_path), *FAST]) == 0
    cert_path = tmp_path / f"{name}.cert.json"
    cert = json.loads(cert_path.read_text())
    source = (EXAMPLES / f"{name}.py").read_text()
    assert cert["model"] == name
    assert cert["model_source"]["text"] == source and cert["model_source"]["file"] == f"{name}.py"
    assert len(cert["model_source"]["sha256"]) == 64 and cert["digest"]["value"] == digest_of(cert)
    assert (tmp_path / f"{name}.model.py").read_text() == source
    names = {c["name"] for c in cert["checks"]}
    assert {"check:crba", "stress:large-angles", "invariant:gravity:energy"} <= names
    capsys.readouterr()
    assert main(["recheck", str(cert_path), "--run-embedded-code"]) == 0
    assert "recheck passed" in capsys.readouterr().out


def _certify_single(tmp_path: Path, source: str = SINGLE_PENDULUM) -> tuple[int, Path]:
    (tmp_path / "single.py").write_text(source)
    (tmp_path / "single.urdf").write_text(SINGLE_URDF)
    (tmp_path / "single.toml").write_text(SINGLE_PARAMS)
    files = ["--analytic", "single.py", "--urdf", "single.urdf", "--params", "single.toml"]
    out = tmp_path / "out"
    paths = [str(tmp_path / f) if not f.startswith("--") else f for f in files]
    return main(["certify", *paths, "-o", str(out), *FAST]), out / "single.cert.json"


def test_a_model_written_in_the_test_is_certified(tmp_path, capsys):
    status, cert_path = _certify_single(tmp_path)
    assert status == 0, capsys.readouterr().out
    cert = json.loads(cert_path.read_text())
    names = {c["name"] for c in cert["checks"]}
    # derived from the model: a damping run (D ≠ 0) and an actuation run (B), no disturbance (no W)
    assert {"invariant:damping:dissipation", "invariant:actuation:work–energy"} <= names
    assert not any(n.startswith("invariant:disturbance") for n in names)
    (tmp_path / "single.py").write_text("# replaced after certification\n")  # recheck must not read it
    assert main(["recheck", str(cert_path), "--run-embedded-code"]) == 0


def test_a_planted_error_is_not_certified(tmp_path, capsys):
    wrong = SINGLE_PENDULUM.replace("p.I + p.m * p.r**2", "p.I + p.m * p.r")  # a wrong M entry
    status, cert_path = _certify_single(tmp_path, wrong)
    assert status == 1
    out = capsys.readouterr().out
    assert "NOT certified" in out and "check:crba" in out.split("NOT certified")[1]
    assert not cert_path.exists()


def test_a_planted_error_in_a_copied_example_is_not_certified(tmp_path, capsys):
    text = (EXAMPLES / "hanging_double_pendulum.py").read_text()
    model = tmp_path / "hanging.py"
    model.write_text(
        text.replace("return np.array([[a, c], [c, d]])", "return np.array([[a, c], [c, 1.001 * d]])")
    )
    assert model.read_text() != text
    args = example("hanging_double_pendulum")
    args[1] = str(model)
    assert main(["certify", *args, "-o", str(tmp_path / "out"), *FAST]) == 1
    failed = capsys.readouterr().out.split("NOT certified")[1]
    assert "check:crba" in failed


def test_tampered_model_source_fails_recheck(tmp_path, capsys):
    assert main(["certify", *example("cart_pole"), "-o", str(tmp_path), *FAST]) == 0
    cert = json.loads((tmp_path / "cart_pole.cert.json").read_text())
    cert["model_source"]["text"] = cert["model_source"]["text"] + "\nCartPole.gravity = None\n"
    edited = tmp_path / "edited.cert.json"
    edited.write_text(json.dumps(cert))
    assert main(["recheck", str(edited)]) == 2
    err = capsys.readouterr().err
    assert "digest mismatch" in err and "the embedded model source does not match its sha256" in err
    cert["digest"]["value"] = digest_of(cert)  # re-signed: the source's own hash still fails
    edited.write_text(json.dumps(cert))
    assert main(["recheck", str(edited)]) == 2
    assert "key 'model_source.text': the embedded model source does not match" in capsys.readouterr().err


def _plugin_sweep(tmp_path: Path) -> Path:
    for suffix in ("py", "urdf", "toml"):
        shutil.copy(EXAMPLES / f"hanging_double_pendulum.{suffix}", tmp_path / f"hanging.{suffix}")
    sweep = tmp_path / "sweep.toml"
    sweep.write_text(
        'model = "hanging.py"\nbase = "hanging.toml"\nurdf = "hanging.urdf"\nmode = "random"\n'
        "count = 2\nseed = 5\nsamples = 10\nduration = 0.2\n[ranges]\nm1 = [0.5, 2.0]\n"
        'r2 = { min = 0.1, max = 0.4, scale = "log" }\n'
    )
    return sweep


def test_sweep_over_a_model_file_locally_and_on_dask(tmp_path, capsys):
    distributed = pytest.importorskip("distributed", reason="the dask extra is part of the test extras")
    sweep = _plugin_sweep(tmp_path)
    local = tmp_path / "local"
    assert main(["certify", "--sweep", str(sweep), "-o", str(local), "--workers", "1"]) == 0
    assert "2 passed, 0 failed, 2 sets" in capsys.readouterr().out
    certs = _certs(local)
    assert len(certs) == 2
    for name, cert in certs.items():
        assert cert["model_source"]["file"] == "hanging.py"
        assert f'<mass value="{cert["parameters"]["m1"]!r}"' in cert["urdf"]["text"]
        assert main(["recheck", str(local / name), "--run-embedded-code"]) == 0
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, host="127.0.0.1", dashboard_address=":0", processes=True
    ) as cluster:
        remote = tmp_path / "dask"
        args = ["certify", "--sweep", str(sweep), "-o", str(remote), "--scheduler", cluster.scheduler_address]
        assert main(args) == 0
    assert _certs(remote) == certs


def test_sweep_over_a_parameter_the_urdf_does_not_show_is_refused(tmp_path, capsys):
    sweep = _plugin_sweep(tmp_path)
    sweep.write_text(sweep.read_text().replace("m1 = [0.5, 2.0]", "l2 = [0.4, 0.6]"))
    assert main(["certify", "--sweep", str(sweep), "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert f"{sweep}: key 'ranges.l2'" in err and "cannot be varied: its value 0.5 is not in the URDF" in err
