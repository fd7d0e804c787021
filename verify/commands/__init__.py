"""Subcommands of ``pendverify``: one module each, found automatically.

A module here defines ``register(subparsers)``, which adds its parser and sets
``func`` to a function taking the parsed arguments and returning an exit status
(0 success, 1 a check or invariant failed; bad input raises a PendverifyError,
which the CLI turns into status 2; anything else is an internal error, status 3:
``pendverify.exitcodes``).  Output paths go through ``pendverify.atomic.check_output``
before any work.  Heavy imports belong inside ``func``.
"""

from __future__ import annotations

import argparse


def _int_at_least(minimum: int, text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if value < minimum:
        raise argparse.ArgumentTypeError(f"{value} must be ≥ {minimum}")
    return value


def positive_int(text: str) -> int:
    return _int_at_least(1, text)


def non_negative_int(text: str) -> int:
    return _int_at_least(0, text)


def positive_float(text: str) -> float:
    """A finite number > 0, for options such as a tolerance."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not (value > 0 and value < float("inf")):
        raise argparse.ArgumentTypeError(f"{value} must be a finite number > 0")
    return value


def add_analytic_option(parser, what: str) -> None:
    """``--analytic FILE``: a model file, as ``check --analytic`` takes it; ``what`` says what it does."""
    parser.add_argument(
        "--analytic",
        metavar="FILE",
        help=f"your own closed-form model file (as check --analytic; see examples/cart_pole.py): {what}",
    )


def refuse_together(first: str, second: str, rule: str):
    """Refuse two options given together (exit status 2), naming both and the rule."""
    from pendverify.errors import OptionConflictError

    raise OptionConflictError(f"{first} with {second}: {rule}")


def builtin_models(model: str | None, analytic: str | None) -> list[str]:
    """The built-in models that --model names (all when omitted; none with --analytic).

    Refuses --model together with --analytic, and unknown names, with one-line errors.
    """
    from pendverify.analytic import MODELS
    from pendverify.errors import PendverifyError, UnknownNameError

    if analytic and model:
        raise PendverifyError("give either --model (a built-in model) or --analytic (a model file), not both")
    if analytic:
        return []
    names = [model] if model else list(MODELS)
    for name in names:
        if name not in MODELS:
            raise UnknownNameError("model", name, tuple(MODELS))
    return names
