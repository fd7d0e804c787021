"""The table and JSON of ``pendverify bench certify`` (``pendverify.bench.certify`` measures).

Targets, on the project's 2-core machine: the battery ≤ 0.1 s per set per core with
default settings, and within 2.5× of its floor.  They are judged only on a battery of the
default settings (``BatterySettings()``): ``--quick``'s 100 states and 0.5 s runs are
another battery, so its target lines give the figures and say that they are not the
target's measurement.  Met or not, the command's exit status is 0: a benchmark records
figures, it does not judge a verification.
"""

from __future__ import annotations

import math

BATTERY_TARGET = 0.1  # s per set per core
FLOOR_TARGET = 2.5  # battery / floor


def rows(cost) -> list[dict]:
    """One row per part and one for the battery: seconds and ratios."""
    out = []
    for part in ("checks", "stress", "invariants"):
        out.append(_row(cost.name, part, cost.parts[part], cost.floor.get(part)))
    invariants = cost.parts["invariants"]
    floor = cost.floor["checks"] + cost.floor["stress"] + invariants
    out.append(_row(cost.name, "battery", cost.battery, floor))
    return out


def _row(name, part, seconds, floor) -> dict:
    return {
        "set": name,
        "part": part,
        "seconds": seconds,
        "floor_s": floor,
        "over_floor": seconds / floor if floor else None,
    }


def _cell(x, fmt: str) -> str:
    return "—" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, fmt)


def _times(x) -> str:
    return _cell(x, ".1f") + ("×" if x is not None else "")


def table(costs, settings, repeats: int, blas: str) -> str:
    head = (
        "pendverify bench certify: the certification battery per parameter set on one core\n"
        f"process time, least of {repeats} runs; "
        f"{settings.samples} random states + the special ones; BLAS threads: {blas}\n"
    )
    columns = f"{'set':<24} {'part':<11} {'seconds':>9} {'floor s':>9} {'over floor':>11}"
    lines = [head, columns, "-" * len(columns)]
    for cost in costs:
        for r in rows(cost):
            name = r["set"] if r["part"] == "checks" else ""
            lines.append(
                f"{name:<24} {r['part']:<11} {r['seconds']:>9.3f} {_cell(r['floor_s'], '.3f'):>9} "
                f"{_times(r['over_floor']):>11}"
            )
    lines += [
        "",
        "floor: the bare Pinocchio calls and closed-form evaluations of the part, timed alone on its",
        "  states; the battery's floor counts the invariants' simulations at their own cost.",
    ]
    for cost in costs:
        lines.append(target_line(cost, settings))
    return "\n".join(lines)


def target_line(cost, settings) -> str:
    """One set's targets: met or NOT met for a battery of the default settings; for another
    (``--quick``), its figures and why they are not the target's measurement."""
    from pendverify.certify.battery import BatterySettings

    battery = next(r for r in rows(cost) if r["part"] == "battery")
    over = _cell(battery["over_floor"], ".1f")
    default = BatterySettings()
    if settings != default:
        return (
            f"target {cost.name}: not judged: battery {battery['seconds']:.3f} s, {over}× its floor, with "
            f"{settings.samples} states and {settings.sim_duration:g} s runs; the targets "
            f"(≤ {BATTERY_TARGET} s per set per core, ≤ {FLOOR_TARGET:g}× the floor) are for the default "
            f"battery ({default.samples} states, {default.sim_duration:g} s runs): "
            "run without --quick to judge them"
        )
    met = battery["seconds"] <= BATTERY_TARGET
    near = battery["over_floor"] is not None and battery["over_floor"] <= FLOOR_TARGET
    missed = "" if met and near else " (recorded, not a failure: a benchmark's exit status is 0)"
    return (
        f"target {cost.name}: battery {battery['seconds']:.3f} s ≤ {BATTERY_TARGET} s per set per core: "
        f"{'met' if met else 'NOT met'}; within {FLOOR_TARGET:g}× of the floor "
        f"({over}×): {'met' if near else 'NOT met'}{missed}"
    )


def to_json(costs, settings, repeats: int, machine: dict) -> dict:
    return {
        "machine": machine,
        "settings": settings.as_dict(),
        "repeats": repeats,
        "sets": [{**cost.as_dict(), "rows": rows(cost)} for cost in costs],
        "targets": {"battery_s": BATTERY_TARGET, "battery_over_floor": FLOOR_TARGET},
    }
