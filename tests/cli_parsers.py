"""The command line's parsers, walked: every subcommand (nested ones too) with its parser."""

from __future__ import annotations

import argparse


def subcommands(parser: argparse.ArgumentParser, prefix: tuple[str, ...] = ()):
    """(command path, parser) for every subcommand under ``parser``, depth first
    (``("bench",)``, then ``("bench", "accuracy")``, ...)."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield (*prefix, name), sub
                yield from subcommands(sub, (*prefix, name))
