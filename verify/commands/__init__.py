"""Subcommands of ``pendverify``: one module each, found automatically.

A module here defines ``register(subparsers)``, which adds its parser with
``add_command`` (a one-line description, examples, the defaults shown, the global
options it takes) and sets ``func`` to a function taking the parsed arguments and
returning an exit status (0 success, 1 a check or invariant failed; bad input raises a
PendverifyError, which the CLI turns into status 2; anything else is an internal error,
status 3: ``pendverify.exitcodes``).  ``func`` checks the options, calls the library
through ``pendverify.api`` (one function per command) and formats what it returns; a
command module imports nothing else of the library but formatters.  Output paths go
through ``pendverify.atomic.check_output`` (``check_report_output`` for ``--json``) before
any work.  Heavy imports, ``pendverify.api`` among them, belong inside ``func``.

The global options, accepted before or after the command's name:

* ``--debug`` (every command): on an internal error, the traceback as well;
* ``--quiet`` (the commands that give ``quiet=True``): only the verdict line and errors;
* ``--json PATH`` (the commands that give ``json=WHAT``): the report as JSON to PATH,
  or to standard output for ``-`` (``write_json_report``); the text then goes to stderr.

Internal (``__all__`` is empty): docs/reference/api.md lists what is public.
"""

from __future__ import annotations

import argparse

#: the files the help's examples name, where ``pendverify example double_pendulum double_pendulum``
#: copies them (one place for the paths several commands cite)
EXAMPLE_SCENE = "double_pendulum/damped_double_pendulum.toml"
EXAMPLE_PARAMS = "double_pendulum/double_pendulum.toml"

#: what each global option does, as its help says it
GLOBAL_HELP = {
    "debug": "on an internal error, print the traceback as well (default: off)",
    "quiet": "print only the verdict line and errors (default: off)",
    "json": "also write {what} as JSON to PATH; with - the JSON goes to standard output and the text "
    "to standard error (default: none)",
}


class HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """The help of a pendverify command: the examples kept line by line, every option's default shown.

    An option whose help already says its default is left as written; a flag shows whether it is
    given by default ("off" for ``--no-erd`` as for ``--strict``: the default is not to give it,
    never the value its ``store_false`` stores), an option without a value "none", any other the
    value argparse would give it.
    """

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        positional_required = not action.option_strings and action.nargs not in ("?", "*")
        nothing_to_default = action.nargs == 0 and action.default is argparse.SUPPRESS
        if "default" in text or positional_required or nothing_to_default:
            return text  # said already; a required positional; -h, --version
        if action.nargs == 0 and isinstance(action.const, bool):
            return f"{text} (default: {'on' if action.default == action.const else 'off'})"
        if action.default is None or action.default is argparse.SUPPRESS:
            return f"{text} (default: none)"
        return f"{text} (default: %(default)s)"


def add_global_options(
    parser: argparse.ArgumentParser,
    names=tuple(GLOBAL_HELP),
    what: str = "the report",
    top: bool = False,
    hidden: bool = False,
) -> None:
    """Add the global options ``names`` to ``parser`` (``what``: what its ``--json`` writes).

    On the top-level parser (``top``) they carry the defaults; on a command's parser they
    are SUPPRESSed, so that a value given before the command's name is not overwritten.
    ``hidden`` ones are left out of the help (a command that refuses them).
    """
    for name in names:
        help_text = argparse.SUPPRESS if hidden else GLOBAL_HELP[name].format(what=what)
        if top and name != "debug":
            help_text = (
                f"({'commands with a report' if name == 'json' else 'commands with a verdict'}) {help_text}"
            )
        if name == "json":
            default = None if top else argparse.SUPPRESS
            parser.add_argument("--json", metavar="PATH", default=default, help=help_text)
        else:
            default = False if top else argparse.SUPPRESS
            parser.add_argument(f"--{name}", action="store_true", default=default, help=help_text)


def add_command(
    sub,
    name: str,
    summary: str,
    examples: list[str],
    *,
    json: str | None = None,
    quiet: bool = True,
    details: str | None = None,
) -> argparse.ArgumentParser:
    """A command's parser, as every command's help must be.

    ``summary`` is the one-line description (also the line in ``pendverify --help``),
    ``examples`` full command lines (``pendverify NAME ...``) shown in the help's epilog,
    ``json`` what ``--json`` writes (None: the command takes no ``--json``), ``quiet``
    whether it takes ``--quiet``, ``details`` an optional paragraph after the summary.
    """
    if "\n" in summary or not summary.strip():
        raise ValueError(f"{name}: the summary must be one line")
    parser = sub.add_parser(
        name,
        help=summary,
        description=summary if details is None else f"{summary}\n\n{details}",
        epilog="examples:\n" + "\n".join(f"  {line}" for line in examples),
        formatter_class=HelpFormatter,
    )
    names = ("debug", *(("quiet",) if quiet else ()), *(("json",) if json else ()))
    add_global_options(parser, names, what=json or "")
    # the global options it does not take are parsed too, unlisted, so that one given after the
    # command's name is refused with the same sentence as one given before it (cli.refuse_unaccepted)
    refused = tuple(name for name in GLOBAL_HELP if name not in names)
    add_global_options(parser, refused, hidden=True)
    parser.set_defaults(accepts=frozenset(names), prog=parser.prog)
    return parser


def write_json_report(args: argparse.Namespace, text: str) -> None:
    """``--json``: ``text`` to the file ``args.json`` (atomically, then "report written to" unless
    ``--quiet``), or with ``-`` to the standard output the command started with (``args.stdout``;
    the CLI sends the command's text to standard error meanwhile)."""
    from pendverify.atomic import STDOUT, write_atomic

    if args.json == STDOUT:
        args.stdout.write(text)
        args.stdout.flush()
        return
    write_atomic(args.json, text)
    if not args.quiet:
        print(f"report written to {args.json}")


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


def state_count(text: str) -> int:
    """A number of random states from 0 to the sample limit (``PENDVERIFY_MAX_SAMPLES``)."""
    from pendverify.simulation.limits import MAX_SAMPLES_VARIABLE, max_samples

    value = non_negative_int(text)
    limit = max_samples()
    if value > limit:
        raise argparse.ArgumentTypeError(
            f"{value:,} states exceed the limit of {limit:,} (raise it with {MAX_SAMPLES_VARIABLE})"
        )
    return value


def positive_float(text: str) -> float:
    """A finite number > 0, for options such as a tolerance."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not (value > 0 and value < float("inf")):
        raise argparse.ArgumentTypeError(f"{value} must be a finite number > 0")
    return value


def add_sampling_options(parser: argparse.ArgumentParser, samples_default: int | None) -> None:
    """``--seed N`` (the state sampler's seed) and, unless ``samples_default`` is None,
    ``--samples N`` (random states per model; ``samples_default`` is what the help says)."""
    if samples_default is not None:
        parser.add_argument(
            "--samples",
            type=state_count,
            default=None,
            help=f"random states per model (default: {samples_default})",
        )
    parser.add_argument(
        "--seed", type=non_negative_int, default=None, help="seed of the state sampler (default: 20260301)"
    )


def add_model_option(parser, default: str = "both reference systems") -> None:
    """``--model NAME``: one of the built-in models (``pendverify.analytic.MODELS``, whose names this
    help lists for the reader); ``default`` says what runs without it."""
    parser.add_argument("--model", help=f"double_pendulum or cart_double_pendulum (default: {default})")


def add_analytic_option(parser, what: str) -> None:
    """``--analytic FILE``: a model file, as ``check --analytic`` takes it; ``what`` says what it does."""
    parser.add_argument(
        "--analytic",
        metavar="FILE",
        help="your own closed-form model file (as check --analytic; `pendverify example cart_pole DIR` "
        f"copies one): {what}",
    )


def add_package_path_option(parser) -> None:
    """``--package-path DIR`` (repeatable): folders holding ROS packages, for ``$(find PKG)`` and
    ``package://PKG/...`` (``pendverify.robot.packages``); the CLI enters them around the command."""
    parser.add_argument(
        "--package-path",
        action="append",
        metavar="DIR",
        help="a folder holding ROS packages (or one package), searched for $(find PKG) and package://PKG/... "
        "before ROS_PACKAGE_PATH and AMENT_PREFIX_PATH; repeatable (default: none)",
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


__all__: list[str] = []
