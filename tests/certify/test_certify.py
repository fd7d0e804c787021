"""Certificates: issued only when the battery passes, tamper-evident, written atomically.

A certificate's fields, its recheck, its stress items, a planted error and a sweep are tested
on a built-in model and on model files (the plug-ins of ``examples/`` and one written here),
whose source travels in the certificate; a sweep over a model file rewrites its URDF.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest

from pendverify.analytic.params import default_parameter_file, load_parameter_file
from pendverify.analytic.plugin import load_model_class
from pendverify.certify.certificate import SCHEMA, digest_of, summary_of
from pendverify.cli import main

from ..conftest import default_params

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FAST = ["--samples", "60"]
PLUGINS = ("cart_pole", "hanging_double_pendulum", "triple_pendulum", "furuta_pendulum")
CERTIFIED_MODELS = ("double_pendulum", *PLUGINS)
DERIVED = {"double_pendulum": {"alpha", "beta", "delta"}}  # the plug-ins derive none
TINY_SWEEP = """
model = "double_pendulum"
mode = "random"
count = 3
seed = 3
samples = 20
duration = 0.3
[ranges]
m1 = [0.5, 2.0]
I1 = { min = 0.001, max = 0.05, scale = "log" }
"""
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


def certify_args(name: str) -> list[str]:
    """A built-in model's default parameter file, or a plug-in example's model, URDF and parameters."""
    return example(name) if name in PLUGINS else [str(default_parameter_file(name))]


def parameters_of(name: str):
    if name not in PLUGINS:
        return default_params(name)
    cls = load_model_class(EXAMPLES / f"{name}.py")
    return load_parameter_file(EXAMPLES / f"{name}.toml", {cls.name: cls.params_type})[2]


@pytest.fixture(scope="module")
def certificates(tmp_path_factory):
    """``certificates(name)``: the model's certificate, issued once for the module into one folder."""
    out = tmp_path_factory.mktemp("certs")
    issued = {}

    def certificate(name: str) -> Path:
        if name not in issued:
            assert main(["certify", *certify_args(name), "-o", str(out), *FAST]) == 0
            issued[name] = out / f"{name}.cert.json"
        return issued[name]

    return certificate


@pytest.fixture(scope="module")
def certified(certificates):
    return certificates("double_pendulum")


@pytest.mark.slow
@pytest.mark.parametrize("name", CERTIFIED_MODELS)
def test_certificate_has_every_field(certificates, name):
    certified = certificates(name)
    cert = json.loads(certified.read_text())
    assert cert["schema"] == SCHEMA and cert["model"] == name
    assert cert["parameters"] == parameters_of(name).as_dict()
    assert set(cert["derived"]) == DERIVED.get(name, set())
    assert cert["urdf"]["text"] == (certified.parent / f"{name}.urdf").read_text()
    assert len(cert["urdf"]["sha256"]) == 64
    assert {"pendverify", "pinocchio", "numpy", "python"} == set(cert["versions"])
    kinds = {c["kind"] for c in cert["checks"]}
    assert {"check", "invariant"} <= kinds
    for c in cert["checks"]:
        assert {
            "name",
            "error",
            "tolerance",
            "at",
            "max_error",
            "max_error_at",
            "samples",
            "seed",
            "passed",
        } <= set(c)
        assert c["passed"] and c["error"] <= c["tolerance"]
        assert (c["max_error"] is None) == (c["kind"] == "stress")
        if c["kind"] == "check":  # the largest error is at least the error at the worst ratio
            assert c["max_error"] >= c["error"] and c["max_error_at"]
    assert cert["summary"] == summary_of(cert["checks"]) and cert["summary"]["result"] == "PASSED"
    assert cert["digest"] == {"algorithm": "sha256", "value": digest_of(cert)}
    assert (certified.parent / f"{name}.params.toml").read_text().startswith(f'model = "{name}"')
    names = {c["name"] for c in cert["checks"]}
    assert {"check:crba", "stress:large-angles", "invariant:gravity:energy"} <= names
    copy = certified.parent / f"{name}.model.py"
    if name in PLUGINS:  # the model file's source travels in the certificate and is written beside it
        source = (EXAMPLES / f"{name}.py").read_text()
        assert cert["model_source"]["text"] == source and cert["model_source"]["file"] == f"{name}.py"
        assert len(cert["model_source"]["sha256"]) == 64
        assert copy.read_text() == source
    else:  # a built-in model is named, not embedded
        assert "model_source" not in cert and not copy.exists()


@pytest.mark.slow
@pytest.mark.parametrize("name", CERTIFIED_MODELS)
def test_recheck_passes(certificates, name, capsys):
    certified = certificates(name)
    capsys.readouterr()
    embedded = ["--run-embedded-code"] if name in PLUGINS else []
    assert main(["recheck", str(certified), *embedded]) == 0
    assert "recheck passed" in capsys.readouterr().out


def _certify_single(tmp_path: Path, source: str = SINGLE_PENDULUM) -> tuple[int, Path]:
    (tmp_path / "single.py").write_text(source)
    (tmp_path / "single.urdf").write_text(SINGLE_URDF)
    (tmp_path / "single.toml").write_text(SINGLE_PARAMS)
    files = ["--analytic", "single.py", "--urdf", "single.urdf", "--params", "single.toml"]
    out = tmp_path / "out"
    paths = [str(tmp_path / f) if not f.startswith("--") else f for f in files]
    return main(["certify", *paths, "-o", str(out), *FAST]), out / "single_pendulum-single.cert.json"


@pytest.mark.slow
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


@pytest.mark.slow
def test_edited_field_is_rejected_by_digest(certified, tmp_path, capsys):
    cert = json.loads(certified.read_text())
    cert["parameters"]["m1"] *= 1.01
    edited = tmp_path / "edited.cert.json"
    edited.write_text(json.dumps(cert))
    assert main(["recheck", str(edited)]) == 2
    err = capsys.readouterr().err
    assert f"{edited}: digest mismatch: recorded {cert['digest']['value']}, computed " in err


@pytest.mark.slow
def test_resigned_edit_names_the_differing_fields(certified, tmp_path, capsys):
    cert = json.loads(certified.read_text())
    cert["checks"][0]["error"] *= 3
    cert["checks"][1]["samples"] += 1
    cert["summary"] = summary_of(cert["checks"])  # the forger derives the summary again too
    cert["digest"]["value"] = digest_of(cert)
    forged = tmp_path / "forged.cert.json"
    forged.write_text(json.dumps(cert))
    assert main(["recheck", str(forged)]) == 1
    out = capsys.readouterr().out
    assert f"differs: {cert['checks'][0]['name']}.error: recorded" in out
    assert f"differs: {cert['checks'][1]['name']}.samples: recorded" in out


@pytest.mark.slow
def test_tampered_model_source_fails_recheck(certificates, tmp_path, capsys):
    cert = json.loads(certificates("cart_pole").read_text())
    capsys.readouterr()
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


@pytest.mark.slow
def test_existing_certificate_is_not_overwritten(certified, capsys):
    params = str(default_parameter_file("double_pendulum"))
    before = certified.read_text()
    assert main(["certify", params, "-o", str(certified.parent), *FAST]) == 2
    assert f"{certified} exists; pass --force to replace it" in capsys.readouterr().err
    assert certified.read_text() == before


def _wrong_urdf_of_the_built_in_model(tmp_path: Path) -> list[str]:
    """The double pendulum's default set against a URDF whose link 2 has its inertia 1 % off."""
    from pendverify.robot.writer import urdf_for

    urdf = tmp_path / "robot.urdf"
    urdf.write_text(urdf_for(default_params("double_pendulum").replace(I2=0.0135 * 1.01)))
    return ["--urdf", str(urdf), "--params", str(default_parameter_file("double_pendulum"))]


def _wrong_mass_matrix_in_a_model_written_here(tmp_path: Path) -> list[str]:
    (tmp_path / "single.py").write_text(SINGLE_PENDULUM.replace("p.I + p.m * p.r**2", "p.I + p.m * p.r"))
    (tmp_path / "single.urdf").write_text(SINGLE_URDF)
    (tmp_path / "single.toml").write_text(SINGLE_PARAMS)
    return [
        "--analytic",
        str(tmp_path / "single.py"),
        "--urdf",
        str(tmp_path / "single.urdf"),
        "--params",
        str(tmp_path / "single.toml"),
    ]


def _wrong_mass_matrix_in_a_copied_example(tmp_path: Path) -> list[str]:
    text = (EXAMPLES / "hanging_double_pendulum.py").read_text()
    model = tmp_path / "hanging.py"
    model.write_text(
        text.replace("return np.array([[a, c], [c, d]])", "return np.array([[a, c], [c, 1.001 * d]])")
    )
    assert model.read_text() != text
    args = example("hanging_double_pendulum")
    args[1] = str(model)
    return args


@pytest.mark.slow
@pytest.mark.parametrize(
    "planted",
    [
        _wrong_urdf_of_the_built_in_model,
        _wrong_mass_matrix_in_a_model_written_here,
        _wrong_mass_matrix_in_a_copied_example,
    ],
    ids=["built-in URDF", "plug-in written here", "plug-in copied example"],
)
def test_failing_set_writes_nothing(planted, tmp_path, capsys):
    args = planted(tmp_path)
    out = tmp_path / "out"
    assert main(["certify", *args, "-o", str(out), *FAST]) == 1
    text = capsys.readouterr().out
    assert "NOT certified" in text and "check:crba" in text.split("NOT certified")[1]
    assert not out.exists() or not list(out.iterdir())


def test_writer_failing_midway_leaves_no_certificate(tmp_path, monkeypatch, capsys):
    import pendverify.atomic as atomic

    calls = {"n": 0}
    real_fsync = os.fsync
    out = tmp_path / "out"

    def into_out(fd) -> bool:
        """A file being written into ``out`` (not the generated-code cache, written or not by now)."""
        st = os.fstat(fd)
        return out.is_dir() and any(
            (p.stat().st_dev, p.stat().st_ino) == (st.st_dev, st.st_ino) for p in out.iterdir()
        )

    def failing_fsync(fd):
        if into_out(fd):
            calls["n"] += 1
            if calls["n"] == 3:  # the certificate is the third file
                raise OSError("disk full")
        real_fsync(fd)

    monkeypatch.setattr(atomic.os, "fsync", failing_fsync)
    # an output that cannot be written: status 2, naming the file and the OS's reason
    assert main(["certify", str(default_parameter_file("cart_double_pendulum")), "-o", str(out), *FAST]) == 2
    assert "cart_double_pendulum.cert.json: cannot write it: disk full" in capsys.readouterr().err
    assert not (out / "cart_double_pendulum.cert.json").exists()
    assert not [p for p in out.iterdir() if p.name.endswith(".tmp")]


def test_example_robot_data_urdf_is_certified(tmp_path, capsys):
    args = ["certify", "--model", "double_pendulum", "--urdf", "erd:double_pendulum", "-o", str(tmp_path)]
    assert main([*args, *FAST]) == 0
    cert = json.loads((tmp_path / "double_pendulum-erd_double_pendulum.cert.json").read_text())
    assert any("off the joint-1→joint-2 line" in note for note in cert["notes"])
    assert main(["recheck", str(tmp_path / "double_pendulum-erd_double_pendulum.cert.json")]) == 0


def certificates_by_file(directory: Path) -> dict[str, dict]:
    """File name → certificate of every certificate in ``directory``, without ``date`` and
    ``digest`` (what differs between two runs on one set)."""
    out = {}
    for path in sorted(directory.glob("*.cert.json")):
        cert = json.loads(path.read_text())
        cert.pop("date"), cert.pop("digest")
        out[path.name] = cert
    return out


def _built_in_sweep(tmp_path: Path) -> Path:
    sweep = tmp_path / "sweep.toml"
    sweep.write_text(TINY_SWEEP)
    return sweep


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


@pytest.mark.sweep
@pytest.mark.parametrize(
    ("write_sweep", "sets", "workers", "model_file"),
    [(_built_in_sweep, 3, "2", None), (_plugin_sweep, 2, "1", "hanging.py")],
    ids=["built-in", "plug-in"],
)
def test_sweep_runs_locally_and_on_dask_alike(write_sweep, sets, workers, model_file, tmp_path, capsys):
    distributed = pytest.importorskip("distributed", reason="the dask extra is part of the test extras")
    sweep = write_sweep(tmp_path)
    local = tmp_path / "local"
    assert main(["certify", "--sweep", str(sweep), "-o", str(local), "--workers", workers]) == 0
    out = capsys.readouterr().out
    assert f"{sets} passed, 0 failed, {sets} sets" in out and "worst error/tolerance" in out
    local_certs = certificates_by_file(local)
    assert len(local_certs) == sets
    embedded = ["--run-embedded-code"] if model_file else []
    for name, cert in local_certs.items():
        if model_file:  # the model file travels with each set
            assert cert["model_source"]["file"] == model_file
        else:
            assert "model_source" not in cert
        assert f'<mass value="{cert["parameters"]["m1"]!r}"' in cert["urdf"]["text"]  # the URDF of the set
        assert main(["recheck", str(local / name), *embedded]) == 0
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, host="127.0.0.1", dashboard_address=":0", processes=True
    ) as cluster:
        assert cluster.scheduler_address.startswith("tcp://127.0.0.1:")
        remote = tmp_path / "dask"
        args = ["certify", "--sweep", str(sweep), "-o", str(remote), "--scheduler", cluster.scheduler_address]
        assert main(args) == 0
    assert certificates_by_file(remote) == local_certs


def test_bad_sweep_is_a_clear_error(tmp_path, capsys):
    sweep = tmp_path / "bad.toml"
    sweep.write_text(TINY_SWEEP.replace("m1 = [0.5, 2.0]", "mass = [0.5, 2.0]"))
    assert main(["certify", "--sweep", str(sweep), "-o", str(tmp_path)]) == 2
    assert (
        f"{sweep}: key 'ranges.mass' = [0.5, 2.0]: unknown parameter; double_pendulum has m1"
        in capsys.readouterr().err
    )


def test_sweep_over_a_parameter_the_urdf_does_not_show_is_refused(tmp_path, capsys):
    sweep = _plugin_sweep(tmp_path)
    sweep.write_text(sweep.read_text().replace("m1 = [0.5, 2.0]", "l2 = [0.4, 0.6]"))
    assert main(["certify", "--sweep", str(sweep), "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert f"{sweep}: key 'ranges.l2'" in err and "cannot be varied: its value 0.5 is not in the URDF" in err


def test_near_singular_set_is_not_certified(tmp_path, capsys):
    params = tmp_path / "fragile.toml"
    params.write_text(default_params("cart_double_pendulum").replace(m1=1e-12).to_toml("fragile"))
    out = tmp_path / "out"
    assert main(["certify", str(params), "-o", str(out), *FAST]) == 1
    text = capsys.readouterr().out
    assert "NOT certified" in text and "stress:conditioning" in text
    assert not (out / "fragile.cert.json").exists()


@pytest.mark.slow
@pytest.mark.parametrize("name", CERTIFIED_MODELS)
def test_battery_covers_stress_cases(certificates, name):
    checks = json.loads(certificates(name).read_text())["checks"]
    names = {c["name"] for c in checks if c["kind"] == "stress"}
    assert names == {
        "stress:large-angles",
        "stress:high-speeds",
        "stress:zero-gravity",
        "stress:conditioning",
    }


def test_the_battery_s_stress_items_run_on_the_urdf_being_certified():
    """A URDF with link 2's inertia 1 % off fails the stress items too, not only the core checks."""
    from pendverify.certify.battery import BatterySettings, stress_items
    from pendverify.robot.writer import urdf_for

    params = default_params("double_pendulum")
    settings = BatterySettings(samples=20)
    wrong = urdf_for(params.replace(I2=params.I2 * 1.01))
    own = stress_items("double_pendulum", params, settings)
    given = stress_items("double_pendulum", params, settings, wrong)
    assert all(i.passed for i in own)
    assert not any(i.passed for i in given if i.name != "stress:conditioning"), [i.name for i in given]
