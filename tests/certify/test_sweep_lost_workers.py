"""A sweep whose workers go away stops with one line and keeps what finished, planted: the only
Dask worker killed (no worker for ``--worker-timeout`` seconds), the Dask scheduler killed, and a
local worker process killed; and a Dask scheduler frozen (SIGSTOP: connected, silent)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from pendverify.certify.certificate import verify_digest
from tests.certify.test_sweep_interrupt import PARENT_FIELD, SWEEP, live_processes, pendverify_process

pytestmark = pytest.mark.sweep  # every test runs a sweep (Dask or local workers) and kills a part of it

SETS = 24
TIMEOUT_S = 120  # a hard bound on every wait: a hang fails the test


def _sweep(folder: Path) -> Path:
    path = folder / "sweep.toml"
    path.write_text(SWEEP.format(count=SETS))
    return path


def _dask(*args: str) -> subprocess.Popen:
    cli = [sys.executable, "-m", *args, "--no-dashboard"]
    return subprocess.Popen(cli, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)


def _worker(address: str) -> subprocess.Popen:
    """One Dask worker process, one thread, no nanny (so nothing restarts it when it is killed)."""
    return _dask("distributed.cli.dask_worker", address, "--nthreads", "1", "--no-nanny")


def _until_first_certificate(proc: subprocess.Popen, out: Path) -> None:
    deadline = time.monotonic() + TIMEOUT_S
    while not list(out.glob("*.cert.json")):
        assert proc.poll() is None and time.monotonic() < deadline, proc.communicate(timeout=TIMEOUT_S)
        time.sleep(0.05)


def _stopped_with_one_line(proc: subprocess.Popen, out: Path, words: str) -> None:
    _, err = proc.communicate(timeout=TIMEOUT_S)
    err = err.decode()
    assert proc.returncode == 2, (proc.returncode, err)
    assert len(err.strip().splitlines()) == 1 and words in err and "--resume" in err, err
    finished = sorted(out.glob("*.cert.json"))
    assert 1 <= len(finished) < SETS
    for cert in finished:
        verify_digest(json.loads(cert.read_text()), str(cert))


def _stop(*procs: subprocess.Popen) -> None:
    for proc in procs:
        if proc.poll() is None:
            proc.send_signal(signal.SIGCONT)  # a stopped process too
            proc.kill()
        proc.wait(timeout=TIMEOUT_S)


def test_a_dask_cluster_whose_only_worker_died(tmp_path):
    distributed = pytest.importorskip("distributed", reason="the dask extra is part of the test extras")
    with distributed.LocalCluster(
        n_workers=0, processes=False, protocol="tcp", host="127.0.0.1", dashboard_address=":0"
    ) as cluster:
        worker = _worker(cluster.scheduler_address)
        out = tmp_path / "out"
        where = ("--scheduler", cluster.scheduler_address, "--worker-timeout", "2")
        proc = pendverify_process("certify", "--sweep", str(_sweep(tmp_path)), "-o", str(out), *where)
        try:
            _until_first_certificate(proc, out)
            worker.kill()
            _stopped_with_one_line(proc, out, "has had no worker for 2 s (--worker-timeout)")
        finally:
            _stop(proc, worker)


@pytest.mark.parametrize(
    ("how", "words"),
    [
        (signal.SIGKILL, "lost the Dask scheduler at"),
        (signal.SIGSTOP, "has not answered for 2 s (--worker-timeout)"),  # frozen: connected, silent
    ],
    ids=["killed", "frozen"],
)
def test_a_dask_scheduler_that_died(tmp_path, how, words):
    pytest.importorskip("distributed", reason="the dask extra is part of the test extras")
    file = tmp_path / "scheduler.json"
    listen = ("--host", "127.0.0.1", "--port", "0", "--scheduler-file", str(file))
    scheduler = _dask("distributed.cli.dask_scheduler", *listen)
    worker = None
    proc = None
    try:
        deadline = time.monotonic() + TIMEOUT_S
        while not file.exists() or not file.read_text().strip():
            assert scheduler.poll() is None and time.monotonic() < deadline
            time.sleep(0.05)
        address = json.loads(file.read_text())["address"]
        worker = _worker(address)
        out = tmp_path / "out"
        sweep = ("--sweep", str(_sweep(tmp_path)), "-o", str(out), "--scheduler", address)
        proc = pendverify_process("certify", *sweep, "--worker-timeout", "2")
        _until_first_certificate(proc, out)
        scheduler.send_signal(how)
        _stopped_with_one_line(proc, out, words)
    finally:
        _stop(*(p for p in (proc, worker, scheduler) if p is not None))


def _children(pid: int) -> list[int]:
    return live_processes(PARENT_FIELD, pid)


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="finds the workers in /proc")
def test_a_local_worker_that_died(tmp_path):
    out = tmp_path / "out"
    proc = pendverify_process("certify", "--sweep", str(_sweep(tmp_path)), "-o", str(out), "--workers", "2")
    try:
        _until_first_certificate(proc, out)
        os.kill(_children(proc.pid)[0], signal.SIGKILL)  # as the out-of-memory killer does
        _stopped_with_one_line(proc, out, "a local worker process died")
    finally:
        _stop(proc)
