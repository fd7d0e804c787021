"""Certificates: issued only when the battery passes, tamper-evident, written atomically."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from pendverify.analytic.params import default_parameter_file
from pendverify.certify.certificate import SCHEMA, digest_of, summary_of
from pendverify.cli import main

from ..conftest import default_params

FAST = ["--samples", "60"]
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


@pytest.fixture(scope="module")
def certified(tmp_path_factory):
    out = tmp_path_factory.mktemp("certs")
    assert main(["certify", str(default_parameter_file("double_pendulum")), "-o", str(out), *FAST]) == 0
    return out / "double_pendulum.cert.json"


def test_certificate_has_every_field(certified):
    cert = json.loads(certified.read_text())
    assert cert["schema"] == SCHEMA and cert["model"] == "double_pendulum"
    assert cert["parameters"] == default_params("double_pendulum").as_dict()
    assert set(cert["derived"]) == {"alpha", "beta", "delta"}
    assert cert["urdf"]["text"] == (certified.parent / "double_pendulum.urdf").read_text()
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
    assert (
        (certified.parent / "double_pendulum.params.toml").read_text().startswith('model = "double_pendulum"')
    )


def test_recheck_passes(certified, capsys):
    assert main(["recheck", str(certified)]) == 0
    assert "recheck passed" in capsys.readouterr().out


def test_edited_field_is_rejected_by_digest(certified, tmp_path, capsys):
    cert = json.loads(certified.read_text())
    cert["parameters"]["m1"] *= 1.01
    edited = tmp_path / "edited.cert.json"
    edited.write_text(json.dumps(cert))
    assert main(["recheck", str(edited)]) == 2
    err = capsys.readouterr().err
    assert f"{edited}: digest mismatch: recorded {cert['digest']['value']}, computed " in err


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


def test_existing_certificate_is_not_overwritten(certified, capsys):
    params = str(default_parameter_file("double_pendulum"))
    before = certified.read_text()
    assert main(["certify", params, "-o", str(certified.parent), *FAST]) == 2
    assert f"{certified} exists; pass --force to replace it" in capsys.readouterr().err
    assert certified.read_text() == before


def test_failing_set_writes_nothing(tmp_path, capsys):
    from pendverify.robot.writer import urdf_for

    urdf = tmp_path / "robot.urdf"
    urdf.write_text(urdf_for(default_params("double_pendulum").replace(I2=0.0135 * 1.01)))
    out = tmp_path / "out"
    params = str(default_parameter_file("double_pendulum"))
    assert main(["certify", "--urdf", str(urdf), "--params", params, "-o", str(out), *FAST]) == 1
    assert "NOT certified" in capsys.readouterr().out
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
    cert = json.loads((tmp_path / "erd_double_pendulum.cert.json").read_text())
    assert any("off the joint-1→joint-2 line" in note for note in cert["notes"])
    assert main(["recheck", str(tmp_path / "erd_double_pendulum.cert.json")]) == 0


def _certs(directory: Path) -> dict[str, dict]:
    out = {}
    for path in sorted(directory.glob("*.cert.json")):
        cert = json.loads(path.read_text())
        cert.pop("date"), cert.pop("digest")
        out[path.name] = cert
    return out


def test_sweep_runs_locally_and_on_dask_alike(tmp_path, capsys):
    distributed = pytest.importorskip("distributed", reason="the dask extra is part of the test extras")
    sweep = tmp_path / "sweep.toml"
    sweep.write_text(TINY_SWEEP)
    local = tmp_path / "local"
    assert main(["certify", "--sweep", str(sweep), "-o", str(local), "--workers", "2"]) == 0
    out = capsys.readouterr().out
    assert "3 passed, 0 failed, 3 sets" in out and "worst error/tolerance" in out
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, host="127.0.0.1", dashboard_address=":0", processes=True
    ) as cluster:
        assert cluster.scheduler_address.startswith("tcp://127.0.0.1:")
        remote = tmp_path / "dask"
        assert (
            main(
                [
                    "certify",
                    "--sweep",
                    str(sweep),
                    "-o",
                    str(remote),
                    "--scheduler",
                    cluster.scheduler_address,
                ]
            )
            == 0
        )
    local_certs, remote_certs = _certs(local), _certs(remote)
    assert len(local_certs) == 3
    assert local_certs == remote_certs


def test_bad_sweep_is_a_clear_error(tmp_path, capsys):
    sweep = tmp_path / "bad.toml"
    sweep.write_text(TINY_SWEEP.replace("m1 = [0.5, 2.0]", "mass = [0.5, 2.0]"))
    assert main(["certify", "--sweep", str(sweep), "-o", str(tmp_path)]) == 2
    assert (
        f"{sweep}: key 'ranges.mass' = [0.5, 2.0]: unknown parameter; double_pendulum has m1"
        in capsys.readouterr().err
    )


def test_near_singular_set_is_not_certified(tmp_path, capsys):
    params = tmp_path / "fragile.toml"
    params.write_text(default_params("cart_double_pendulum").replace(m1=1e-12).to_toml("fragile"))
    out = tmp_path / "out"
    assert main(["certify", str(params), "-o", str(out), *FAST]) == 1
    text = capsys.readouterr().out
    assert "NOT certified" in text and "stress:conditioning" in text
    assert not (out / "fragile.cert.json").exists()


def test_battery_covers_stress_cases(certified):
    names = {c["name"] for c in json.loads(certified.read_text())["checks"] if c["kind"] == "stress"}
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
