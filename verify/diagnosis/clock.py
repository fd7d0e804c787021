"""The diagnosis's clock: the CPU time of the thread that runs it.

Every time bound of the diagnosis (``pendverify.diagnosis.explain.REPAIR_DEADLINE_S`` and the
shares of it that its searches take) is counted on this clock, not on the wall clock, so that
what a diagnosis searches, and so what it finds and whether a repair is confirmed, does not
depend on what else the machine runs: another process on the same cores stretches the wall
time, not this thread's CPU time.  On an idle machine the two agree, since the diagnosis is one
thread of Python, NumPy and Pinocchio calls (BLAS threads, on its small matrices, are not
counted).  Measurements of how long a diagnosis took (``pendverify bench explain``) stay on the
wall clock: that is what a user waits.
"""

from __future__ import annotations

import time


def now() -> float:
    """Seconds of CPU time of the calling thread, from an arbitrary origin."""
    return time.thread_time()
