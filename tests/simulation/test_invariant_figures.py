"""Invariants report the largest error and the worst error/tolerance ratio apart, each with where."""

from __future__ import annotations

import json
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from pendverify.checks.evidence import invariant_record, largest_abs
from pendverify.cli import main
from pendverify.simulation.invariants import evaluate, figures_of
from pendverify.simulation.scene import load_scene
from pendverify.simulation.simulate import run_scene

CHAOTIC = Path(__file__).resolve().parents[2] / "scenes" / "chaotic_double_pendulum.toml"


class PlantedEnergy:
    """A one-coordinate system whose energy is its coordinate: E(x) = q."""

    nv = 1

    def energy(self, q, v):
        return float(q[0])


def test_largest_error_and_worst_ratio_are_reported_apart():
    # the largest error (3e-3 at t = 2) is not where error/tolerance is worst (1e-3/1e-3 at t = 1)
    t = np.array([0.0, 1.0, 2.0, 3.0])
    energy = np.array([1.0, 1.001, 1.003, 1.002])
    xs = np.column_stack([energy, np.zeros(4), np.zeros(4), np.zeros(4)])
    bound = np.array([1e-9, 1e-3, 1e-2, 1e-2])
    scene = SimpleNamespace(actuation=None, disturbance=None, conservative=True, damping=None)
    (drift,) = evaluate(PlantedEnergy(), scene, t, xs, bound, scale=2.0)
    assert drift.largest_error == pytest.approx(3e-3 / 2) and drift.largest_at["t"] == 2.0
    assert largest_abs(drift) == pytest.approx(3e-3)
    assert drift.error == pytest.approx(1e-3 / 2) and drift.tolerance == pytest.approx(1e-3 / 2)
    assert drift.at["t"] == 1.0 and drift.passed
    record = invariant_record(drift)
    assert {"max_error", "max_error_t", "max_error_abs", "error", "tolerance", "worst_t", "scale"} <= set(
        record
    )


def test_a_state_beyond_its_tolerance_fails_whatever_the_largest_error():
    result = figures_of("planted", np.array([5.0, 2.0]), np.array([10.0, 1.0]), [0.0, 1.0], 1.0, "")
    assert not result.passed
    assert (result.largest_error, result.largest_at["t"]) == (5.0, 0.0)
    assert (result.error, result.tolerance, result.at["t"]) == (2.0, 1.0, 1.0)


@pytest.fixture(scope="module")
def chaotic():
    return run_scene(load_scene(CHAOTIC))


def test_chaotic_scene_reports_its_largest_energy_error(chaotic):
    (drift,) = chaotic.invariants
    assert largest_abs(drift) == pytest.approx(1.24e-8, rel=0.05)  # J
    assert drift.error == pytest.approx(4.24e-11, rel=0.05)  # relative, at the worst ratio
    assert drift.largest_error > 5 * drift.error and drift.largest_at["t"] != drift.at["t"]
    meta = chaotic.metadata()["invariants"][0]
    assert meta["max_error_abs"] == pytest.approx(1.24e-8, rel=0.05)
    assert json.loads(json.dumps(meta))["worst_t"] == drift.at["t"]


def test_simulate_table_prints_both_figures(capsys):
    assert main(["simulate", str(CHAOTIC)]) == 0
    out = capsys.readouterr().out
    assert "largest error" in out and "worst error/tolerance" in out
    row = next(line for line in out.splitlines() if line.startswith("energy drift"))
    assert "1.24e-08" in row and "4.24e-11" in row
