"""``pendverify certify`` and ``pendverify recheck``: certificates for parameter sets."""

from __future__ import annotations

import argparse

from pendverify.commands import non_negative_int, positive_int


def register(sub) -> None:
    p = sub.add_parser("certify", help="run the full battery on a parameter set and certify it")
    p.add_argument("params_file", nargs="?", help="a parameter file (TOML)")
    p.add_argument("--model", help="with --urdf: the model the URDF describes")
    p.add_argument("--urdf", help="a URDF to certify (or erd:NAME for example-robot-data's)")
    p.add_argument("--params", dest="params_option", help="with --urdf: the parameter set it must match")
    p.add_argument("--sweep", help="a sweep file: certify many sets in parallel")
    p.add_argument("--scheduler", help="with --sweep: a Dask scheduler address, tcp://HOST:PORT")
    p.add_argument("--workers", type=positive_int, help="with --sweep: local worker processes")
    p.add_argument("-o", "--output", required=True, help="directory for the certificate, URDF and parameters")
    p.add_argument("--samples", type=positive_int, help="random states for the core checks (default 2000)")
    p.add_argument("--seed", type=non_negative_int, help="seed of the state sampler")
    p.add_argument("--force", action="store_true", help="replace existing files")
    p.set_defaults(func=run_certify)

    r = sub.add_parser("recheck", help="verify a certificate's digest and re-run its battery")
    r.add_argument("certificate", help="a NAME.cert.json")
    r.set_defaults(func=run_recheck)


def _resolve_urdf(spec: str):
    from pathlib import Path

    from pendverify.errors import UrdfShapeError

    if spec.startswith("erd:"):
        from pendverify.robot.erd import double_pendulum_urdfs

        found = double_pendulum_urdfs()
        stem = spec[4:]
        if stem not in found:
            raise UrdfShapeError(spec, f"example-robot-data has no {stem!r}; it has {', '.join(found)}")
        return found[stem], f"erd_{stem}"
    path = Path(spec)
    if not path.is_file():
        raise UrdfShapeError(spec, "file not found")
    return path, path.stem


def _print_items(items) -> None:
    width = max(len(i.name) for i in items)
    print(f"{'battery item'.ljust(width)}  {'error':>9}  {'tolerance':>9}  result")
    for i in items:
        print(
            f"{i.name.ljust(width)}  {i.max_error:9.2e}  {i.tolerance:9.2e}  {'pass' if i.passed else 'FAIL'}"
        )


def run_certify(args: argparse.Namespace) -> int:
    from dataclasses import replace

    from pendverify.analytic.params import load_parameter_file
    from pendverify.certify.battery import BatterySettings, run_battery
    from pendverify.certify.certificate import build_certificate, refuse_existing, write_bundle
    from pendverify.errors import PendverifyError
    from pendverify.robot.system import PinocchioSystem
    from pendverify.robot.writer import urdf_for

    if args.sweep:
        return _run_sweep(args)
    settings = BatterySettings()
    if args.samples:
        settings = replace(settings, samples=args.samples)
    if args.seed is not None:
        settings = replace(settings, seed=args.seed)
    if args.urdf:
        path, name = _resolve_urdf(args.urdf)
        urdf = path.read_text()
        if args.params_option:
            model_name, _, params = load_parameter_file(args.params_option)
            if args.model and args.model != model_name:
                raise PendverifyError(
                    f"{args.params_option}: model is {model_name!r}, --model says {args.model!r}"
                )
        else:
            if not args.model:
                raise PendverifyError("with --urdf, name the model (--model) or give --params")
            model_name = args.model
            params = PinocchioSystem.from_urdf(model_name, urdf, source=str(path)).geometry.params
            if params is None:
                raise PendverifyError(
                    f"{path}: give --params: a {model_name} URDF alone does not fix the closed form"
                )
    elif args.params_file:
        model_name, name, params = load_parameter_file(args.params_file)
        urdf = urdf_for(params, name)
    else:
        raise PendverifyError("give a parameter file, --urdf, or --sweep")

    refuse_existing(args.output, name, args.force)
    items = run_battery(model_name, params, urdf, settings)
    _print_items(items)
    failed = [i for i in items if not i.passed]
    if failed:
        print(f"NOT certified: {len(failed)} item(s) failed: {', '.join(i.name for i in failed)}")
        return 1
    notes = PinocchioSystem.from_urdf(model_name, urdf, params.g).notes
    cert = build_certificate(name, model_name, params, urdf, settings, items, notes=notes)
    path = write_bundle(args.output, name, params, urdf, cert, force=args.force)
    print(f"certified: {path} (digest {cert['digest']['value'][:16]}…)")
    return 0


def _run_sweep(args) -> int:
    import sys

    from pendverify.analytic import PARAMETER_TYPES
    from pendverify.certify.battery import BatteryItem, BatterySettings
    from pendverify.certify.certificate import build_certificate, write_bundle
    from pendverify.certify.sweep import executor_for, load_sweep, run_sweep, summary_table

    sweep = load_sweep(args.sweep)
    executor, resource = executor_for(args.scheduler, args.workers)
    try:
        results = run_sweep(sweep, executor, progress=sys.stderr.isatty())
    finally:
        close = getattr(resource, "shutdown", None) or resource.close
        close()
    print(summary_table(results))
    written = 0
    for r in results:
        if r["error"] is None and all(i["passed"] for i in r["items"]):
            params = PARAMETER_TYPES[sweep.model].from_mapping(r["values"])
            items = [BatteryItem(**i) for i in r["items"]]
            settings = BatterySettings(**sweep.settings.as_dict())
            cert = build_certificate(r["name"], sweep.model, params, r["urdf"], settings, items)
            write_bundle(args.output, r["name"], params, r["urdf"], cert, force=args.force)
            written += 1
    print(f"{written} certificate(s) written to {args.output}")
    return 0 if written == len(results) else 1


def run_recheck(args: argparse.Namespace) -> int:
    import json

    from pendverify.analytic import PARAMETER_TYPES
    from pendverify.certify.battery import BatterySettings, run_battery
    from pendverify.certify.certificate import CertificateError, compare_items, verify_digest

    try:
        with open(args.certificate, encoding="utf-8") as fh:
            cert = json.load(fh)
    except FileNotFoundError:
        raise CertificateError(f"{args.certificate}: file not found") from None
    except json.JSONDecodeError as exc:
        raise CertificateError(f"{args.certificate}: not JSON: {exc}") from None
    verify_digest(cert, args.certificate)
    print(f"digest ok: {cert['digest']['value']}")
    params = PARAMETER_TYPES[cert["model"]].from_mapping(cert["parameters"], args.certificate, "parameters.")
    items = run_battery(cert["model"], params, cert["urdf"]["text"], BatterySettings(**cert["settings"]))
    _print_items(items)
    differences = compare_items(cert["checks"], items)
    for d in differences:
        print(f"differs: {d}")
    if differences or not all(i.passed for i in items):
        print("recheck FAILED")
        return 1
    print(f"recheck passed: {len(items)} items reproduce the certificate's figures")
    return 0
