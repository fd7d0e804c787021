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
    import sympy as sp

    from pendverify.analytic.plugin import load_model_class
    from pendverify.analytic.symbolic_reading import SymbolicModel
    from pendverify.analytic.text_model import METHODS

    cls = load_model_class(args.model)
    sm = SymbolicModel.of(cls)
    spec = getattr(cls, "text_spec", None)
    derived = spec.derived if spec is not None else {}
    keys = {method: key for key, (method, _) in METHODS.items()}
    kinds = ", ".join(
        f"{c} ({'angle' if a else 'position'})" for c, a in zip(cls.coordinates, cls.angular, strict=True)
    )
    print(f"model {cls.name}: coordinates {kinds}; rates {', '.join('d' + c for c in cls.coordinates)}")
    if cls.inputs or cls.disturbances:
        print(f"inputs {', '.join(cls.inputs) or '-'}; disturbances {', '.join(cls.disturbances) or '-'}")
    print(f"parameters {', '.join(sm.parameters)}")
    for method, form in cls.written_closed_forms().items():
        value = sm.evaluate(method, form.args)
        how = derived.get(keys.get(method, ""))
        note = f" (derived: {how})" if how else ""
        if args.pretty:
            text = sp.pretty(value, use_unicode=True)
        elif isinstance(value, sp.MatrixBase):
            text = "".join(f"\n  {list(value.row(i))}" for i in range(value.rows))
        else:
            text = str(value)
        print(f"\n{method}{note} =\n{text}" if args.pretty else f"{method}{note} = {text}")
    return 0
