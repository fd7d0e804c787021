"""``pendverify bench certify --quick``: the table's shape and finite, positive figures.  No test looks at
a time."""

from __future__ import annotations

import json
import math

from pendverify.analytic import MODELS
from pendverify.bench.certify import SetCost
from pendverify.bench.certify_report import rows
from pendverify.cli import main

PARTS = ("checks", "stress", "invariants", "battery")


def test_bench_certify_quick_prints_every_set_and_part(tmp_path, capsys):
    out = tmp_path / "certify.json"
    assert main(["bench", "certify", "--quick", "--json", str(out)]) == 0
    text = capsys.readouterr().out
    assert "floor s" in text and "over floor" in text
    for name in MODELS:
        assert f"target {name}: battery" in text
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
