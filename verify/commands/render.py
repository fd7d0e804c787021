"""``pendverify render SCENE.toml -o OUT.html``: a trajectory as a self-contained browser animation.

The scene is simulated (as ``pendverify simulate`` does), or, with
``--trajectory FILE.npz``, a saved run is loaded instead: its t, q and the
metadata's model and parameters, from which the same URDF is written again.  A run
of a Python model file is drawn only with that file given as ``--analytic FILE``:
the npz is data and never makes pendverify import what it names.
The page plays from file:// with no server and no network (``pendverify.viz``).
"""

from __future__ import annotations

import argparse

from pendverify.commands import EXAMPLE_SCENE, add_analytic_option, add_command, add_package_path_option
from pendverify.simulation.engine_names import SCENE_ENGINE_CHOICES


def register(sub) -> None:
    p = add_command(
        sub,
        "render",
        "write a self-contained HTML animation of a scene (meshcat, plays from file://)",
        [
            f"pendverify render {EXAMPLE_SCENE} -o chaos.html --trace",
            "pendverify render --trajectory run.npz -o run.html",
            "pendverify render --trajectory cart_pole.npz --analytic cart_pole/cart_pole.py -o run.html",
        ],
    )
    p.add_argument(
        "scene", nargs="?", help="a scene file (TOML) to simulate (default: none; or --trajectory)"
    )
    p.add_argument("-o", "--output", required=True, help="the HTML file to write (required)")
    p.add_argument("--trajectory", help="render a saved run (npz of `pendverify simulate -o`) instead")
    add_analytic_option(
        p, "with --trajectory, the Python model file the saved run names (a saved run never imports it)"
    )
    p.add_argument("--trace", action="store_true", help="draw the path of the tip as it moves")
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
    add_package_path_option(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from pendverify import api
    from pendverify.atomic import check_output, write_atomic
    from pendverify.commands import refuse_together
    from pendverify.commands.simulate import urdf_argument
    from pendverify.errors import InputError

    if args.scene is None and args.trajectory is None:
        raise InputError("<command line>", "scene", None, "give a scene file, or --trajectory FILE.npz")
    if args.analytic is not None and not args.trajectory:
        refuse_together(
            "--analytic", "a scene file", "a scene names its model; --analytic is for --trajectory"
        )
    if args.trajectory:
        for given, option in ((args.scene, "a scene file"), (args.engine, "--engine"), (args.urdf, "--urdf")):
            if given is not None:
                refuse_together("--trajectory", option, "give one: a saved run is drawn as it was simulated")
    check_output(args.output)
    status = 0
    if args.trajectory:
        traj = api.trajectory(args.trajectory, args.analytic)
        for note in traj.notes:
            print(f"note: {note}")
    else:
        scene = api.load_scene(args.scene)
        api.check_animation_length(scene)  # before simulating
        result = api.simulate(scene, urdf_argument(args.urdf), args.engine)
        traj = api.trajectory(result)
        if not result.passed:
            print(f"note: {traj.title}: an invariant FAILS (see `pendverify simulate {args.scene}`)")
            status = 1
    page = api.animation_page(traj, trace=args.trace)
    for note in page.notes:
        print(f"note: {note}")
    write_atomic(args.output, page.html)
    duration = traj.t[-1] - traj.t[0]
    size_mb = len(page.html.encode()) / 1e6
    print(f"animation of {traj.title} ({duration:g} s) written to {args.output} ({size_mb:.2f} MB)")
    return status
