"""``pendverify stress``: the catalogue of hard cases, one table, exit 1 on any failure.

Prints, per case, the achieved relative error next to the tolerance used, κ(M)
raw and after diagonal scaling, and the verdict; then the simulation
invariants, the notes (refusals, warnings, failures), the near-singular trust
study against 50-digit mpmath, and the time taken.  ``--json`` writes the same
evidence atomically.
"""

from __future__ import annotations

import argparse
import time

from pendverify.commands import (
    add_analytic_option,
    add_command,
    add_package_path_option,
    add_sampling_options,
    write_json_report,
)


def register(sub) -> None:
    p = add_command(
        sub,
        "stress",
        "run the catalogue of numerically hard cases",
        [
            "pendverify stress --quick",
            "pendverify stress --case 'double pendulum g = 0' --json stress.json",
            "pendverify stress --quick --analytic cart_pole/cart_pole.py --urdf cart_pole/cart_pole.urdf "
            "--params cart_pole/cart_pole.toml",
        ],
        json="the report",
    )
    p.add_argument("--quick", action="store_true", help="fewer states and shorter horizons (same cases)")
    p.add_argument(
        "--case",
        action="append",
        metavar="NAME",
        help="run only this case (repeatable) (default: every case)",
    )
    add_sampling_options(p, samples_default=None)
    add_analytic_option(p, "run hard cases derived from its parameters' kinds; needs --urdf, --params")
    p.add_argument("--urdf", help="with --analytic: the model's URDF or xacro file")
    p.add_argument("--params", help="with --analytic: its parameter file (TOML)")
    add_package_path_option(p)
    p.set_defaults(func=run)


def _num(x, fmt=".2e") -> str:
    return "-" if x is None else format(x, fmt)


def format_table(report) -> str:
    from pendverify.checks.evidence import stress_verdict
    from pendverify.checks.report import text_table

    header = ("case", "quantity", "error", "tolerance", "ratio", "κ(M)", "κ̃(M)", "refused", "result")
    rows = [
        (
            r.name,
            r.detail,
            _num(r.error),
            _num(r.tolerance),
            _num(_margin(r), ".2g"),
            _num(r.extras["kappa_raw"], ".1e"),
            _num(r.extras["kappa_scaled"], ".1e"),
            str(r.extras["refused"]),
            stress_verdict(r),
        )
        for r in report.results
    ]
    out = text_table(header, rows)
    out.append("")
    out.append(
        "error and tolerance are relative, in diagonally scaled coordinates; κ̃(M) is κ(M) after "
        "diagonal scaling (worst over the case's states)."
    )
    invariants = [r for r in report.results if r.extras["invariant"]]
    if invariants:
        out.append("")
        out.append("invariants:")
        out += [f"  {r.name}: {r.extras['invariant']}" for r in invariants]
    notes = [r for r in report.results if r.notes]
    if notes:
        out.append("")
        out.append("notes:")
        out += [f"  {'FAIL ' if r.failed else ''}{r.name}: {'; '.join(r.notes)}" for r in notes]
    if report.evidence:
        out.append("")
        out.append("evidence:")
        out += [f"  {note}" for note in report.evidence]
    if report.notes:
        out.append("")
        out.append("not varied:")
        out += [f"  {note}" for note in report.notes]
    compared = [r for r in report.results if _margin(r) is not None]
    if compared:
        worst = max(compared, key=_margin)
        out.append("")
        out.append(
            f"worst error/tolerance {_margin(worst):.2g} ({worst.name}); largest error "
            f"{max(r.error for r in compared):.2e}; {sum(r.extras['refused'] for r in report.results)} "
            "state(s) refused"
        )
    return "\n".join(out)


def _margin(r) -> float | None:
    """error / tolerance of a case that compared something, else None."""
    if r.error is None or not r.tolerance:
        return None
    return r.error / r.tolerance


def format_study(study) -> str:
    from pendverify import api

    labels = {  # each quantity the study compares, in its column's order
        "det_closed_form": "det closed",
        "det_lu": "det LU",
        "accel_closed_form": "q̈ closed",
        "accel_aba": "q̈ ABA",
        "minv_closed_form": "M⁻¹ closed",
        "minv_pinocchio": "M⁻¹ Pinocchio",
    }
    header = ("m1 [kg]", "κ̃(M)", "guard", *labels.values())
    rows = []
    for m1 in sorted({r.m1 for r in study.rows}, reverse=True):
        group = [r for r in study.rows if r.m1 == m1]
        order = ("ok", "warn", "refuse")
        guard = max((r.level for r in group), key=order.index)
        worst = [max(getattr(r, q) for r in group) for q in labels]
        kappa = max(r.kappa_scaled for r in group)
        rows.append((f"{m1:.0e}", f"{kappa:.1e}", guard, *(f"{e:.1e}" for e in worst)))
    widths = [max(len(h), *(len(row[i]) for row in rows)) for i, h in enumerate(header)]
    out = [
        "near-singular cart, m1 → 0 at θ1 = θ2 (θ1 = 0 and 0.7, and θ2 = θ1 + 1e-12): relative error "
        "against 50-digit mpmath, worst over the states",
        "  ".join(h.ljust(w) for h, w in zip(header, widths, strict=True)),
    ]
    out.append("-" * len(out[-1]))
    out += ["  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)).rstrip() for row in rows]
    per = ", ".join(f"{labels[q]} ≥ {m:.0e}" for q, m in study.limit_per_quantity.items())
    out.append(f"trusted to {api.REFUSE_REL:g} down to m1 [kg]: {per}")
    out.append(
        f"measured trust limit (every quantity): m1 ≥ {study.measured_limit:.0e} kg; "
        f"the guard accepts m1 ≥ {study.accepted_limit:.0e} kg and refuses below; {study.zero_mass_note}, "
        f"{'refused' if study.zero_mass_refused else 'NOT refused'}"
    )
    return "\n".join(out)


def report_dict(report) -> dict:
    import dataclasses

    from pendverify.checks.evidence import stress_record
    from pendverify.jsonio import versions

    study = None
    if report.study is not None:
        s = report.study
        study = {
            "measured_limit_kg": s.measured_limit,
            "accepted_limit_kg": s.accepted_limit,
            "limit_per_quantity_kg": s.limit_per_quantity,
            "zero_mass": s.zero_mass_note,
            "zero_mass_refused": s.zero_mass_refused,
            "violations": s.violations,
            "rows": [dataclasses.asdict(r) for r in s.rows],
        }
    return {
        **versions(),
        "seed": report.seed,
        "settings": dataclasses.asdict(report.settings),
        "elapsed_s": round(report.elapsed_s, 3),
        "passed": report.passed,
        "results": [stress_record(r) for r in report.results],
        "near_singular": study,
        "evidence": report.evidence,
        "not_varied": report.notes,
    }


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from pendverify import api
    from pendverify.atomic import check_report_output
    from pendverify.errors import PendverifyError
    from pendverify.jsonio import to_json

    check_report_output(args.json)
    if args.analytic and not args.urdf:
        raise PendverifyError(
            f"{args.analytic}: give --urdf (and --params, unless the model file gives PARAMS) with --analytic"
        )
    if not args.analytic and (args.urdf or args.params):
        raise PendverifyError("--urdf and --params go with --analytic (a model file)")
    report = api.stress(
        Path(args.analytic) if args.analytic else None,
        args.urdf,
        args.params,
        quick=args.quick,
        cases=args.case,
        seed=args.seed,
    )
    seed = report.seed
    if not args.quiet:
        print(format_table(report))
        if report.study is not None:
            print()
            print(format_study(report.study))
        print()
    elapsed = time.perf_counter() - args.started
    failures = [r for r in report.results if r.failed]
    verdict = "all cases pass" if not failures else f"{len(failures)} case(s) FAIL"
    print(
        f"{len(report.results)} stress cases ({'quick' if args.quick else 'full'}, seed {seed}), "
        f"{elapsed:.1f} s: {verdict}"
    )
    if args.json:
        document = report_dict(report)
        document["elapsed_s"] = round(elapsed, 3)
        write_json_report(args, to_json(document))
    return 0 if not failures else 1
