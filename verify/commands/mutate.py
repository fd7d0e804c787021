"""``pendverify mutate``: how many single-term mutants of a closed form do the checks catch?"""

from __future__ import annotations

import argparse

from pendverify.commands import (
    add_command,
    add_model_option,
    add_package_path_option,
    add_sampling_options,
    builtin_models,
    write_json_report,
)


def register(sub) -> None:
    p = add_command(
        sub,
        "mutate",
        "mutation sensitivity: mutate the closed forms, run the checks, report the detection rate",
        [
            "pendverify mutate --model double_pendulum",
            "pendverify mutate --analytic cart_pole/cart_pole.py --urdf cart_pole/cart_pole.urdf "
            "--params cart_pole/cart_pole.toml --method mass_matrix --json mutants.json",
        ],
        json="the mutants and their verdicts",
    )
    add_model_option(p)
    p.add_argument("--analytic", metavar="FILE", help="your own model file instead (with --urdf, --params)")
    p.add_argument("--urdf", help="the URDF (or xacro, MJCF) of --analytic")
    p.add_argument("--params", help="the parameter file of --analytic")
    add_sampling_options(p, samples_default=40)
    p.add_argument(
        "--all-checks",
        action="store_true",
        help="run every check on every mutant (slower) instead of stopping at the first that fails",
    )
    p.add_argument(
        "--method",
        action="append",
        metavar="NAME",
        help="mutate only this closed form (e.g. mass_matrix); repeatable (default: every closed form)",
    )
    add_package_path_option(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from pendverify import api
    from pendverify.atomic import check_report_output
    from pendverify.errors import PendverifyError
    from pendverify.jsonio import to_json
    from pendverify.symbolic.mutation_report import format_report

    check_report_output(args.json)
    builtin_models(args.model, args.analytic)  # refuses --model with --analytic, and unknown names
    if (args.urdf or args.params) and not args.analytic:
        raise PendverifyError("--urdf and --params go with --analytic; built-in models use their defaults")
    options = {"samples": args.samples, "seed": args.seed}
    reports = api.mutate(
        Path(args.analytic) if args.analytic else args.model,
        args.urdf,
        args.params,
        all_checks=args.all_checks,
        methods=tuple(args.method) if args.method else None,
        **{key: value for key, value in options.items() if value is not None},
    )
    texts = [format_report(r) for r in reports]  # each ends with its verdict line
    print("\n".join(t.splitlines()[-1] for t in texts) if args.quiet else "\n\n".join(texts))
    if args.json:
        write_json_report(args, to_json([r.as_dict() for r in reports]))
    return 0 if all(r.passed for r in reports) else 1
