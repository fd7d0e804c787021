"""``pendverify example [NAME [DIR]]``: list the worked examples, or copy one into a folder.

The files land in DIR at the paths the manual names them by (``urdf/double_pendulum.urdf``,
``examples/...``, ``scenes/...``), so the manual's commands run unchanged inside DIR.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from pendverify.commands import add_command

DETAILS = (
    "Each example is a model written by hand (Python, and LaTeX or text where one exists), its URDF "
    "(xacro and MJCF where they exist), its parameters and a scene. They are copied to the paths the "
    "manual names them by (urdf/, examples/, scenes/, ...), so its commands run unchanged in DIR. "
    "A file already in DIR with the same content is left as it is; one with other content is not "
    "replaced unless --force is given."
)


def register(sub) -> None:
    p = add_command(
        sub,
        "example",
        "list the worked examples, or copy one into a folder, ready to run",
        [
            "pendverify example                       list the worked examples",
            "pendverify example cart_pole             what the cart_pole example holds",
            "pendverify example cart_pole my_model    copy it into my_model/, print how to run it",
        ],
        quiet=False,
        details=DETAILS,
    )
    from pendverify.worked_examples import NAMES

    p.add_argument(
        "name",
        nargs="?",
        metavar="NAME",
        help=f"the example to show or copy: {', '.join(NAMES)} (default: list them all)",
    )
    p.add_argument(
        "folder",
        nargs="?",
        metavar="DIR",
        help="the folder to copy it into, created if missing (default: only show what it holds)",
    )
    p.add_argument(
        "--force", action="store_true", help="replace files of the same names in DIR (default: refuse)"
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from pendverify import api
    from pendverify.worked_examples import next_commands

    if args.name is None:
        examples = api.worked_examples()
        width = max(len(e.name) for e in examples)
        for e in examples:
            files = ", ".join(str(f.path) for f in e.files)
            print(f"{e.name.ljust(width)}  {e.dof} dof  {e.summary}; files: {files}")
        print("copy one with: pendverify example NAME DIR")
        return 0
    example = api.worked_example(args.name)
    if args.folder is None:
        print(f"{example.name}: {example.summary} ({example.dof} dof)")
        for f in example.files:
            print(f"  {f.path!s:<48} {f.role}")
        print(f"copy it with: pendverify example {example.name} DIR")
        return 0
    written = set(api.copy_example(example.name, args.folder, force=args.force))
    print(f"{example.name}: {example.summary} ({example.dof} dof), copied into {args.folder}:")
    for f in example.files:
        path = Path(args.folder) / f.path
        kept = "" if path in written else " (already there, the same)"
        print(f"  {path!s:<48} {f.role}{kept}")
    print("run it:")
    for command in next_commands(example, args.folder):
        print(f"  {command}")
    return 0
