"""Command line of pendverify: one subcommand per module in ``pendverify.commands``.

``main`` returns the exit status of the contract in ``pendverify.exitcodes``: 0 all
good, 1 a verification failed, 2 bad input or usage (one line naming the file, key,
value and rule), 3 an internal error (a bug: one line, the traceback with
``--debug``), 130 interrupted.  Text goes out as UTF-8 whatever the locale.
"""

from __future__ import annotations

import argparse
import importlib
import os
import pkgutil
import sys
import time
import traceback

from pendverify import __version__, commands


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="pendverify",
        description="Check hand-derived pendulum dynamics against their URDF in Pinocchio.",
        epilog="exit status: 0 passed, 1 a verification failed, 2 bad input or usage, "
        "3 internal error (a bug), 130 interrupted",
    )
    parser.add_argument("--version", action="version", version=f"pendverify {__version__}")
    parser.add_argument(
        "--debug", action="store_true", help="on an internal error, print the traceback as well"
    )
    sub = parser.add_subparsers(dest="command", required=True)
    for info in sorted(pkgutil.iter_modules(commands.__path__), key=lambda m: m.name):
        if not info.name.startswith("_"):
            importlib.import_module(f"{commands.__name__}.{info.name}").register(sub)
    return parser


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


def main(argv: list[str] | None = None) -> int:
    started = time.perf_counter()
    utf8_streams()
    debug = False
    try:
        args = build_parser().parse_args(argv)
        args.started = started
        debug = args.debug
        return args.func(args)
    except SystemExit as exc:
        if args_parsed(exc):
            return _fail(exc, debug)
        raise  # argparse: usage errors (status 2), --help and --version (0)
    except BaseException as exc:  # the contract: every outcome is an exit status and one line
        return _fail(exc, debug)


def args_parsed(exc: SystemExit) -> bool:
    """Whether a SystemExit came from running a command (a model file exiting), not from argparse."""
    frames = traceback.extract_tb(exc.__traceback__)
    return not any(f.filename.endswith("argparse.py") for f in frames)


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
