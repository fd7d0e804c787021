"""``pendverify export``: a model's closed forms as C, MATLAB, NumPy or CasADi code, verified first."""

from __future__ import annotations

import argparse

from pendverify.commands import add_command
from pendverify.errors import PendverifyError


def register(sub) -> None:
    p = add_command(
        sub,
        "export",
        "write a model's closed forms as C, MATLAB, NumPy or CasADi code, checked against the robot first",
        [
            "pendverify export model.toml --lang c --urdf robot.urdf --params robot.toml -o exported",
            "pendverify export model.toml --lang matlab --urdf robot.urdf --params robot.toml -o exported",
            "pendverify export model.toml --casadi --urdf robot.urdf --params robot.toml -o exported",
        ],
        quiet=False,
    )
    p.add_argument("model", metavar="MODEL", help="a model file (.py, .toml, or a declaration of .m files)")
    p.add_argument("--lang", choices=("c", "matlab", "numpy"), help="the language to write")
    p.add_argument(
        "--casadi",
        action="store_true",
        help="write the quantities as CasADi Functions too (NAME_casadi.py; needs the casadi package)",
    )
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="the folder to write the files into")
    p.add_argument("--urdf", metavar="FILE", help="the robot description the written code is checked against")
    p.add_argument("--params", metavar="FILE", help="the parameter file the code is checked with")
    p.add_argument("--force", action="store_true", help="replace exported files already in DIR")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from pendverify import api  # deferred on purpose: building the command line imports no Pinocchio

    if args.lang is None and not args.casadi:
        raise PendverifyError("export: give --lang c|matlab|numpy, --casadi, or both")
    results = api.export(
        args.model, args.lang, args.output, args.urdf, args.params, casadi=args.casadi, force=args.force
    )
    for result in results:
        for path in result.files:
            print(f"wrote {path}")
        print(f"{result.verification.status}: {result.verification.line}")
    return 1 if any(result.failed for result in results) else 0
