"""SIGTERM handled as Ctrl-C is, and worker processes that die with their parent.

``terminate_as_interrupt()`` (the command line's, around a command) turns SIGTERM into a
``Terminated`` exception, a ``KeyboardInterrupt``: every ``finally`` and every cleanup that
a Ctrl-C runs runs for it too (a temporary file or folder is removed, finished work is
kept), and ``pendverify.exitcodes`` maps it to status 143 (128 + SIGTERM) as a shell
reports a process ended by SIGTERM.

``die_with_parent(parent)`` is for a worker process's initializer: the worker is killed
when the process that started it ends, however it ends (``kill -9`` included), so that no
worker outlives it holding the caller's standard output and error.  On Linux it asks the
kernel for SIGKILL at the parent's death (``prctl(PR_SET_PDEATHSIG)``); elsewhere a
daemon thread looks at the parent's process id every ``WATCH_S`` seconds and ends the
worker when it changes.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
from contextlib import contextmanager

WATCH_S = 0.5  # how often a worker without prctl looks for its parent
_PR_SET_PDEATHSIG = 1  # <linux/prctl.h>


class Terminated(KeyboardInterrupt):
    """The process received SIGTERM: stop as for Ctrl-C, with status 143."""


def _raise_terminated(signum, frame) -> None:
    raise Terminated


@contextmanager
def terminate_as_interrupt():
    """Within the block SIGTERM raises ``Terminated`` (the main thread only; elsewhere a no-op)."""
    try:
        previous = signal.signal(signal.SIGTERM, _raise_terminated)
    except ValueError:  # not the main thread: signals are the main thread's
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def die_with_parent(parent: int | None) -> None:
    """End this process when its parent ends: ``parent``, the process id of the one that
    started it, or None for the parent it has now (a fork server's child)."""
    if parent is None:
        parent = os.getppid()
    if sys.platform.startswith("linux") and _parent_death_signal(signal.SIGKILL):
        if os.getppid() != parent:  # the parent ended before the request was made
            os._exit(1)
        return
    threading.Thread(target=_watch, args=(parent,), name="pendverify-parent-watch", daemon=True).start()


def _parent_death_signal(signum: int) -> bool:
    """Ask Linux to send ``signum`` to this process when its parent ends; whether it agreed."""
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(_PR_SET_PDEATHSIG, int(signum), 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def _watch(parent: int) -> None:
    stop = threading.Event()
    while not stop.wait(WATCH_S):
        if os.getppid() != parent:
            os._exit(1)
