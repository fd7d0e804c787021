"""``pendverify report -o DIR``: the review page ``DIR/index.html``.

It holds, on one page, the verification table of every model the scenes
simulate (built-in or plug-in, against the scene's URDF or the one the project
writes; example-robot-data's URDFs too unless ``--no-erd``; see
``pendverify.viz.review_folder``), and for every scene its animation
(``DIR/scenes/<stem>.html``, embedded), its energy and work-balance plot
(``DIR/plots/<stem>.svg``) and its invariant results.
The check report is also written as ``DIR/report.json``.  The folder is built
beside ``DIR`` and renamed into place at the end; an existing ``DIR`` is
refused unless ``--force``.

Without ``--scenes DIR`` it reviews the scenes installed with pendverify
(``pendverify.shipped``); ``pendverify.api.review`` does the work.
"""

from __future__ import annotations

import argparse

from pendverify.commands import add_command, add_sampling_options


def register(sub) -> None:
    p = add_command(
        sub,
        "report",
        "write a review page: check table, scene animations, energy plots",
        ["pendverify report -o review", "pendverify report -o review --scenes my-scenes --no-erd --force"],
    )
    p.add_argument(
        "-o", "--output", required=True, help="the directory to write (index.html and its files) (required)"
    )
    p.add_argument(
        "--scenes",
        default=None,
        metavar="DIR",
        help="the folder of scene files (*.toml) to review (default: the scenes installed with pendverify)",
    )
    add_sampling_options(p, samples_default=400)
    p.add_argument(
        "--no-erd",
        dest="erd",
        action="store_false",
        help="skip example-robot-data's URDFs (default: off: they are checked when installed)",
    )
    p.add_argument("--trace", action="store_true", help="draw the tip's path in the animations")
    p.add_argument("--force", action="store_true", help="replace an existing output folder")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from pendverify import api
    from pendverify.atomic import check_output

    check_output(args.output, folder=True)
    options = {"samples": args.samples, "seed": args.seed}
    folder = api.review(
        args.output,
        args.scenes,
        erd=args.erd,
        trace=args.trace,
        force=args.force,
        log=(lambda line: None) if args.quiet else (lambda line: print(line, flush=True)),
        **{key: value for key, value in options.items() if value is not None},
    )
    print(f"review page written to {folder.index}")
    return 0 if folder.passed else 1
