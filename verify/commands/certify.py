"""``pendverify certify`` and ``pendverify recheck``: certificates for parameter sets."""

from __future__ import annotations

import argparse

from pendverify.atomic import check_output, check_report_output
from pendverify.certify.settings_rules import samples_option, seed_option
from pendverify.certify.sweep_limits import DEFAULT_MAX_SETS, WORKER_TIMEOUT_S
from pendverify.commands import (
    EXAMPLE_PARAMS,
    add_analytic_option,
    add_command,
    add_package_path_option,
    positive_float,
    positive_int,
    refuse_together,
    write_json_report,
)


def register(sub) -> None:
    p = add_command(
        sub,
        "certify",
        "run the full battery on a parameter set and certify it",
        [
            f"pendverify certify {EXAMPLE_PARAMS} -o certified",
            "pendverify certify --sweep double_pendulum/double_pendulum_200.toml --workers 2 -o certified",
            "pendverify certify --urdf robot.urdf --model double_pendulum --params mine.toml -o certified "
            "--key keys/pendverify-signing.key.pem",
        ],
        json="the battery's items and the verdict (with --sweep: the summary)",
    )
    p.add_argument("params_file", nargs="?", help="a parameter file (TOML) (default: none; or --sweep)")
    p.add_argument("--model", help="with --urdf: the model the URDF describes")
    add_analytic_option(p, "certify it on --urdf with --params")
    p.add_argument(
        "--urdf", help="a URDF, xacro or MJCF file to certify (or erd:NAME for example-robot-data's)"
    )
    p.add_argument("--params", dest="params_option", help="with --urdf: the parameter set it must match")
    p.add_argument("--sweep", help="a sweep file: certify many sets in parallel")
    p.add_argument(
        "--scheduler",
        help="with --sweep: a Dask scheduler address, tcp://HOST:PORT (default: local processes)",
    )
    p.add_argument(
        "--workers", type=positive_int, help="with --sweep: local worker processes (default: one per core)"
    )
    p.add_argument(
        "--worker-timeout",
        type=positive_float,
        default=WORKER_TIMEOUT_S,
        metavar="SECONDS",
        help="with --scheduler: stop the sweep when the cluster has had no worker this long "
        f"(default: {WORKER_TIMEOUT_S:g})",
    )
    p.add_argument(
        "--resume",
        action="store_true",
        help="with --sweep: keep the sets certified in -o already (digests checked), compute the rest",
    )
    p.add_argument(
        "--max-sets",
        type=positive_int,
        default=DEFAULT_MAX_SETS,
        help=f"with --sweep: refuse a sweep of more sets than this (default: {DEFAULT_MAX_SETS:,})",
    )
    p.add_argument(
        "-o", "--output", required=True, help="directory for the certificate, URDF and parameters (required)"
    )
    p.add_argument(
        "--samples",
        type=samples_option,
        help="random states for the core checks, at most PENDVERIFY_MAX_SAMPLES (default: 2000)",
    )
    p.add_argument("--seed", type=seed_option, help="seed of the state sampler (default: 20260301)")
    p.add_argument("--force", action="store_true", help="replace existing files")
    p.add_argument(
        "--key",
        help="sign the certificate(s) with this Ed25519 private key (pendverify keygen) (default: unsigned)",
    )
    p.add_argument(
        "--export",
        choices=("c", "matlab", "numpy", "casadi"),
        help="add the model's code in this language (casadi: CasADi Functions) to the bundle, verified "
        "against the URDF and signed "
        "(needs --key; one set, not --sweep) (default: none)",
    )
    add_package_path_option(p)
    p.set_defaults(func=run_certify)

    r = add_command(
        sub,
        "recheck",
        "verify a certificate's digest and re-run its battery",
        [
            "pendverify recheck certified/double_pendulum.cert.json",
            "pendverify recheck certified/double_pendulum.cert.json "
            "--trust keys/pendverify-signing.pub.pem --quiet",
        ],
        json="the re-run items, the differences and the verdict",
    )
    r.add_argument("certificate", help="a NAME.cert.json")
    r.add_argument(
        "--trust",
        help="accept only a certificate signed by this public key (PEM) (default: any signature or none)",
    )
    r.add_argument(
        "--run-embedded-code",
        action="store_true",
        help="run a certificate's embedded Python model although no --trust key vouches for it "
        "(default: refused; built-in and text models are data and always rechecked)",
    )
    r.set_defaults(func=run_recheck)


def _print_items(items) -> None:
    from pendverify.checks.evidence import item_verdict

    width = max(len(i.name) for i in items)
    print(f"{''.ljust(width)}  {'largest':>9}  {'worst error/tolerance':^20}")
    print(f"{'battery item'.ljust(width)}  {'error':>9}  {'error':>9}  {'tolerance':>9}  result")
    for i in items:
        largest = f"{i.largest_error:9.2e}" if i.largest_error is not None else f"{'—':>9}"
        print(f"{i.name.ljust(width)}  {largest}  {i.error:9.2e}  {i.tolerance:9.2e}  {item_verdict(i)}")


def run_certify(args: argparse.Namespace) -> int:
    from pendverify import api

    if args.sweep and args.params_file:
        refuse_together("--sweep", "a parameter file", "a sweep file names its own sets; give one of them")
    check_output(args.output, folder=True)  # before any work
    check_report_output(args.json)
    if args.sweep:
        if args.export:
            refuse_together("--sweep", "--export", "export one set's code: certify that set with --export")
        return _run_sweep(args)
    issued = api.certify_set(
        args.output,
        args.params_file,
        urdf=args.urdf,
        model=args.model,
        urdf_params=args.params_option,
        analytic=args.analytic,
        key=args.key,
        samples=args.samples,
        seed=args.seed,
        force=args.force,
        export=args.export,
    )
    if not args.quiet:
        _print_items(issued.items)
        for sentence in issued.not_run:
            print(sentence)
    if args.json:
        write_json_report(args, _certify_json(issued))
    if not issued.certified:
        failed = [i for i in issued.items if not i.passed]
        print(f"NOT certified: {len(failed)} item(s) failed: {', '.join(i.name for i in failed)}")
        return 1
    print(f"certified: {issued.path} (digest {issued.certificate['digest']['value'][:16]}…)")
    if "signature" in issued.certificate and not args.quiet:
        signature = issued.certificate["signature"]
        print(f"signed: {signature['envelope']} (key {signature['keyid']})")
    return 0


def _certify_json(issued) -> str:
    from pendverify.checks.evidence import item_record
    from pendverify.jsonio import to_json, versions

    return to_json(
        {
            **versions(),
            "certified": issued.certified,
            "certificate": str(issued.path) if issued.path else None,
            "digest": issued.certificate["digest"]["value"] if issued.certified else None,
            "items": [item_record(i) for i in issued.items],
        }
    )


def _run_sweep(args) -> int:
    import sys

    from pendverify import api
    from pendverify.exitcodes import BAD_INPUT, TERMINATED

    run, there = api.sweep(
        args.sweep,
        args.output,
        workers=args.workers,
        scheduler=args.scheduler,
        worker_timeout=args.worker_timeout,
        resume=args.resume,
        max_sets=args.max_sets,
        key=args.key,
        force=args.force,
        log=(lambda line: None) if args.quiet else print,
    )
    certified = run.written + run.skipped
    if run.lost:
        print(
            f"pendverify: error: {run.lost}: the sweep stopped; {certified} of {run.total} set(s) "
            f"certified in {args.output}; continue with --resume",
            file=sys.stderr,
        )
        return BAD_INPUT
    if run.interrupted:
        how = "terminated" if run.status == TERMINATED else "interrupted"
        print(
            f"pendverify: {how}: {certified} of {run.total} set(s) certified in {args.output}; "
            "continue with --resume",
            file=sys.stderr,
        )
        return run.status
    if there < certified:  # what is there, not only what was written
        print(
            f"pendverify: error: {certified} certificate(s) written or kept, but only {there} of the "
            f"sweep's are in {args.output}: files were removed during the sweep; continue with --resume",
            file=sys.stderr,
        )
        return 1
    if not args.quiet:
        print(run.summary.table())
        if args.resume:  # how many it skipped, zero included
            print(f"{run.skipped} set(s) already certified in {args.output} (--resume): not recomputed")
    if args.json:
        write_json_report(args, _sweep_json(run))
    print(f"{run.written} certificate(s) written to {args.output}")
    return 0 if certified == run.total else 1


def _sweep_json(run) -> str:
    from pendverify.jsonio import to_json, versions

    worst = {
        item: {"ratio": ratio, "set": name} for item, (ratio, _, name) in sorted(run.summary.worst.items())
    }
    return to_json(
        {
            **versions(),
            "sets": run.total,
            "computed": run.summary.sets,
            "passed": run.summary.passed,
            "failed": run.summary.failed,
            "written": run.written,
            "skipped": run.skipped,
            "certified": run.written + run.skipped == run.total,
            "worst_ratio": worst,
        }
    )


def run_recheck(args: argparse.Namespace) -> int:
    from pendverify import api

    check_report_output(args.json)
    result = api.recheck(args.certificate, args.trust, args.run_embedded_code)
    if not args.quiet:
        print(f"digest ok: {result.certificate['digest']['value']}")
        print(result.signature)
        _print_items(result.items)
        for d in result.differences:
            print(f"differs: {d}")
    if args.json:
        write_json_report(args, _recheck_json(args.certificate, result))
    if not result.passed:
        print("recheck FAILED")
        return 1
    print(f"recheck passed: {len(result.items)} items reproduce the certificate's figures")
    return 0


def _recheck_json(path: str, result) -> str:
    from pendverify.checks.evidence import item_record
    from pendverify.jsonio import to_json, versions

    return to_json(
        {
            **versions(),
            "certificate": path,
            "digest": result.certificate["digest"]["value"],
            "signature": result.signature,
            "passed": result.passed,
            "differences": result.differences,
            "items": [item_record(i) for i in result.items],
        }
    )
