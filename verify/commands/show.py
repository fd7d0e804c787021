"""``pendverify show MODEL``: each equation of a model as SymPy reads it, to confirm the reading."""

from __future__ import annotations

import argparse

from pendverify.commands import add_command


def register(sub) -> None:
    p = add_command(
        sub,
        "show",
        "print each equation of a model file (.toml or .py) as parsed, to confirm the reading",
        [
            "pendverify show minimal_double_pendulum/minimal_double_pendulum_text.toml",
            "pendverify show cart_pole/cart_pole.py --pretty",
        ],
        quiet=False,
    )
    p.add_argument("model", metavar="MODEL", help="a model file: a text model (.toml) or Python (.py)")
    p.add_argument("--pretty", action="store_true", help="SymPy's two-dimensional pretty form")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
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
    return 0
