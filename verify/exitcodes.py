"""The exit-status contract of the ``pendverify`` command, and how an exception maps onto it.

==== =====================================================================
code meaning
==== =====================================================================
0    every check, invariant or certificate passed
1    a verification failed (a check, an invariant, a certificate)
2    bad input or usage: a file, a key, an option, an output path
3    internal error: a bug in pendverify (one line; the traceback with ``--debug``)
130  interrupted (Ctrl-C, SIGINT)
143  terminated (SIGTERM): handled as Ctrl-C is (finished work kept, temporaries removed),
     as a shell reports a command ended by SIGTERM (128 + 15)
141  the reader of standard output went away (``pendverify show X | head``): nothing printed,
     as a shell reports a command ended by SIGPIPE (128 + 13)
==== =====================================================================

An exception raised by a user's model file (``--analytic``, a scene's ``model``)
is bad input, not a bug: it is reported as the file, the line and the exception.
"""

from __future__ import annotations

import traceback

from pendverify.analytic.plugin import user_code_error
from pendverify.errors import ExcerptError, PendverifyError
from pendverify.signals import Terminated

PASSED = 0
FAILED = 1
BAD_INPUT = 2
INTERNAL_ERROR = 3
INTERRUPTED = 130  # 128 + SIGINT
PIPE_CLOSED = 141  # 128 + SIGPIPE
TERMINATED = 143  # 128 + SIGTERM

REPORT_BUGS = (
    "this is a bug in pendverify, not in your input: please report it on the project's issues "
    "with the command line (run it again with --debug for the traceback)"
)


def classify(exc: BaseException) -> tuple[int, str]:
    """(exit status, the one line to print on stderr) for an exception a command raised."""
    if isinstance(exc, Terminated):
        return TERMINATED, "terminated (SIGTERM)"
    if isinstance(exc, KeyboardInterrupt):
        return INTERRUPTED, "interrupted"
    if isinstance(exc, BrokenPipeError):
        return PIPE_CLOSED, ""
    if isinstance(exc, ExcerptError):  # one error: its headline, then the fragment and the caret
        return BAD_INPUT, f"error: {one_line(exc.headline)}\n{exc.pointer()}"
    if isinstance(exc, PendverifyError):
        return BAD_INPUT, f"error: {one_line(str(exc))}"
    user = user_code_error(exc)
    if user is not None:
        return BAD_INPUT, f"error: {one_line(str(user))}"
    where = traceback.extract_tb(exc.__traceback__)
    place = f" at {where[-1].filename}:{where[-1].lineno}" if where else ""
    return INTERNAL_ERROR, f"internal error: {type(exc).__name__}: {one_line(str(exc))}{place}; {REPORT_BUGS}"


def one_line(text: str) -> str:
    """``text`` on one line (line breaks shown as ' | '), so that stderr's error is one line."""
    return " | ".join(part.strip() for part in text.strip().splitlines() if part.strip())
