"""``pendverify bench accuracy [--scene SCENE.toml] [--quick] [-o DIR]``: the work–precision benchmark;
``pendverify bench certify [--quick] [--json PATH]``: the certification battery's cost
(``pendverify.bench.certify``);
``pendverify bench explain [--quick]``: how well the diagnosis names and repairs planted errors,
and its cost (``pendverify.bench.explain``).

Without ``--scene``, the two reference systems' problems (the shipped scenes ``scenes/bench``,
``pendverify.bench.problems.shipped_problems``); with it, a user's scene, any model
(``pendverify.bench.problems.scene_problems`` says which problems and refuses what the benchmark
cannot run, exit status 2).

Writes DIR/work_precision.png (the plot), DIR/work_precision.csv (every point)
and DIR/work_precision.md (the tables), and prints the tables.  BLAS is limited
to one thread for the whole run: through threadpoolctl when installed, else
through the environment (effective only if numpy is not imported yet); the
report says which.
"""

from __future__ import annotations

import argparse

from pendverify.atomic import check_output, check_report_output
from pendverify.commands import EXAMPLE_PARAMS, EXAMPLE_SCENE, add_command, positive_int, write_json_report

BLAS_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def register(sub) -> None:
    p = add_command(
        sub,
        "bench",
        "benchmarks: work–precision of the integrators, cost of the certification battery",
        ["pendverify bench accuracy --quick -o bench-out", "pendverify bench certify --quick"],
        json="the report (bench certify)",
    )
    what = p.add_subparsers(dest="benchmark", required=True, metavar="BENCHMARK")
    a = add_command(
        what,
        "accuracy",
        "work–precision: error against wall time for each integrator and engine",
        [
            "pendverify bench accuracy --quick",
            f"pendverify bench accuracy --scene {EXAMPLE_SCENE} -o out --svg",
        ],
    )
    a.add_argument(
        "--quick", action="store_true", help="fewer tolerances and shorter runs (well under a minute)"
    )
    a.add_argument(
        "--scene",
        default=None,
        help="benchmark this scene (any model, a model file with its params and URDF) "
        "instead of the problems of the two reference systems (default: those problems)",
    )
    a.add_argument("-o", "--output", default="bench-out", help="output folder")
    a.add_argument("--svg", action="store_true", help="also write the plot as SVG")
    a.set_defaults(func=run)
    c = add_command(
        what,
        "certify",
        "the certification battery's cost per parameter set on one core: its parts and their floor",
        [
            "pendverify bench certify --quick",
            f"pendverify bench certify --params {EXAMPLE_PARAMS} --json bench.json",
        ],
        json="every figure",
    )
    c.add_argument("--quick", action="store_true", help="100 states, short simulations, one run each")
    c.add_argument(
        "--repeats",
        type=positive_int,
        default=None,
        help="runs per figure, least kept (default: 7; 1 with --quick)",
    )
    c.add_argument(
        "--params",
        action="append",
        metavar="FILE",
        help="a parameter set to measure (repeat for more; default: each built-in model's own set)",
    )
    c.set_defaults(func=run_certify)
    e = add_command(
        what,
        "explain",
        "the diagnosis on a corpus of planted errors in every shipped model: named, repaired, time",
        ["pendverify bench explain --quick", "pendverify bench explain"],
    )
    e.add_argument(
        "--quick", action="store_true", help="a seeded sample: up to 2 planted errors per operator and model"
    )
    e.set_defaults(func=run_explain)


def limit_blas() -> tuple[object, str]:
    """(a context to hold for the run, how BLAS was limited to one thread)."""
    import contextlib
    import os
    import sys

    numpy_loaded = "numpy" in sys.modules
    for name in BLAS_VARIABLES:
        os.environ[name] = "1"
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:
        how = "1 (environment)" if not numpy_loaded else "not limited (numpy loaded first, no threadpoolctl)"
        return contextlib.nullcontext(), how
    return threadpool_limits(limits=1), "1 (threadpoolctl)"


def run(args: argparse.Namespace) -> int:
    check_output(args.output, folder=True)
    guard, blas = limit_blas()
    with guard:
        from pathlib import Path

        from pendverify import api
        from pendverify.atomic import write_atomic
        from pendverify.bench.plot import render
        from pendverify.bench.report import fraction, ratios, to_csv, to_markdown

        log = (lambda msg: None) if args.quiet else (lambda msg: print(msg, flush=True))
        results = api.bench_accuracy(args.quick, args.scene, log=log, blas=blas)
        out = Path(args.output)
        markdown = to_markdown(results)
        write_atomic(out / "work_precision.csv", to_csv(results))
        write_atomic(out / "work_precision.md", markdown)
        write_atomic(out / "work_precision.png", render(results, "png"))
        if args.svg:
            write_atomic(out / "work_precision.svg", render(results, "svg"))
    if not args.quiet:
        print()
        print(markdown)
    for name, (r, rm, met) in ratios(results).items():
        target = "1/8" if name == "single" else "1/50"
        print(
            f"generated fast path / scipy DOP853 + Pinocchio aba (same run), {name}: {fraction(r)} (min), "
            f"{fraction(rm)} (median); "
            f"target ≤ {target}: {'met' if met else 'NOT met'}"
        )
    print(f"written: {out}/work_precision.png, .csv, .md")
    return 0


def run_explain(args: argparse.Namespace) -> int:
    """``bench explain``: the corpus of planted errors, diagnosed, on one core."""
    guard, _ = limit_blas()
    with guard:
        from pendverify import api
        from pendverify.bench.explain_report import table

        text = table(api.bench_explain(args.quick))
    lines = text.splitlines()
    print("\n".join(lines[-3:]) if args.quiet else text)  # the totals, confirmed, clean and time
    return 0


def run_certify(args: argparse.Namespace) -> int:
    """``bench certify``: the battery per set, its parts and their floor, in one run."""
    check_report_output(args.json)
    guard, blas = limit_blas()
    with guard:
        import json
        import os
        import platform

        import numpy as np
        import pinocchio

        from pendverify import api
        from pendverify.bench.certify_report import table, to_json
        from pendverify.bench.timing import cpu_model

        costs, settings, repeats = api.bench_certify(args.params, args.quick, args.repeats)
    lines = table(costs, settings, repeats, blas).splitlines()
    print("\n".join(line for line in lines if line.startswith("target ")) if args.quiet else "\n".join(lines))
    if args.json:
        machine = {
            "cpu": cpu_model(),
            "cores": os.cpu_count(),
            "blas_threads": blas,
            "python": platform.python_version(),
            "numpy": np.__version__,
            "pinocchio": pinocchio.__version__,
        }
        text = json.dumps(to_json(costs, settings, repeats, machine), indent=2)
        write_json_report(args, text + "\n")
    return 0
