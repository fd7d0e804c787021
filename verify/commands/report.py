"""``pendverify report -o DIR``: the review page ``DIR/index.html``.

It holds, on one page, the verification table of ``pendverify check`` (default
models, and example-robot-data's URDFs unless ``--no-erd``), and for every
shipped scene its animation (``DIR/scenes/<stem>.html``, embedded), its energy
and work-balance plot (``DIR/plots/<stem>.svg``) and its invariant results.
The check report is also written as ``DIR/report.json``.

The shipped scenes live in the checkout's ``scenes/`` folder, which is not part
of the installed package: ``report`` runs from a checkout (an editable
install), or is given ``--scenes DIR``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from pendverify.commands import non_negative_int

CHECKOUT_SCENES = Path(__file__).resolve().parents[2] / "scenes"


def register(sub) -> None:
    p = sub.add_parser("report", help="write a review page: check table, scene animations, energy plots")
    p.add_argument("-o", "--output", required=True, help="the directory to write (index.html and its files)")
    p.add_argument("--scenes", default=None, help=f"the folder of scenes (default: {CHECKOUT_SCENES})")
    p.add_argument("--samples", type=non_negative_int, default=None, help="random states per model")
    p.add_argument("--seed", type=non_negative_int, default=None, help="seed of the state sampler")
    p.add_argument("--no-erd", dest="erd", action="store_false", help="skip example-robot-data's URDFs")
    p.add_argument("--trace", action="store_true", help="draw the tip's path in the animations")
    p.set_defaults(func=run)


def check_report(samples: int | None, seed: int | None, erd: bool):
    """The report ``pendverify check`` prints with its default targets."""
    from pendverify.analytic import MODELS
    from pendverify.checks.sampling import DEFAULT_RANDOM_STATES, DEFAULT_SEED
    from pendverify.checks.targets import default_target, erd_targets
    from pendverify.checks.verification import build_report

    targets = [default_target(name) for name in MODELS]
    if erd:
        targets += erd_targets()
    return build_report(
        targets,
        DEFAULT_RANDOM_STATES if samples is None else samples,
        DEFAULT_SEED if seed is None else seed,
    )


def shipped_scenes(folder: str | None) -> list[Path]:
    from pendverify.errors import InputError

    path = Path(folder) if folder else CHECKOUT_SCENES
    scenes = sorted(path.glob("*.toml")) if path.is_dir() else []
    if not scenes:
        raise InputError(
            "<command line>",
            "scenes",
            str(path),
            "no scene files (*.toml) there; `report` runs from a checkout, or give --scenes DIR",
        )
    return scenes


def _shown(path: Path) -> str:
    """A scene's path relative to the working directory when it is below it."""
    try:
        return str(path.resolve().relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(path)


def run(args: argparse.Namespace) -> int:
    import time

    from pendverify.atomic import write_atomic
    from pendverify.simulation.scene import load_scene
    from pendverify.simulation.simulate import simulate
    from pendverify.viz.animation import Trajectory, render_html
    from pendverify.viz.plots import energy_plot_svg
    from pendverify.viz.review import SceneReview, review_page

    out = Path(args.output)
    paths = shipped_scenes(args.scenes)
    report = check_report(args.samples, args.seed, args.erd)
    report.elapsed_s = time.perf_counter() - args.started
    write_atomic(out / "report.json", report.to_json())
    verdict = "pass" if report.passed else "FAIL"
    print(f"checks: {len(report.results)} on {len(report.states)} model(s): {verdict}")
    reviews = []
    for path in paths:
        result = simulate(load_scene(path))
        scene = result.scene
        animation, plot = f"scenes/{path.stem}.html", f"plots/{path.stem}.svg"
        write_atomic(out / animation, render_html(Trajectory.from_run(result), trace=args.trace))
        write_atomic(out / plot, energy_plot_svg(result))
        reviews.append(
            SceneReview(
                name=scene.name,
                source=_shown(path),
                animation=animation,
                plot=plot,
                invariants=[
                    *result.invariants,
                    *([result.engine_comparison] if result.engine_comparison else []),
                ],
                passed=result.passed,
                model=scene.model,
                duration_s=scene.duration,
                notes=list(result.notes),
            )
        )
        print(f"scene {scene.name}: invariants {'pass' if result.passed else 'FAIL'}")
    index = write_atomic(out / "index.html", review_page(report, reviews))
    print(f"review page written to {index}")
    return 0 if report.passed and all(r.passed for r in reviews) else 1
