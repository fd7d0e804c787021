"""Property-based fuzz of sweep files: whatever a sweep file holds, ``certify --sweep`` keeps the
contract — status 0, 1 or 2 (never 3), no traceback, one error line for status 2.

Hypothesis writes each key of a sweep file (``model``, ``base``, ``urdf``, ``mode``, ``count``,
``seed``, ``samples``, ``duration``, ``ranges`` and its entries, an unknown key) as absent, a
valid value or a value of the wrong type or range, and now and then the whole file as garbage.
The valid values are tiny (at most 4 sets with ``--max-sets 4``, up to 3 battery states,
0.02 s per simulated effect), and the tasks run on a thread of the test's process
(``InProcessWorkers``: the sweep file is what is fuzzed, not the worker processes, which
``test_sweep_signals`` and ``test_sweep_lost_workers`` plant), so a sweep that runs is
quick. Each example has a hard bound (``HARD_LIMIT_S`` of CPU time, ``tests.hard_limit``): a
hang fails the test instead of stalling it, and load on the machine does not.
Seeded, without an example database.
"""

from __future__ import annotations

import contextlib
from concurrent.futures import ThreadPoolExecutor

import pytest
from hypothesis import HealthCheck, event, given, seed, settings
from hypothesis import strategies as st

from pendverify.certify import sweep_run
from tests.commands.test_cli_fuzz import FUZZ_SEED, PARAMS, assert_contract, workdir
from tests.hard_limit import hard_limit

pytestmark = pytest.mark.sweep  # every example certifies a fuzzed sweep file

HARD_LIMIT_S = 120

VALUES = [  # TOML values of every type, for any key
    "0",
    "-1",
    "1",
    "2.5",
    "nan",
    "inf",
    "1e300",
    "9" * 30,
    '"text"',
    '""',
    "true",
    "[1.0, 2.0]",
    "[]",
    "{ a = 1 }",
    "1979-05-27",
]
VALID = {  # a tiny sweep that runs; each example changes a few of its keys
    "model": '"double_pendulum"',
    "base": '"default"',
    "urdf": None,
    "mode": '"random"',
    "count": "2",
    "seed": "7",
    "samples": "2",
    "duration": "0.02",
    "unknown": None,
}
OTHER = {  # further values of each key, valid or not, besides the shared pool
    "model": ['"simple_pendulum"', '"nope"', '"missing.py"', '"params.toml"'],
    "base": ['"params.toml"', '"missing.toml"', '"."', '"sweep.toml"'],
    "urdf": ['"missing.urdf"', '"params.toml"'],
    "mode": ['"grid"', '"other"'],
    "count": ["1", "3", "10000000000"],
    "seed": ["0", "18446744073709551616"],
    "samples": ["1", "3", "10000000000"],
    "duration": ["1e9", "1e-300"],
    "unknown": [],
}
RANGES = [  # a range's value
    "[0.5, 2.0]",
    "[2.0, 0.5]",
    "[1.0]",
    "[0.5, 2.0, 3.0]",
    '["a", "b"]',
    "[nan, 1.0]",
    "[0.5, inf]",
    "{ min = 0.5, max = 2.0 }",
    '{ min = 0.01, max = 0.05, scale = "log", points = 2 }',
    '{ min = 0.0, max = 1.0, scale = "log" }',
    '{ min = 1.0, max = 2.0, scale = "cubic" }',
    "{ min = 1.0, max = 2.0, points = 0 }",
    "{ min = 1.0, max = 2.0, points = 1000000 }",
    "{ min = 1.0, max = 2.0, extra = 1 }",
    "{ min = 1.0 }",
]


@st.composite
def sweep_files(draw) -> bytes:
    if draw(st.integers(0, 19)) == 0:  # the whole file garbage: bytes, a BOM, broken TOML
        return draw(st.sampled_from([b"\xff\xfe\x00garbage", b"\xef\xbb\xbfmodel = ", b"[ranges\n", b""]))
    changed = draw(st.lists(st.sampled_from([*VALID, "ranges"]), max_size=2, unique=True))
    lines = []
    for key, valid in VALID.items():
        value = valid
        if key in changed:
            value = draw(st.one_of(st.none(), st.sampled_from(OTHER[key] + VALUES)))
        if value is not None:
            lines.append(f"{key} = {value}")
    if "ranges" not in changed:
        lines += ["[ranges]", "m1 = [0.5, 2.0]"]
    elif draw(st.booleans()):
        lines.append(f"ranges = {draw(st.sampled_from(VALUES))}")
    else:
        lines.append("[ranges]")
        names = draw(st.lists(st.sampled_from(["m1", "I1", "l2", "g", "nope"]), max_size=2, unique=True))
        for name in names:
            lines.append(f"{name} = {draw(st.sampled_from(RANGES + VALUES))}")
    return ("\n".join(lines) + "\n").encode()


class InProcessWorkers:
    """``sweep_run.Workers``'s interface on one thread of this process."""

    count = 1

    def __init__(self, *args):
        self.executor = ThreadPoolExecutor(max_workers=1)

    def submit(self, *args):
        return self.executor.submit(*args)

    def lost(self):
        return None

    def kill(self):
        pass

    def close(self, cancel=False):
        self.executor.shutdown(wait=True, cancel_futures=cancel)


@contextlib.contextmanager
def in_process_workers():
    real = sweep_run.Workers
    sweep_run.Workers = InProcessWorkers  # not monkeypatch: hypothesis runs many examples per test
    try:
        yield
    finally:
        sweep_run.Workers = real


@seed(FUZZ_SEED)
@settings(max_examples=40, deadline=None, database=None, suppress_health_check=[HealthCheck.too_slow])
@given(sweep=sweep_files(), resume=st.booleans())
def test_fuzz_sweep_files(sweep, resume):
    with workdir() as folder, hard_limit(HARD_LIMIT_S), in_process_workers():
        (folder / "params.toml").write_text(PARAMS)
        path = folder / "sweep.toml"
        path.write_bytes(sweep)
        out = str(folder / "out")
        argv = ["certify", "--sweep", str(path), "-o", out, "--workers", "1", "--max-sets", "4"]
        code = assert_contract([*argv, "--resume"] if resume else argv)
        event(f"exit {code}")
        if code == 0:  # it ran: again with --resume finds everything done
            assert assert_contract([*argv, "--resume"]) == 0
