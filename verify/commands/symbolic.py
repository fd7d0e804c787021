"""``pendverify sympy``: the closed forms against a Lagrangian derivation, term by term."""

from __future__ import annotations

import argparse

from pendverify.commands import builtin_models


def register(sub) -> None:
    p = sub.add_parser(
        "sympy", help="derive M, C, H, D, B, W from the model's energies with SymPy and compare term by term"
    )
    p.add_argument("--model", help="double_pendulum or cart_double_pendulum (default: both)")
    p.add_argument(
        "--analytic", metavar="FILE", help="your own model file instead (it must define energies())"
    )
    p.add_argument("--json", help="also write the comparison as JSON to this path")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:

    from pendverify.analytic import MODELS
    from pendverify.analytic.plugin import load_model_class
    from pendverify.atomic import check_output, write_atomic
    from pendverify.jsonio import to_json
    from pendverify.symbolic.compare import compare, format_report

    check_output(args.json)
    names = builtin_models(args.model, args.analytic)
    classes = [load_model_class(args.analytic)] if args.analytic else [MODELS[n] for n in names]
    reports = [compare(cls) for cls in classes]
    print("\n\n".join(format_report(r) for r in reports))
    if args.json:
        write_atomic(args.json, to_json([r.as_dict() for r in reports]))
        print(f"report written to {args.json}")
    return 0 if all(r.passed for r in reports) else 1
