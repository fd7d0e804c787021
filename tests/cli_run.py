"""``pendverify.cli.main`` run in-process the way a test would run ``python -m pendverify``: exit
status and what it printed, under a hard bound (``tests.hard_limit``: a hang fails the test).

For tests whose claim is a command's status and messages, not the process boundary (signals, a
fresh interpreter's imports, pipes): a subprocess costs a fresh interpreter importing SymPy,
NumPy and Pinocchio for every command line, where in-process they are imported once per worker.
"""

from __future__ import annotations

import contextlib
import dataclasses
import io

from pendverify.cli import main
from tests.hard_limit import hard_limit

#: the most CPU time one command line of a test may take [s]: a test's command runs in a few
#: seconds, so two minutes is a hang or unbounded work
CPU_LIMIT_S = 120


@dataclasses.dataclass(frozen=True)
class Done:
    """What a command line did (the fields of ``subprocess.CompletedProcess`` the tests read)."""

    returncode: int
    stdout: str
    stderr: str


def run_main(argv: list[str], cpu_s: float = CPU_LIMIT_S) -> Done:
    """``main(argv)`` with its output captured; argparse's exits give their status."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        with hard_limit(cpu_s) as limit:
            try:
                code = main(argv)
            except SystemExit as exit_:
                code = exit_.code if isinstance(exit_.code, int) else 2
    assert not limit.fired, f"pendverify {' '.join(argv)}: {limit.describe()}"
    return Done(code, out.getvalue(), err.getvalue())
