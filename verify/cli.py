"""Command line of pendverify: one subcommand per module in ``pendverify.commands``.

``main`` returns the exit status of the contract in ``pendverify.exitcodes``: 0 all
good, 1 a verification failed, 2 bad input or usage (one line naming the file, key,
value and rule), 3 an internal error (a bug: one line, the traceback with
``--debug``), 130 interrupted, 143 terminated (SIGTERM, handled as Ctrl-C is:
``pendverify.signals``).  Text goes out as UTF-8 whatever the locale.

The global options ``--debug``, ``--quiet`` and ``--json PATH`` may come before or after
the command's name; a command refuses those it does not take (status 2).  With
``--json -`` the JSON report is the only thing on standard output: the command's text
goes to standard error.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import importlib.metadata
import os
import pkgutil
import platform
import sys
import time
import traceback

from pendverify import __version__, commands
from pendverify.atomic import STDOUT
from pendverify.commands import EXAMPLE_PARAMS, EXAMPLE_SCENE, HelpFormatter, add_global_options
from pendverify.signals import terminate_as_interrupt

EXAMPLES = (
    "pendverify check",
    "pendverify example double_pendulum double_pendulum",
    "pendverify check --model double_pendulum --samples 200 --quiet",
    "pendverify check --json - --quiet > report.json",
    f"pendverify --debug simulate {EXAMPLE_SCENE}",
    f"pendverify certify {EXAMPLE_PARAMS} -o certified",
)
#: the command modules in the order of a newcomer's path (``pendverify --help`` lists them so):
#: check a model, read it back, copy an example, simulate and look, then the deeper tools; a
#: module not named here comes after them, by name
COMMAND_ORDER = (
    "check",
    "show",
    "example",
    "simulate",
    "render",
    "report",
    "symbolic",  # sympy
    "mutate",
    "certify",  # certify, recheck
    "keygen",
    "export",
    "stress",
    "bench",
)
EXIT_STATUS = (
    "exit status: 0 passed, 1 a verification failed, 2 bad input or usage, "
    "3 internal error (a bug), 130 interrupted, 143 terminated (SIGTERM)"
)


def pinocchio_version() -> str:
    """The installed Pinocchio's version: its distribution's metadata, else the module's own."""
    try:
        return importlib.metadata.version("pin")
    except importlib.metadata.PackageNotFoundError:
        pass
    try:
        import pinocchio
    except ImportError:
        return "not installed"
    return pinocchio.__version__


def version_line() -> str:
    """``pendverify 0.1.0 (Pinocchio 4.1.0, Python 3.11.7)``."""
    return f"pendverify {__version__} (Pinocchio {pinocchio_version()}, Python {platform.python_version()})"


class VersionAction(argparse.Action):
    """``--version``: the versions of pendverify, Pinocchio and Python, looked up only when asked."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS, help=None):
        super().__init__(option_strings, dest=dest, default=default, nargs=0, help=help)

    def __call__(self, parser, namespace, values, option_string=None):
        print(version_line())
        parser.exit()


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="pendverify",
        description="Check hand-derived pendulum dynamics against their URDF in Pinocchio.",
        epilog="examples:\n" + "\n".join(f"  {line}" for line in EXAMPLES) + "\n\n" + EXIT_STATUS,
        formatter_class=HelpFormatter,
    )
    parser.add_argument(
        "--version", action=VersionAction, help="print the versions of pendverify, Pinocchio and Python"
    )
    add_global_options(parser, top=True)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in command_modules():
        importlib.import_module(f"{commands.__name__}.{name}").register(sub)
    return parser


def command_modules() -> list[str]:
    """The modules of ``pendverify.commands``, in ``COMMAND_ORDER`` and then by name."""
    found = [info.name for info in pkgutil.iter_modules(commands.__path__) if not info.name.startswith("_")]
    rank = {name: i for i, name in enumerate(COMMAND_ORDER)}
    return sorted(found, key=lambda name: (rank.get(name, len(rank)), name))


def refuse_unaccepted(parser: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    """A usage error (status 2) for a global option given before a command that does not take it."""
    accepts = getattr(args, "accepts", frozenset({"debug"}))  # set by commands.add_command
    given = {"quiet": args.quiet, "json": args.json is not None}
    for name, present in given.items():
        if present and name not in accepts:
            takes = ", ".join(f"--{n}" for n in sorted(accepts))
            what = "writes no report" if name == "json" else "has no verdict line to keep"
            prog = getattr(args, "prog", f"pendverify {args.command}")
            parser.error(f"--{name}: `{prog}` {what}; it takes {takes}")


def utf8_streams() -> None:
    """Write stdout and stderr as UTF-8 (the reports hold θ, κ̃, ·) whatever the locale says.

    A path the OS gave in bytes the locale cannot decode (``θ.urdf`` under ``LC_ALL=POSIX``)
    is written back as those same bytes (surrogateescape), not as an error.
    """
    for stream in (sys.stdout, sys.stderr):
        reconfigure = getattr(stream, "reconfigure", None)
        utf8 = (stream.encoding or "").lower().replace("-", "") == "utf8"
        if reconfigure is not None and not (utf8 and stream.errors == "surrogateescape"):
            stream.flush()
            reconfigure(encoding="utf-8", errors="surrogateescape")


def parse(argv: list[str] | None) -> argparse.Namespace:
    """The parsed command line; argparse exits on a usage error (2), --help and --version (0)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:  # `pendverify` alone: the commands, then the usage error (status 2)
        parser.print_help(sys.stderr)
        parser.exit(2, "\npendverify: error: give a command (`pendverify COMMAND --help`: what it takes)\n")
    refuse_unaccepted(parser, args)
    return args


def main(argv: list[str] | None = None) -> int:
    with terminate_as_interrupt():  # SIGTERM stops a command as Ctrl-C does (status 143)
        return _main(argv)


def _main(argv: list[str] | None) -> int:
    started = time.perf_counter()
    utf8_streams()
    try:
        args = parse(argv)
    except SystemExit:
        raise  # argparse's own exits: usage errors (status 2), --help and --version (0)
    except BaseException as exc:  # a bug in a parser, or Ctrl-C while building them
        return _fail(exc, debug=False)
    args.started = started
    args.stdout = sys.stdout  # where --json - writes; the text goes to stderr meanwhile
    text_to_stderr = (
        contextlib.redirect_stdout(sys.stderr) if args.json == STDOUT else contextlib.nullcontext()
    )
    try:
        with text_to_stderr, _ros_packages(getattr(args, "package_path", None)):
            return args.func(args)
    except BaseException as exc:  # the contract: every outcome is an exit status and one line
        return _fail(exc, args.debug)


def _ros_packages(folders: list[str] | None):
    """The ``--package-path`` folders as the setting of the command's run (``pendverify.ros_packages``)."""
    if not folders:
        return contextlib.nullcontext()
    from pendverify.api import ros_packages

    return ros_packages(*folders)


def _fail(exc: BaseException, debug: bool) -> int:
    from pendverify.exitcodes import INTERNAL_ERROR, PIPE_CLOSED, classify

    code, line = classify(exc)
    if code == PIPE_CLOSED:  # stdout's reader is gone: nothing more to say, and no flush error at exit
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return code
    sys.stdout.flush()
    if debug and code == INTERNAL_ERROR:
        traceback.print_exception(exc, file=sys.stderr)
    print(f"pendverify: {line}", file=sys.stderr, flush=True)
    return code


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
