"""A hard bound on an in-process call of a test, counted in CPU time: a hang fails the test.

A call that runs past its bound is a hang or unbounded work (a SymPy expression that never
finishes, a loop without an end), and ``Hang`` is raised in it, so that the test fails instead of
stalling the suite.  The bound is counted on the process's CPU time (``ITIMER_PROF``: the user and
system time of all its threads), not on the wall clock, so that other processes on the same cores
cannot make a test fail: load stretches a call's wall time, not its CPU time.  A call that waits
without working (a deadlock) spends no CPU time; a wall-clock bound ``WALL_FACTOR`` times longer
catches it, a stretch no load on a 2-core machine shared by a handful of processes comes near (a
process getting a sixth of a core takes six times its CPU time).

``Hang`` is a ``BaseException``: no ``except Exception`` in the code under test turns it into an
exit status.  Code that catches everything may still swallow it, so ``Limit.fired`` records that
the bound was reached whatever the call returned.
"""

from __future__ import annotations

import contextlib
import signal

#: the wall-clock bound of a call, in multiples of its CPU-time bound (module docstring)
WALL_FACTOR = 10


class Hang(BaseException):
    """Raised in a call that ran past its bound."""


class Limit:
    """The bound of one call: ``fired`` once it was reached."""

    def __init__(self, cpu_s: float):
        self.cpu_s, self.fired = cpu_s, False

    def describe(self) -> str:
        return f"no end within {self.cpu_s:g} s of CPU time (or {WALL_FACTOR * self.cpu_s:g} s on the clock)"

    def _expired(self, signum, frame):
        self.fired = True
        raise Hang(self.describe())


@contextlib.contextmanager
def hard_limit(cpu_s: float):
    """Run the ``with`` block with ``Hang`` raised in it past ``cpu_s`` seconds of CPU time (module
    docstring); yields its ``Limit``."""
    limit = Limit(cpu_s)
    previous = {sig: signal.signal(sig, limit._expired) for sig in (signal.SIGPROF, signal.SIGALRM)}
    signal.setitimer(signal.ITIMER_PROF, cpu_s)
    signal.setitimer(signal.ITIMER_REAL, WALL_FACTOR * cpu_s)
    try:
        yield limit
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)
        signal.setitimer(signal.ITIMER_REAL, 0)
        for sig, handler in previous.items():
            signal.signal(sig, handler)
