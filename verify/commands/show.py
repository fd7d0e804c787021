"""``pendverify show``: a model's equations as SymPy reads them, or a robot description as
Pinocchio will use it (``--robot``), to confirm the reading."""

from __future__ import annotations

import argparse
import textwrap

from pendverify.commands import add_command
from pendverify.errors import PendverifyError


def register(sub) -> None:
    p = add_command(
        sub,
        "show",
        "print a model file's equations as parsed, or a robot file as Pinocchio will use it",
        [
            "pendverify show minimal_double_pendulum/minimal_double_pendulum_text.toml",
            "pendverify show cart_pole/cart_pole.py --pretty",
            "pendverify show --robot cart_pole/cart_pole.urdf",
        ],
        quiet=False,
    )
    p.add_argument(
        "model", metavar="MODEL", nargs="?", help="a model file: a text model (.toml) or Python (.py)"
    )
    p.add_argument(
        "--robot",
        metavar="FILE",
        help="a robot description (URDF, xacro, MJCF, SDFormat): each joint's frame, axis, inertia, "
        "damping and armature as Pinocchio will use them, and where each number came from",
    )
    p.add_argument("--pretty", action="store_true", help="SymPy's two-dimensional pretty form")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if args.model is None and args.robot is None:
        raise PendverifyError("pendverify show: give a MODEL file, --robot FILE, or both")
    if args.model is not None:
        _show_model(args)
    if args.robot is not None:
        if args.model is not None:
            print()
        _show_robot(args.robot)
    return 0


def _show_model(args: argparse.Namespace) -> None:
    from pathlib import Path

    import sympy as sp

    from pendverify import api

    reading = api.read_model(Path(args.model))
    cls = reading.model_cls
    kinds = ", ".join(
        f"{c} ({'angle' if a else 'position'})" for c, a in zip(cls.coordinates, cls.angular, strict=True)
    )
    print(f"model {cls.name}: coordinates {kinds}; rates {', '.join('d' + c for c in cls.coordinates)}")
    if cls.inputs or cls.disturbances:
        print(f"inputs {', '.join(cls.inputs) or '-'}; disturbances {', '.join(cls.disturbances) or '-'}")
    print(f"parameters {', '.join(reading.parameters)}")
    if reading.conventions:
        print(f"names by convention: {', '.join(reading.conventions)}")
    for method, derived, value in reading.equations:
        note = f" (derived: {derived})" if derived else ""
        if args.pretty:
            text = sp.pretty(value, use_unicode=True)
        elif isinstance(value, sp.MatrixBase):
            text = "".join(f"\n  {list(value.row(i))}" for i in range(value.rows))
        else:
            text = str(value)
        print(f"\n{method}{note} =\n{text}" if args.pretty else f"{method}{note} = {text}")


def _number(x: float) -> str:
    return f"{x + 0.0:.6g}"  # + 0.0 turns −0 into 0


def _show_robot(path: str) -> None:
    from pendverify import api

    summary = api.read_robot(path)
    count = len(summary.joints)
    print(
        f"robot {summary.source} ({summary.reader}), as Pinocchio will use it: "
        f"{count} joint{'s' if count != 1 else ''}"
    )
    print(textwrap.fill(summary.legend, 100))
    if summary.gravity is None:
        print("gravity: none in the file (the closed form's g is used, along −z)")
    else:
        g = summary.gravity
        print(f"gravity: {' '.join(_number(x) for x in g.value)} {g.unit} ({g.origin})")
    values = {id(q): " ".join(_number(x) for x in q.value) for j in summary.joints for q in j.quantities}
    width = max(values.values(), key=len, default="")
    for joint in summary.joints:
        print(f"\njoint {joint.name}: {joint.kind}, on {joint.parent}")
        for q in joint.quantities:
            print(f"  {q.name:<13}{values[id(q)]:<{len(width)}}  {q.unit:<10} {q.origin}")
    if summary.notes:
        print()
        for note in summary.notes:
            print(f"note: {note}")
