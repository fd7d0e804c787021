"""Command line: ``pendverify check`` (and later ``simulate``, ``render``, ...).

Each subcommand is one function; heavy imports happen inside it.  ``main``
returns the exit status: 0 all good, 1 a check failed, 2 bad input.
"""

from __future__ import annotations

import argparse
import sys
import time

from pendverify import __version__


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value} must be at least 1")
    return value


def _non_negative_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"{value} must be ≥ 0")
    return value


def cmd_check(args: argparse.Namespace) -> int:
    from pendverify.atomic import write_atomic
    from pendverify.checks import run_checks
    from pendverify.report import Report, format_table
    from pendverify.sampling import sample_states
    from pendverify.targets import default_target, erd_targets, user_target

    if args.urdf or args.params:
        targets = [user_target(args.model, args.urdf, args.params)]
    else:
        names = [args.model] if args.model else ["double_pendulum", "cart_double_pendulum"]
        targets = [default_target(name) for name in names]
        if args.erd and (args.model in (None, "double_pendulum")):
            targets += erd_targets()
    report = Report(seed=args.seed, states={}, results=[])
    for target in targets:
        states = sample_states(target.model, args.samples, args.seed)
        report.states[target.label] = len(states)
        report.sources[target.label] = target.source
        if target.notes:
            report.notes[target.label] = target.notes
        report.results += run_checks(target.label, target.model, target.system, states, args.seed)
    report.elapsed_s = time.perf_counter() - args.started
    print(format_table(report))
    if args.json:
        write_atomic(args.json, report.to_json())
        print(f"report written to {args.json}")
    return 0 if report.passed else 1


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="pendverify", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"pendverify {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)

    check = sub.add_parser("check", help="compare Pinocchio with the hand-derived closed forms")
    check.add_argument("--model", help="double_pendulum or cart_double_pendulum")
    check.add_argument("--urdf", help="a URDF to check (with --model, or with --params)")
    check.add_argument("--params", help="a parameter file (TOML) giving the closed form")
    check.add_argument("--samples", type=_non_negative_int, default=None, help="random states per model")
    check.add_argument("--seed", type=_non_negative_int, default=None, help="seed of the state sampler")
    check.add_argument("--json", help="also write the report as JSON to this path")
    check.add_argument("--no-erd", dest="erd", action="store_false", help="skip example-robot-data's URDFs")
    check.set_defaults(func=cmd_check)
    return parser


def main(argv: list[str] | None = None) -> int:
    started = time.perf_counter()
    args = build_parser().parse_args(argv)
    args.started = started
    from pendverify.errors import PendverifyError
    from pendverify.sampling import DEFAULT_RANDOM_STATES, DEFAULT_SEED

    if getattr(args, "samples", 0) is None:
        args.samples = DEFAULT_RANDOM_STATES
    if getattr(args, "seed", 0) is None:
        args.seed = DEFAULT_SEED
    try:
        return args.func(args)
    except PendverifyError as exc:
        print(f"pendverify: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
