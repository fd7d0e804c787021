"""The table and JSON of ``pendverify bench certify`` (``pendverify.bench.certify`` measures).

Targets (issue 15, on the project's 2-core machine): the battery ≤ 0.2 s per set per
core with default settings, and within 4× of its floor.
"""

from __future__ import annotations

import math

BATTERY_TARGET = 0.2  # s per set per core
FLOOR_TARGET = 4.0  # battery / floor


def rows(cost) -> list[dict]:
    """One row per part and one for the battery: seconds and ratios."""
    out = []
    for part in ("checks", "stress", "invariants"):
        batch, floor, per_state = cost.batch[part], cost.floor.get(part), cost.per_state.get(part)
        out.append(_row(cost.name, part, batch, floor, per_state))
    invariants = cost.batch["invariants"]
    floor = cost.floor["checks"] + cost.floor["stress"] + invariants
    per_state = cost.per_state["checks"] + cost.per_state["stress"] + invariants
    out.append(_row(cost.name, "battery", cost.battery, floor, per_state))
    return out


def _row(name, part, batch, floor, per_state) -> dict:
    return {
        "set": name,
        "part": part,
        "batch_s": batch,
        "floor_s": floor,
        "batch_over_floor": batch / floor if floor else None,
        "per_state_s": per_state,
        "per_state_over_batch": per_state / batch if per_state is not None and batch > 0 else None,
    }


def _cell(x, fmt: str) -> str:
    return "—" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, fmt)


def _times(x) -> str:
    return _cell(x, ".1f") + ("×" if x is not None else "")


def table(costs, settings, repeats: int, reference_repeats: int, blas: str) -> str:
    head = (
        "pendverify bench certify: the certification battery per parameter set on one core\n"
        f"process time, least of {repeats} runs (per-state path: {reference_repeats}); "
        f"{settings.samples} random states + the special ones; BLAS threads: {blas}\n"
    )
    columns = f"{'set':<24} {'part':<11} {'batch s':>9} {'floor s':>9} {'batch/floor':>12} "
    columns += f"{'per-state s':>12} {'per-state/batch':>16}"
    lines = [head, columns, "-" * len(columns)]
    for cost in costs:
        for r in rows(cost):
            name = r["set"] if r["part"] == "checks" else ""
            over_floor = _times(r["batch_over_floor"])
            speedup = _times(r["per_state_over_batch"])
            lines.append(
                f"{name:<24} {r['part']:<11} {r['batch_s']:>9.3f} {_cell(r['floor_s'], '.3f'):>9} "
                f"{over_floor:>12} {_cell(r['per_state_s'], '.3f'):>12} {speedup:>16}"
            )
    lines += [
        "",
        "floor: the bare Pinocchio calls and closed-form evaluations of the part, timed alone on its",
        "  states; the battery's floor counts the invariants' simulations at their own cost.",
        "per-state: run_check_per_state and trust.assess state by state, as before the batch (the",
        "  battery's per-state figure adds the invariants as measured).",
    ]
    for cost in costs:
        battery = next(r for r in rows(cost) if r["part"] == "battery")
        met = battery["batch_s"] <= BATTERY_TARGET
        near = battery["batch_over_floor"] is not None and battery["batch_over_floor"] <= FLOOR_TARGET
        lines.append(
            f"target {cost.name}: battery {battery['batch_s']:.3f} s ≤ {BATTERY_TARGET} s per set per core: "
            f"{'met' if met else 'NOT met'}; within {FLOOR_TARGET:g}× of the floor "
            f"({_cell(battery['batch_over_floor'], '.1f')}×): {'met' if near else 'NOT met'}"
        )
    return "\n".join(lines)


def to_json(costs, settings, repeats: int, reference_repeats: int, machine: dict) -> dict:
    return {
        "machine": machine,
        "settings": settings.as_dict(),
        "repeats": repeats,
        "reference_repeats": reference_repeats,
        "sets": [{**cost.as_dict(), "rows": rows(cost)} for cost in costs],
        "targets": {"battery_s": BATTERY_TARGET, "battery_over_floor": FLOOR_TARGET},
    }
