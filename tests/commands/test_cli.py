"""The command line, called as ``main([...])``: table, JSON, exit codes, errors."""

from __future__ import annotations

import json

import pytest

from pendverify.checks.catalogue import CHECK_NAMES
from pendverify.cli import main
from pendverify.robot.erd import family_urdfs

from ..conftest import default_params

JSON_FIELDS = {"model", "check", "max_error", "tolerance", "samples", "worst_state", "passed", "seed"}


def test_default_check_passes_and_writes_json(tmp_path, capsys):
    out_json = tmp_path / "sub" / "report.json"
    assert main(["check", "--samples", "50", "--json", str(out_json)]) == 0
    out = capsys.readouterr().out
    # erd's mesh URDFs put link 1's centre of mass 2 µm off the joint line: within the model-form
    # threshold, a pass with a warning each (erd:double_pendulum and its continuous twin)
    assert "pass with 2 warning(s)" in out
    for label in ("double_pendulum", "cart_double_pendulum", "erd:double_pendulum_simple"):
        assert label in out
    report = json.loads(out_json.read_text())
    assert report["passed"] is True
    assert report["seed"] == 20260301
    models = {r["model"] for r in report["results"]}
    assert {"double_pendulum", "cart_double_pendulum", "erd:double_pendulum"} <= models
    for r in report["results"]:
        assert JSON_FIELDS <= set(r)
        assert r["max_error"] <= r["tolerance"]
    # erd's mesh URDFs carry a centre of mass 2 µm off the seed's joint line: a model-form row
    assert {r["check"] for r in report["results"]} == {"units", *CHECK_NAMES, "model-form"}
    assert not list(out_json.parent.glob(".*.tmp")), "temporary file left behind"


def test_model_urdf_extracts_parameters(capsys):
    urdf = str(family_urdfs()["double_pendulum_simple"])
    assert main(["check", "--model", "double_pendulum", "--urdf", urdf, "--samples", "20"]) == 0
    assert "parameters read off the URDF" in capsys.readouterr().out


def test_params_alone_checks_the_generated_urdf(tmp_path, capsys):
    path = tmp_path / "mine.toml"
    path.write_text(default_params("cart_double_pendulum").replace(m=3.0).to_toml())
    assert main(["check", "--params", str(path), "--samples", "20"]) == 0
    assert "cart_double_pendulum:mine" in capsys.readouterr().out


def test_cart_urdf_alone_needs_params(capsys):
    from importlib.resources import files

    urdf = str(files("pendverify.urdf") / "cart_double_pendulum.urdf")
    assert main(["check", "--model", "cart_double_pendulum", "--urdf", urdf]) == 2
    assert "give the parameter set (--params on the command line" in capsys.readouterr().err


def test_not_a_planar_chain_is_exit_2(capsys):
    from importlib.resources import files

    urdf = str(files("pendverify.urdf") / "cart_double_pendulum.urdf")
    assert main(["check", "--model", "double_pendulum", "--urdf", urdf]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pendverify: error: ")
    assert "expected a chain of joints revolute → revolute, found prismatic → revolute → revolute" in err


def test_unknown_model_is_exit_2(capsys):
    assert main(["check", "--model", "triple", "--urdf", "x.urdf"]) == 2
    assert "unknown model 'triple'; known: double_pendulum, cart_double_pendulum" in capsys.readouterr().err


def test_bad_parameter_file_is_exit_2(tmp_path, capsys):
    path = tmp_path / "neg.toml"
    path.write_text(
        default_params("double_pendulum").replace(b1=0.0).to_toml().replace("b1 = 0.0", "b1 = -1.0")
    )
    assert main(["check", "--params", str(path)]) == 2
    assert f"{path}: key 'parameters.b1' = -1.0: a damping must be" in capsys.readouterr().err


def test_json_reports_are_standard_json_even_with_an_infinite_error():
    """A det check that fails on a non-positive det M has an infinite error: written as "inf"."""
    from pendverify.checks.evidence import Evidence
    from pendverify.checks.report import Report

    failed = Evidence(
        "check", "det", "fail", float("inf"), 1e-15, {"label": "s", "q": []}, model="m", samples=1, seed=1
    )
    text = Report(seed=1, states={"m": 1}, results=[failed]).to_json()

    def refuse(name):
        raise AssertionError(f"non-standard JSON constant {name}")

    document = json.loads(text, parse_constant=refuse)
    assert document["results"][0]["max_error"] == "inf"
    assert document["status"] == "fail"


def test_check_reports_the_largest_error_apart_from_the_worst_ratio(tmp_path, capsys):
    """The table's error is at the worst error/tolerance; the largest error is reported too."""
    out = tmp_path / "check.json"
    assert main(["check", "--model", "cart_double_pendulum", "--samples", "200", "--json", str(out)]) == 0
    text = capsys.readouterr().out
    # the units row counts entries, no relative error: it has no largest error (NaN, "nan" in JSON)
    results = [r for r in json.loads(out.read_text())["results"] if r["check"] != "units"]
    for r in results:
        assert r["largest_error"] >= r["max_error"] and r["largest_state"]["label"]
        assert r["largest_error"] <= r["largest_tolerance"]  # every check passes
    top = max(results, key=lambda r: r["largest_error"])
    assert f"largest relative error: {top['largest_error']:.2e} (cart_double_pendulum {top['check']}" in text
    # on this sample the largest error and the worst ratio fall at different states for some check
    assert any(r["largest_state"]["label"] != r["worst_state"]["label"] for r in results)


@pytest.mark.parametrize(
    "argv, verdict",
    [
        (["sympy", "--model", "double_pendulum"], "every closed form equals its derivation"),
        (["stress", "--quick", "--case", "double pendulum g = 0"], "all cases pass"),
        (
            ["mutate", "--model", "double_pendulum", "--samples", "10", "--method", "mass_matrix"],
            "non-equivalent mutants",
        ),
    ],
    ids=lambda v: v[0] if isinstance(v, list) else "",
)
def test_json_dash_is_the_whole_of_stdout_and_quiet_keeps_the_verdict(
    argv, verdict, tmp_path, monkeypatch, capsys
):
    """``--json -``: the JSON on stdout, nothing else; with --quiet the verdict line alone on stderr."""
    monkeypatch.chdir(tmp_path)
    assert main([*argv, "--json", "-", "--quiet"]) == 0
    out, err = capsys.readouterr()
    json.loads(out)
    assert len(err.splitlines()) == 1 and verdict in err
    assert list(tmp_path.iterdir()) == [], "a file was written for --json -"
