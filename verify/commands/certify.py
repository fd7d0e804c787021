"""``pendverify certify`` and ``pendverify recheck``: certificates for parameter sets."""

from __future__ import annotations

import argparse

from pendverify.atomic import check_output
from pendverify.commands import add_analytic_option, non_negative_int, positive_int, refuse_together

DEFAULT_MAX_SETS = 100_000  # pendverify.certify.sweep.DEFAULT_MAX_SETS, without importing NumPy here


def register(sub) -> None:
    p = sub.add_parser("certify", help="run the full battery on a parameter set and certify it")
    p.add_argument("params_file", nargs="?", help="a parameter file (TOML)")
    p.add_argument("--model", help="with --urdf: the model the URDF describes")
    add_analytic_option(p, "certify it on --urdf with --params")
    p.add_argument(
        "--urdf", help="a URDF, xacro or MJCF file to certify (or erd:NAME for example-robot-data's)"
    )
    p.add_argument("--params", dest="params_option", help="with --urdf: the parameter set it must match")
    p.add_argument("--sweep", help="a sweep file: certify many sets in parallel")
    p.add_argument("--scheduler", help="with --sweep: a Dask scheduler address, tcp://HOST:PORT")
    p.add_argument("--workers", type=positive_int, help="with --sweep: local worker processes")
    p.add_argument(
        "--resume",
        action="store_true",
        help="with --sweep: keep the sets certified in -o already (digests checked), compute the rest",
    )
    p.add_argument(
        "--max-sets",
        type=positive_int,
        default=DEFAULT_MAX_SETS,
        help=f"with --sweep: refuse a sweep of more sets than this (default {DEFAULT_MAX_SETS:,})",
    )
    p.add_argument("-o", "--output", required=True, help="directory for the certificate, URDF and parameters")
    p.add_argument("--samples", type=positive_int, help="random states for the core checks (default 2000)")
    p.add_argument("--seed", type=non_negative_int, help="seed of the state sampler")
    p.add_argument("--force", action="store_true", help="replace existing files")
    p.add_argument("--key", help="sign the certificate(s) with this Ed25519 private key (pendverify keygen)")
    p.set_defaults(func=run_certify)

    r = sub.add_parser("recheck", help="verify a certificate's digest and re-run its battery")
    r.add_argument("certificate", help="a NAME.cert.json")
    r.add_argument("--trust", help="accept only a certificate signed by this public key (PEM)")
    r.set_defaults(func=run_recheck)


def _print_items(items) -> None:
    width = max(len(i.name) for i in items)
    print(f"{''.ljust(width)}  {'largest':>9}  {'worst error/tolerance':^20}")
    print(f"{'battery item'.ljust(width)}  {'error':>9}  {'error':>9}  {'tolerance':>9}  result")
    for i in items:
        largest = f"{i.max_error:9.2e}" if i.max_error is not None else f"{'—':>9}"
        verdict = "pass" if i.passed else ("refused" if i.detail.startswith("refused:") else "FAIL")
        print(f"{i.name.ljust(width)}  {largest}  {i.error:9.2e}  {i.tolerance:9.2e}  {verdict}")


def _key(args):
    """The private key of ``--key``, loaded before any work (a bad key fails at once)."""
    from pendverify.certify.signing import load_private_key

    return load_private_key(args.key) if args.key else None


def run_certify(args: argparse.Namespace) -> int:
    from dataclasses import replace

    from pendverify.certify.battery import BatterySettings
    from pendverify.certify.issue import certification_input, issue

    if args.sweep and args.params_file:
        refuse_together("--sweep", "a parameter file", "a sweep file names its own sets; give one of them")
    check_output(args.output, folder=True)  # before any work
    if args.sweep:
        return _run_sweep(args)
    settings = BatterySettings()
    if args.samples:
        settings = replace(settings, samples=args.samples)
    if args.seed is not None:
        settings = replace(settings, seed=args.seed)
    target = certification_input(args.params_file, args.urdf, args.model, args.params_option, args.analytic)
    issued = issue(target, settings, args.output, args.force, _key(args))
    _print_items(issued.items)
    if not issued.certified:
        failed = [i for i in issued.items if not i.passed]
        print(f"NOT certified: {len(failed)} item(s) failed: {', '.join(i.name for i in failed)}")
        return 1
    print(f"certified: {issued.path} (digest {issued.certificate['digest']['value'][:16]}…)")
    if "signature" in issued.certificate:
        signature = issued.certificate["signature"]
        print(f"signed: {signature['envelope']} (key {signature['keyid']})")
    return 0


def _run_sweep(args) -> int:
    import sys

    from pendverify.certify.issue import check_sweep_names, write_sweep_certificates
    from pendverify.certify.sweep import load_sweep
    from pendverify.certify.sweep_output import prepare_output
    from pendverify.certify.sweep_run import INTERRUPTED, Workers, run_sweep

    sweep = load_sweep(args.sweep, args.max_sets)
    check_sweep_names(sweep, args.sweep)
    key = _key(args)  # a bad key fails before any work
    state = prepare_output(sweep, args.output, args.force, args.resume)

    def write(result: dict, replace: bool) -> int:
        return write_sweep_certificates(sweep, [result], args.output, args.force or replace, key)

    run = run_sweep(sweep, Workers(args.scheduler, args.workers), write, state.done, state.partial)
    certified = run.written + run.skipped
    if run.interrupted:
        print(
            f"pendverify: interrupted: {certified} of {run.total} set(s) certified in {args.output}; "
            "continue with --resume",
            file=sys.stderr,
        )
        return INTERRUPTED
    print(run.summary.table())
    if args.resume:  # how many it skipped, zero included
        print(f"{run.skipped} set(s) already certified in {args.output} (--resume): not recomputed")
    print(f"{run.written} certificate(s) written to {args.output}")
    return 0 if certified == run.total else 1


def run_recheck(args: argparse.Namespace) -> int:
    from pendverify.certify.issue import recheck

    result = recheck(args.certificate, args.trust)
    print(f"digest ok: {result.certificate['digest']['value']}")
    print(result.signature)
    _print_items(result.items)
    for d in result.differences:
        print(f"differs: {d}")
    if not result.passed:
        print("recheck FAILED")
        return 1
    print(f"recheck passed: {len(result.items)} items reproduce the certificate's figures")
    return 0
