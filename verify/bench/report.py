"""The benchmark's CSV (every point) and Markdown report (what the numbers say)."""

from __future__ import annotations

import csv
import io
import math

from pendverify.bench.run import Results
from pendverify.bench.workprecision import CSV_FIELDS

SINGLE_TARGET = 1 / 8  # fast path / scipy DOP853, one trajectory
ENSEMBLE_TARGET = 1 / 50  # per trajectory of the ensemble / one scipy DOP853 run
THRESHOLDS = (1e-4, 1e-7, 1e-10)
REFERENCE_MARGIN = 1000.0


def to_csv(results: Results) -> str:
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(CSV_FIELDS)
    for p in results.points:
        writer.writerow([_cell(getattr(p, f)) for f in CSV_FIELDS])
    return buf.getvalue()


def _cell(v):
    if isinstance(v, float):
        return "" if math.isnan(v) else repr(v)
    return v


def _ms(seconds: float) -> str:
    if not math.isfinite(seconds):
        return "–"
    return f"{seconds * 1e3:.3g} ms" if seconds < 10 else f"{seconds:.3g} s"


def _e(x: float) -> str:
    return "–" if not math.isfinite(x) else f"{x:.1e}"


def fraction(r: float) -> str:
    return "–" if not math.isfinite(r) or r <= 0 else f"1/{1 / r:.0f}" if r < 1 else f"{r:.2f}"


def baseline(results: Results) -> tuple[float, float] | None:
    """(min, median) seconds of one scipy DOP853 + aba run on the anchor problem at the comparison's
    tolerance: the faster of its two measurements (the sweep's point and the engine study's row)."""
    anchor = results.config.anchor
    runs = [
        (r.t_min, r.t_median) for r in results.engines if r.problem == anchor and r.engine.startswith("aba")
    ]
    s = results.single
    if s is not None and s.scipy is not None and s.scipy.setting == results.engine_tolerance:
        runs.append((s.scipy.t_min, s.scipy.t_median))
    return min(runs) if runs else None


def ratios(results: Results) -> dict:
    """The two headline ratios (min and median wall time) and whether they meet the targets."""
    out = {}
    s = results.single
    if s is not None:
        out["single"] = (
            s.ratio,
            s.ratio_median,
            s.ratio <= SINGLE_TARGET if math.isfinite(s.ratio) else False,
        )
    base, best = baseline(results), best_ensemble(results)
    if best is not None and base is not None:
        r, rm = best.per_trajectory / base[0], (best.t_median / best.size) / base[1]
        out["ensemble"] = (r, rm, r <= ENSEMBLE_TARGET)
    return out


def best_ensemble(results: Results):
    """The faster of the fast path's ensemble variants (by minimum wall time)."""
    fast = [e for e in results.ensemble if e.variant.startswith("fast path")]
    return min(fast, key=lambda e: e.t_min) if fast else None


def _header(results: Results) -> list[str]:
    m, c = results.machine, results.config
    return [
        f"# Work–precision benchmark ({c.name})",
        "",
        f"Machine: {m['cpu']}, {m['cores']} cores; BLAS threads: {m['blas_threads']}; Python {m['python']}, "
        f"numpy {m['numpy']}, scipy {m['scipy']}, Pinocchio {m['pinocchio']}, numba {m['numba']}.",
        f"Wall time: one warm-up, then the minimum and the median of {c.repeats} runs "
        "(garbage collector off; calls under 5 ms batched within a sample). "
        f"numba compile or cache load: {results.compile_seconds:.1f} s, excluded. "
        f"References: {results.reference_seconds:.1f} s. Total: {results.elapsed:.0f} s.",
        "",
    ]


def _fast_section(results: Results) -> list[str]:
    lines = ["## The fast path against scipy", ""]
    s, rs = results.single, ratios(results)
    lines += [
        "| comparison | fast path | scipy DOP853 + Pinocchio aba "
        "| ratio (min) | ratio (median) | target | met |",
        "|---|---|---|---|---|---|---|",
    ]
    if s is not None:
        f, sc = s.fast, s.scipy
        fcell = (
            f"{_ms(f.t_min)} (rtol {f.setting:g}, error {_e(f.final_error)})" if f else "target not reached"
        )
        scell = (
            f"{_ms(sc.t_min)} (rtol {sc.setting:g}, error {_e(sc.final_error)})"
            if sc
            else "target not reached"
        )
        r, rm, met = rs["single"]
        lines.append(
            f"| one trajectory, {s.problem}, T = {results.config.horizons[s.problem]:g} s, "
            f"final error ≤ {s.target:g} "
            f"| {fcell} | {scell} | {fraction(r)} | {fraction(rm)} | ≤ 1/8 | {'yes' if met else 'NO'} |"
        )
    if "ensemble" in rs:
        best, base = best_ensemble(results), baseline(results)
        r, rm, met = rs["ensemble"]
        lines.append(
            f"| ensemble of {best.size} states, per trajectory | {_ms(best.per_trajectory)} ({best.variant}) "
            f"| {_ms(base[0])} per run | {fraction(r)} | {fraction(rm)} | ≤ 1/50 "
            f"| {'yes' if met else 'NO'} |"
        )
    if results.ensemble:
        base = baseline(results)
        lines += [
            "",
            "Ensemble variants (same tolerance; error: max over the members checked against "
            "their own reference):",
            "",
            "| variant | states | wall min | wall median | per trajectory | vs one scipy + aba run "
            "| max error | checked |",
            "|---|---|---|---|---|---|---|---|",
        ]
        for e in results.ensemble:
            vs = fraction(e.per_trajectory / base[0]) if base else "–"
            lines.append(
                f"| {e.variant} | {e.size} | {_ms(e.t_min)} | {_ms(e.t_median)} | {_ms(e.per_trajectory)} "
                f"| {vs} | {_e(e.max_error)} | {e.checked} |"
            )
    return [*lines, ""]


def _engine_section(results: Results) -> list[str]:
    if not results.engines:
        return []
    tol = results.engine_tolerance
    lines = [
        f"## Dynamics engines (DOP853 at rtol = atol = {tol:g})",
        "",
        "| problem | engine | per call | wall min | wall median | nfev | time outside the RHS "
        "| final error |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in results.engines:
        per_call = "inside the kernel" if not math.isfinite(r.per_call) else f"{r.per_call * 1e6:.2f} µs"
        share = "–" if not math.isfinite(r.outside_share) else f"{100 * r.outside_share:.0f} %"
        lines.append(
            f"| {r.problem} | {r.engine} | {per_call} | {_ms(r.t_min)} | {_ms(r.t_median)} | {r.nfev} "
            f"| {share} | {_e(r.final_error)} |"
        )
    return [*lines, ""]


def _cost_section(results: Results) -> list[str]:
    lines = [
        "## What each digit costs: the cheapest measured point reaching an error",
        "",
        "Final-state error (max over components; rad, m, rad/s, m/s) for the state problems, "
        "max relative energy error for the energy-only (long) runs. "
        "Cells: wall time (min), setting (rtol, or step h in s).",
        "",
        "| problem | method | engine | " + " | ".join(f"≤ {t:g}" for t in THRESHOLDS) + " | smallest error |",
        "|---|---|---|" + "---|" * (len(THRESHOLDS) + 1),
    ]
    keys = []
    for p in results.points:
        if (p.problem, p.method, p.engine) not in keys:
            keys.append((p.problem, p.method, p.engine))
    for problem, method, engine in keys:
        pts = [
            p
            for p in results.points
            if (p.problem, p.method, p.engine) == (problem, method, engine) and p.ok and p.plotted_error > 0
        ]
        cells = []
        for t in THRESHOLDS:
            reach = [p for p in pts if p.plotted_error <= t]
            best = min(reach, key=lambda p: p.t_min) if reach else None
            cells.append(f"{_ms(best.t_min)} ({best.setting:.3g})" if best else "–")
        smallest = min((p.plotted_error for p in pts), default=math.nan)
        lines.append(f"| {problem} | {method} | {engine} | " + " | ".join(cells) + f" | {_e(smallest)} |")
    lines += [
        "",
        "scipy is not run on the energy-only problems: the fast path takes exactly scipy DOP853's steps "
        "(same tableau, initial step, error control), so its line is scipy DOP853's at a fraction "
        "of the time.",
    ]
    skipped = [p for p in results.points if not p.ok]
    if skipped:
        lines += [
            "",
            "Not measured: "
            + "; ".join(f"{p.problem} {p.method} at {p.setting:g}: {p.note}" for p in skipped),
        ]
    return [*lines, ""]


def _order_section(results: Results) -> list[str]:
    lines = [
        "## Fixed-step methods: observed order (least squares over errors in [1e-11, 1e-2])",
        "",
        "| problem | method | theory | observed | points |",
        "|---|---|---|---|---|",
    ]
    for o in results.orders:
        obs = "–" if not math.isfinite(o.observed) else f"{o.observed:.2f}"
        lines.append(f"| {o.problem} | {o.method} | {o.theory} | {obs} | {o.points} |")
    return [*lines, ""]


def _reference_section(results: Results) -> list[str]:
    c = results.config
    lines = [
        "## References",
        "",
        f"Taylor series of the closed form in {c.digits[0]}-digit decimal arithmetic "
        f"(tolerance 1e-{c.digits[0]}), "
        f"checked against a {c.digits[1]}-digit run; bound = max |x₁ − x₂| over all dense points. "
        "The energy-only runs need no reference: the exact flow keeps E(0); "
        "energies are evaluated in mpmath.",
        "",
        "| problem | T | reference | error bound |",
        "|---|---|---|---|",
    ]
    for key, ref in results.references.items():
        lines.append(f"| {key} | {c.horizons[key]:g} s | {ref.describe()} | {ref.error_bound:.1e} |")
    small, bound = results.smallest_error(), results.largest_reference_bound()
    margin = small / bound if bound > 0 else math.inf
    verdict = "holds" if margin >= REFERENCE_MARGIN else "FAILS"
    lines += [
        "",
        f"Smallest state error plotted: {_e(small)}; largest reference bound: {_e(bound)}; "
        f"margin {margin:.1e} (≥ {REFERENCE_MARGIN:g} required: {verdict}).",
        "",
    ]
    return lines


def _invariant_section(results: Results) -> list[str]:
    lines = [
        "## The fast path passes the simulator's invariants (rtol = atol = 1e-10, on its own steps)",
        "",
        "Error and tolerance at the step with the worst error/tolerance ratio; the largest error "
        "apart (all relative to the energy scale).",
        "",
        "| problem | invariant | error | tolerance | largest error | result |",
        "|---|---|---|---|---|---|",
    ]
    for key, invariants, steps in results.invariants:
        for i in invariants:
            lines.append(
                f"| {key} | {i.name} | {i.error:.2e} | {i.tolerance:.2e} | {i.largest_error:.2e} "
                f"(t = {i.largest_at['t']:.3g} s) | {'pass' if i.passed else 'FAIL'} ({steps} steps) |"
            )
    return [*lines, ""]


def to_markdown(results: Results) -> str:
    parts = (
        _header(results)
        + _fast_section(results)
        + _engine_section(results)
        + _cost_section(results)
        + _order_section(results)
        + _reference_section(results)
        + _invariant_section(results)
        + ["Every point: `work_precision.csv`; the plot: `work_precision.png`.", ""]
    )
    return "\n".join(parts)
