"""``pendverify sympy``: the closed forms against a Lagrangian derivation, term by term."""

from __future__ import annotations

import argparse

from pendverify.commands import add_command, add_model_option, builtin_models, write_json_report


def register(sub) -> None:
    p = add_command(
        sub,
        "sympy",
        "derive M, C, H, D, B, W from the model's energies with SymPy and compare term by term",
        [
            "pendverify sympy --model cart_double_pendulum",
            "pendverify sympy --analytic cart_pole/cart_pole.py --quiet",
        ],
        json="the comparison",
    )
    add_model_option(p)
    p.add_argument(
        "--analytic", metavar="FILE", help="your own model file instead (it must define energies())"
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from pendverify import api
    from pendverify.atomic import check_report_output
    from pendverify.jsonio import to_json
    from pendverify.symbolic.compare import format_report

    check_report_output(args.json)
    names = builtin_models(args.model, args.analytic)
    models = [Path(args.analytic)] if args.analytic else names
    reports = [report for model in models for report in api.compare_symbolic(model)]
    texts = [format_report(r) for r in reports]  # each ends with its verdict line
    print("\n".join(t.splitlines()[-1] for t in texts) if args.quiet else "\n\n".join(texts))
    if args.json:
        write_json_report(args, to_json([r.as_dict() for r in reports]))
    return 0 if all(r.passed for r in reports) else 1
