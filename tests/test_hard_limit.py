"""``tests.hard_limit``: a busy call is stopped by its CPU-time bound, a waiting one by the clock, a
swallowed ``Hang`` is still recorded, and nothing fires once the block is left."""

from __future__ import annotations

import time

import pytest

from tests.hard_limit import WALL_FACTOR, Hang, hard_limit


def _spin(seconds: float) -> None:
    """Work for ``seconds`` of CPU time."""
    end = time.process_time() + seconds
    while time.process_time() < end:
        pass


def test_a_busy_call_is_stopped_after_its_cpu_time():
    start = time.process_time()
    with pytest.raises(Hang, match=r"0\.2 s of CPU time"), hard_limit(0.2):
        _spin(30)
    assert 0.15 <= time.process_time() - start < 5  # the kernel's CPU accounting is in clock ticks


def test_a_waiting_call_is_stopped_by_the_clock():
    start = time.monotonic()
    with pytest.raises(Hang), hard_limit(0.05):
        time.sleep(30)  # spends no CPU time: the wall-clock bound, WALL_FACTOR × 0.05 s, ends it
    assert time.monotonic() - start >= WALL_FACTOR * 0.05


def test_a_swallowed_hang_is_recorded():
    with hard_limit(0.2) as limit:
        try:
            _spin(30)
        except BaseException:
            pass
    assert limit.fired


def test_a_call_within_its_bound_is_untouched_and_nothing_fires_afterwards():
    with hard_limit(0.1) as limit:
        _spin(0.02)
    _spin(0.2)
    time.sleep(1.2)  # past the wall-clock bound of the block (1 s)
    assert not limit.fired
