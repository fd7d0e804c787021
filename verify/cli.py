"""Command line of pendverify: one subcommand per module in ``pendverify.commands``.

``main`` returns the exit status: 0 all good, 1 a check failed, 2 bad input
(a PendverifyError, printed as one line naming the file, key, value and rule).
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys
import time

from pendverify import __version__, commands


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="pendverify", description="Check hand-derived pendulum dynamics against their URDF in Pinocchio."
    )
    parser.add_argument("--version", action="version", version=f"pendverify {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    for info in sorted(pkgutil.iter_modules(commands.__path__), key=lambda m: m.name):
        if not info.name.startswith("_"):
            importlib.import_module(f"{commands.__name__}.{info.name}").register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    started = time.perf_counter()
    args = build_parser().parse_args(argv)
    args.started = started
    from pendverify.errors import PendverifyError

    try:
        return args.func(args)
    except PendverifyError as exc:
        print(f"pendverify: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
