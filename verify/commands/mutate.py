"""``pendverify mutate``: how many single-term mutants of a closed form do the checks catch?"""

from __future__ import annotations

import argparse

from pendverify.commands import builtin_models, non_negative_int


def register(sub) -> None:
    p = sub.add_parser(
        "mutate",
        help="mutation sensitivity: mutate the closed forms, run the checks, report the detection rate",
    )
    p.add_argument("--model", help="double_pendulum or cart_double_pendulum (default: both)")
    p.add_argument("--analytic", metavar="FILE", help="your own model file instead (with --urdf, --params)")
    p.add_argument("--urdf", help="the URDF (or xacro, MJCF) of --analytic")
    p.add_argument("--params", help="the parameter file of --analytic")
    p.add_argument(
        "--samples", type=non_negative_int, default=None, help="random states per model (default 40)"
    )
    p.add_argument("--seed", type=non_negative_int, default=None, help="seed of the state sampler")
    p.add_argument(
        "--all-checks",
        action="store_true",
        help="run every check on every mutant (slower) instead of stopping at the first that fails",
    )
    p.add_argument(
        "--method",
        action="append",
        metavar="NAME",
        help="mutate only this closed form (e.g. mass_matrix); repeatable",
    )
    p.add_argument("--json", help="also write the mutants and their verdicts as JSON to this path")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:

    from pendverify.atomic import check_output, write_atomic
    from pendverify.checks.sampling import DEFAULT_SEED
    from pendverify.checks.targets import default_target, plugin_target
    from pendverify.errors import PendverifyError
    from pendverify.jsonio import to_json
    from pendverify.symbolic.mutate import DEFAULT_MUTATION_STATES, run_mutation
    from pendverify.symbolic.mutation_report import format_report

    check_output(args.json)
    names = builtin_models(args.model, args.analytic)
    if args.analytic:
        targets = [plugin_target(args.analytic, args.urdf, args.params)]
    elif args.urdf or args.params:
        raise PendverifyError("--urdf and --params go with --analytic; built-in models use their defaults")
    else:
        targets = [default_target(n) for n in names]
    samples = DEFAULT_MUTATION_STATES if args.samples is None else args.samples
    seed = DEFAULT_SEED if args.seed is None else args.seed
    methods = tuple(args.method) if args.method else None
    reports = [run_mutation(t, samples, seed, args.all_checks, methods) for t in targets]
    print("\n\n".join(format_report(r) for r in reports))
    if args.json:
        write_atomic(args.json, to_json([r.as_dict() for r in reports]))
        print(f"report written to {args.json}")
    return 0 if all(r.passed for r in reports) else 1
