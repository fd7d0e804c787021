"""``pendverify simulate SCENE.toml``: run a scene and check its invariants."""

from __future__ import annotations

import argparse
import math

from pendverify.commands import EXAMPLE_SCENE, add_command, add_package_path_option, write_json_report
from pendverify.simulation.engine_names import SCENE_ENGINE_CHOICES


def register(sub) -> None:
    p = add_command(
        sub,
        "simulate",
        "simulate a scene and check the physics invariants its effects imply",
        [
            f"pendverify simulate {EXAMPLE_SCENE}",
            "pendverify simulate cart_double_pendulum/cart_lqr_push.toml -o run.npz --csv --html run.html",
            f"pendverify simulate {EXAMPLE_SCENE} --engine both --json - --quiet",
        ],
        json="the run's metadata and invariant results",
    )
    p.add_argument("scene", help="a scene file (TOML)")
    p.add_argument("-o", "--output", help="write the trajectory (npz)")
    p.add_argument("--csv", action="store_true", help="also write a CSV beside the npz")
    p.add_argument(
        "--engine",
        choices=SCENE_ENGINE_CHOICES,
        help="override the scene's engine (default: the scene's)",
    )
    p.add_argument(
        "--urdf",
        help="the URDF (or xacro, MJCF) ABA integrates and the animation draws (default: the scene's urdf, "
        "or the project's URDF of the parameter set)",
    )
    p.add_argument("--html", help="also write a self-contained HTML animation (as `pendverify render`)")
    add_package_path_option(p)
    p.set_defaults(func=run)


def summary(run) -> str:
    from pendverify.checks.evidence import largest_abs

    s, integ = run.scene, run.integration
    engine = "both (ABA integrated; closed form compared)" if run.engine_comparison else run.dynamics.engine
    lines = [
        f"scene       {s.name}  ({s.source})",
        f"model       {s.model}{f' ({s.model_file})' if s.model_file else ''}, parameters {s.params_source}",
        f"engine      {engine}",
        f"integrator  {s.integrator.describe()}: {len(integ.steps_t) - 1} steps, "
        f"{integ.nfev} right-hand-side evaluations, {s.duration:g} s, {len(run.t)} samples",
        "dynamics    " + "\n            ".join(run.dynamics.terms),
    ]
    checks = run.checks
    width = max(len(c.name) for c in checks)
    lines.append("")
    lines.append(f"{''.ljust(width)}  {'largest error':^30}  {'worst error/tolerance':^32}".rstrip())
    lines.append(
        f"{'invariant'.ljust(width)}  {'relative':>9}  {'J':>9}  {'t (s)':>8}  "
        f"{'error':>9}  {'tolerance':>9}  {'t (s)':>8}  result"
    )
    for c in checks:
        verdict = "pass" if c.passed else "FAIL"
        lines.append(
            f"{c.name.ljust(width)}  {c.largest_error:9.2e}  {_joules(largest_abs(c))}  "
            f"{c.largest_at['t']:8.4g}  {c.error:9.2e}  {c.tolerance:9.2e}  {c.at['t']:8.4g}  {verdict}  "
            f"({c.detail})"
        )
    lines += [f"note: {n}" for n in run.notes]
    lines.append("all invariants hold" if run.passed else "an invariant FAILS")
    return "\n".join(lines)


def _joules(value: float) -> str:
    """The largest error in J, or a dash where errors are relative to each state's own scale."""
    return f"{value:9.2e}" if math.isfinite(value) else f"{'—':>9}"


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from pendverify import api
    from pendverify.atomic import check_output, check_report_output, write_atomic
    from pendverify.commands import refuse_together

    if args.csv and not args.output:
        refuse_together(
            "--csv", "no -o/--output", "the CSV is written beside the npz of -o; give -o FILE.npz"
        )
    csv = Path(args.output).with_suffix(".csv") if args.csv else None
    for path in (args.output, csv, args.html):
        check_output(path)
    check_report_output(args.json)
    scene = api.load_scene(args.scene)
    if args.html:
        api.check_animation_length(scene)  # before simulating
    result = api.simulate(scene, urdf_argument(args.urdf), args.engine)
    text = summary(result)
    print(text.splitlines()[-1] if args.quiet else text)  # its last line is the verdict
    say = (lambda line: None) if args.quiet else print
    if args.output:
        write_atomic(args.output, result.to_npz_bytes())
        say(f"trajectory written to {args.output}")
        if csv is not None:
            write_atomic(csv, result.to_csv())
            say(f"CSV written to {csv}")
    if args.html:
        page = api.animation_page(api.trajectory(result))
        for note in page.notes:
            say(f"note: {note}")
        write_atomic(args.html, page.html)
        say(f"animation written to {args.html}")
    if args.json:
        write_json_report(args, _json(result))
    return 0 if result.passed else 1


def _json(run) -> str:
    """The run's metadata (scene, model, engine, integrator, invariants), engine comparison, notes."""
    from pendverify.checks.evidence import invariant_record
    from pendverify.jsonio import to_json

    comparison = invariant_record(run.engine_comparison) if run.engine_comparison else None
    return to_json({**run.metadata(), "engine_comparison": comparison, "notes": run.notes})


def urdf_argument(path: str | None) -> str | None:
    """``--urdf``: an existing file, or a UserFileError naming it."""
    from pathlib import Path

    from pendverify.errors import missing_file

    if path is not None and not Path(path).is_file():
        raise missing_file(path, "robot description (--urdf)")
    return path
