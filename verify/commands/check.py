"""``pendverify check``: Pinocchio against the closed forms, one table."""

from __future__ import annotations

import argparse
import shlex
import time

from pendverify.commands import (
    add_command,
    add_model_option,
    add_package_path_option,
    add_sampling_options,
    builtin_models,
    positive_float,
    write_json_report,
)


def register(sub) -> None:
    p = add_command(
        sub,
        "check",
        "compare Pinocchio with the hand-derived closed forms, one table",
        [
            "pendverify check",
            "pendverify check --model double_pendulum --samples 1000 --seed 7",
            "pendverify check --analytic cart_pole/cart_pole.py --urdf cart_pole/cart_pole.urdf "
            "--params cart_pole/cart_pole.toml",
            "pendverify check --json - --quiet > report.json",
        ],
        json="the report",
    )
    add_model_option(p, "both reference systems, and example-robot-data's URDFs")
    p.add_argument(
        "--analytic",
        metavar="FILE",
        help="your own model: a Python file (a ClosedFormModel subclass, a SymPy mechanics derivation, "
        "or the dynamics as code) or a text model (.toml: SymPy text or LaTeX, M, C, H, ... or whole "
        "equations) (`pendverify example cart_pole DIR` copies one); with --urdf, or alone for its units "
        "check (one dimension per entry, from the parameters' kinds)",
    )
    p.add_argument(
        "--urdf",
        help="a URDF, xacro, MJCF or SDFormat file to check (with --model, --analytic or --params), "
        "or erd:NAME for example-robot-data's",
    )
    p.add_argument("--params", help="a parameter file (TOML) giving the closed form")
    add_sampling_options(p, samples_default=400)
    p.add_argument(
        "--junit", metavar="PATH", help="also write the report as JUnit XML (one test case per check)"
    )
    p.add_argument(
        "--no-erd",
        dest="erd",
        action="store_false",
        help="skip example-robot-data's URDFs (default: off: they are checked when installed)",
    )
    p.add_argument(
        "--strict",
        action="store_true",
        help="warnings (a C that is not the Christoffel one, a URDF's Coulomb friction) count as failures",
    )
    p.add_argument(
        "--no-explain",
        dest="explain",
        action="store_false",
        help="do not diagnose a failing model (which entries differ, how, and a confirmed repair) "
        "(default: off: a failing model is diagnosed)",
    )
    p.add_argument(
        "--model-form-rtol",
        type=positive_float,
        default=None,
        metavar="R",
        help="largest relative size of a URDF term the closed form cannot express, e.g. a centre of "
        "mass off the reference system's joint line (default: 1e-4)",
    )
    add_package_path_option(p)
    # files given without their option: taken only to say which option each one needs (``stray_files``)
    p.add_argument("files", nargs="*", help=argparse.SUPPRESS)
    p.set_defaults(func=run)


def stray_files(files: list[str]) -> str:
    """What to type instead of ``pendverify check FILE ...``: each file behind the option its kind
    takes (``pendverify.file_kinds``), as a message for the usage error."""
    from pendverify.documents import file_kind
    from pendverify.file_kinds import KINDS

    options, unknown = [], []
    for name in files:
        kind = file_kind(name)
        flag = KINDS[kind].flag if kind in ("model", "description", "params") else ""
        if flag:
            options.append(f"{flag} {shlex.quote(name)}")
        else:
            unknown.append(name)
    head = f"check takes its files by option, not as {', '.join(files)}"
    if unknown:
        return (
            f"{head}: give each with the option for its kind: --analytic (a model file: .py or a text "
            "model), --urdf (a robot description), --params (a parameter file)"
        )
    return f"{head}: did you mean `pendverify check {' '.join(options)}`?"


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from pendverify import api
    from pendverify.atomic import check_output, check_report_output, write_atomic
    from pendverify.checks.junit import to_junit

    if args.files:
        from pendverify.errors import OptionConflictError

        raise OptionConflictError(stray_files(args.files))
    check_report_output(args.json)
    check_output(args.junit)
    builtin_models(args.model, args.analytic)  # refuses --model with --analytic, and unknown names
    given = {"samples": args.samples, "seed": args.seed, "model_form_rtol": args.model_form_rtol}
    report = api.check(
        Path(args.analytic) if args.analytic else args.model,
        args.urdf,
        args.params,
        erd=args.erd,
        strict=args.strict,
        explain=args.explain,
        **{key: value for key, value in given.items() if value is not None},
    )
    report.elapsed_s = time.perf_counter() - args.started
    table = report.table()
    print(table.splitlines()[-1] if args.quiet else table)
    if args.junit:
        write_atomic(args.junit, to_junit(report))
        if not args.quiet:
            print(f"report written to {args.junit}")
    if args.json:
        write_json_report(args, report.to_json())
    if report.passed and not report.robot_compared:
        # a model alone whose units agree is not verified: a script that forgot --urdf must not pass
        # (2, as for bad usage: pendverify.exitcodes)
        return 2
    return 0 if report.passed else 1
