"""``pendverify bench certify --quick``: the table's shape and finite, positive figures.  No test looks at
a time."""

from __future__ import annotations

import json
import math

import pytest

from pendverify.analytic import MODELS
from pendverify.bench.certify import SetCost
from pendverify.bench.certify_report import rows, target_line
from pendverify.certify.battery import BatterySettings
from pendverify.cli import main

PARTS = ("checks", "stress", "invariants", "battery")


@pytest.mark.slow
def test_bench_certify_quick_prints_every_set_and_part(tmp_path, capsys):
    out = tmp_path / "certify.json"
    assert main(["bench", "certify", "--quick", "--json", str(out)]) == 0
    text = capsys.readouterr().out
    assert "floor s" in text and "over floor" in text
    for name in MODELS:
        assert f"target {name}: not judged: battery" in text
        assert "run without --quick to judge them" in text and "NOT met" not in text
    report = json.loads(out.read_text())
    assert [s["name"] for s in report["sets"]] == list(MODELS)
    for cost in report["sets"]:
        assert [r["part"] for r in cost["rows"]] == list(PARTS)
        for r in cost["rows"]:
            assert math.isfinite(r["seconds"]) and r["seconds"] > 0, r
            if r["part"] != "invariants":
                for key in ("floor_s", "over_floor"):
                    assert math.isfinite(r[key]) and r[key] > 0, (r, key)
        assert cost["contexts"]["checks"] >= 1 and cost["contexts"]["stress"] >= 1


def test_rows_derive_the_batterys_floor():
    cost = SetCost(
        "x",
        battery=1.0,
        parts={"checks": 0.2, "stress": 0.1, "invariants": 0.5},
        floor={"checks": 0.1, "stress": 0.05},
        states=10,
    )
    battery = rows(cost)[-1]
    assert battery["floor_s"] == 0.1 + 0.05 + 0.5
    assert battery["over_floor"] == 1.0 / 0.65
    assert rows(cost)[0]["over_floor"] == 0.2 / 0.1


def _cost(battery: float, floor: float) -> SetCost:
    """A set whose battery takes ``battery`` s against a floor of ``floor`` s (invariants free)."""
    return SetCost(
        "x", battery=battery, parts={"checks": 0.0, "stress": 0.0, "invariants": 0.0},
        floor={"checks": floor, "stress": 0.0}, states=10,
    )  # fmt: skip


def test_the_targets_are_judged_on_the_default_battery_only():
    default = BatterySettings()
    assert target_line(_cost(0.05, 0.04), default).endswith("met; within 2.5× of the floor (1.2×): met")
    slow = target_line(_cost(0.5, 0.04), default)  # a planted miss: 0.5 s and 12.5× the floor
    assert "≤ 0.1 s per set per core: NOT met" in slow and "(12.5×): NOT met" in slow
    assert slow.endswith("(recorded, not a failure: a benchmark's exit status is 0)")
    quick = target_line(_cost(0.5, 0.04), BatterySettings(samples=100, sim_duration=0.5))
    assert quick.startswith("target x: not judged: battery 0.500 s, 12.5× its floor, with 100 states")
    assert "for the default battery (2000 states, 2 s runs)" in quick and "NOT met" not in quick
