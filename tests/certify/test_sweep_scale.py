"""Sweeps that scale: sets made as they are needed, chunks in flight bounded, results dropped once
written — so the main process holds a bounded number of sets, results and futures, whatever the
sweep's size.  No wall time is asserted: the bounds are counted."""

from __future__ import annotations

import dataclasses
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from pendverify.certify import sweep_run
from pendverify.certify.battery import BatteryRun
from pendverify.certify.sweep import load_sweep
from pendverify.certify.sweep_run import MAX_CHUNK, chunk_size, run_sweep
from pendverify.certify.sweep_summary import FAILURES_SHOWN, SweepSummary
from pendverify.certify.sweep_task import SetResult
from pendverify.checks.evidence import Evidence

SWEEP = """
model = "double_pendulum"
mode = "random"
count = {count}
seed = 5
samples = 20
duration = 0.3
[ranges]
m1 = {{ min = 0.2, max = 2.0, scale = "log" }}
l1 = [0.2, 1.0]
"""


def _load(tmp_path, count):
    path = tmp_path / "sweep.toml"
    path.write_text(SWEEP.format(count=count))
    return load_sweep(path)


class CountedSets:
    """A sweep's sets that count how many have been made (iterated) so far."""

    def __init__(self, sets):
        self.sets, self.made = sets, 0

    def __len__(self):
        return len(self.sets)

    def __iter__(self):
        for item in self.sets:
            self.made += 1
            yield item


class ThreadWorkers:
    """Workers for ``run_sweep`` on a thread pool, counting the tasks submitted and not finished."""

    def __init__(self, count: int):
        self.count = count
        self.pool = ThreadPoolExecutor(count)
        self.lock = threading.Lock()
        self.open = self.most_open = self.tasks = 0

    def submit(self, fn, *args):
        with self.lock:
            self.open += 1
            self.tasks += 1
            self.most_open = max(self.most_open, self.open)
        future = self.pool.submit(fn, *args)
        future.add_done_callback(self._done)
        return future

    def _done(self, future):
        with self.lock:
            self.open -= 1

    def kill(self):
        pass

    def close(self, cancel=False):
        self.pool.shutdown(wait=True, cancel_futures=cancel)


def _fake_chunk(model, sets, settings, base_urdf, base_values):
    """A task's results without the battery: set k fails when k % 7 == 3."""
    time.sleep(0.001)
    out = []
    for name, values in sets:
        k = int(name.rsplit("-", 1)[1])
        status = "pass" if k % 7 != 3 else "fail"
        item = Evidence("check", "check:x", status, float(k % 10), 10.0, largest_error=None, samples=1)
        out.append(SetResult(name, values, BatteryRun([item], notes=[])))
    return out


@pytest.mark.parametrize(("count", "workers"), [(1000, 2), (3000, 3)])
def test_sets_results_and_tasks_in_flight_are_bounded(tmp_path, monkeypatch, count, workers):
    monkeypatch.setattr(sweep_run, "certify_chunk", _fake_chunk)
    sweep = _load(tmp_path, count)
    counted = CountedSets(sweep.sets)
    sweep = dataclasses.replace(sweep, sets=counted)
    pool = ThreadWorkers(workers)
    written, most_held = [], 0

    def write(result, replace):
        nonlocal most_held
        written.append(result.name)
        most_held = max(most_held, counted.made - len(written))  # made, not yet written and dropped
        return 1

    run = run_sweep(sweep, pool, write)
    chunk, bound = chunk_size(count, workers), 2 * workers
    assert (run.chunk, run.in_flight) == (chunk, bound) and chunk == MAX_CHUNK
    assert pool.most_open <= bound and run.peak_in_flight <= bound
    assert pool.tasks == run.submitted == -(-count // chunk)
    assert most_held <= bound * chunk  # the sets held at once: the chunks in flight, no more
    assert sorted(written) == sorted(name for name, _ in sweep.sets.sets) and run.written == count
    assert not hasattr(run, "results")
    assert (run.summary.sets, run.summary.failed) == (count, sum(k % 7 == 3 for k in range(count)))


def test_resumed_sets_are_never_made_into_tasks(tmp_path, monkeypatch):
    monkeypatch.setattr(sweep_run, "certify_chunk", _fake_chunk)
    sweep = _load(tmp_path, 50)
    done = {name for name, _ in sweep.sets[:30]}
    written = []
    run = run_sweep(sweep, ThreadWorkers(2), lambda r, replace: written.append(r.name) or 1, skip=done)
    assert run.skipped == 30 and run.written == 20 and not set(written) & done


def test_the_sets_are_made_again_the_same_on_every_pass(tmp_path):
    sweep = _load(tmp_path, 40)
    first, second = list(sweep.sets), list(sweep.sets)
    assert first == second and len(sweep.sets) == 40 and sweep.sets[7] == first[7] == sweep.sets[-33]
    assert [name for name, _ in first][:3] == [
        "double_pendulum-00",
        "double_pendulum-01",
        "double_pendulum-02",
    ]
    rng = np.random.default_rng(5)  # the draws: one uniform per range, in order, set after set
    for _, values in first:
        m1, l1 = rng.uniform(), rng.uniform()
        assert values["m1"] == float(np.exp(np.log(0.2) + m1 * (np.log(2.0) - np.log(0.2))))
        assert values["l1"] == 0.2 + l1 * (1.0 - 0.2)


def test_chunks_are_small_enough_to_share_the_work():
    assert chunk_size(10, 2) == 2 and chunk_size(200, 2) == MAX_CHUNK and chunk_size(1, 4) == 1
    assert chunk_size(0, 2) == 1


def _result(k: int, passed: bool, ratio: float) -> SetResult:
    item = Evidence(
        "check", "check:x", "pass" if passed else "fail", ratio, 1.0, largest_error=None, samples=1
    )
    return SetResult(f"m-{k:03d}", {}, BatteryRun([item], notes=[]))


def test_the_summary_does_not_depend_on_the_order_results_arrive_in():
    results = [_result(k, passed=k % 3 != 0, ratio=0.5 if k in (4, 9) else 0.1) for k in range(60)]
    tables = set()
    for order in (results, results[::-1], results[1::2] + results[::2]):
        summary = SweepSummary()
        for r in order:
            summary.add(r)
        tables.add(summary.table())
    (table,) = tables
    lines = table.splitlines()
    assert lines[0] == "40 passed, 20 failed, 60 sets"
    assert lines[2].split() == ["check:x", "0.5", "m-004"]  # the tie goes to the earlier set
    fails = [line for line in lines if line.startswith("FAIL")]
    assert (
        len(fails) == FAILURES_SHOWN
        and fails[0] == "FAIL m-000: check:x"
        and fails[-1].startswith("FAIL m-057")
    )
    summary = SweepSummary()
    for r in [_result(k, passed=False, ratio=2.0) for k in range(25)]:
        summary.add(r)
    assert summary.table().endswith("... and 5 more failed")
