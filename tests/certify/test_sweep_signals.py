"""Signals and a changing output folder during a sweep, planted: ``kill -9`` of the main process
takes its workers with it (the caller's pipes close), SIGTERM is handled as Ctrl-C is (status
143, finished work kept), SIGTERM during ``report -o DIR`` leaves no temporary folder, and a
sweep whose output folder or files are removed under it does not claim certificates it lost."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from pendverify.certify import issue
from pendverify.cli import main
from tests.certify.test_sweep_interrupt import (
    HANG_S,
    SWEEP,
    pendverify_process,
    session_processes,
    short_scene,
)

pytestmark = pytest.mark.sweep  # every test runs a sweep in a process and signals it

SETS = 24  # enough that a sweep is still running when its first certificate lands
TIMEOUT_S = HANG_S  # a hard bound on every wait: a hang fails the test, it does not stall the suite


def _sweep(folder: Path, count: int = SETS) -> Path:
    path = folder / "sweep.toml"
    path.write_text(SWEEP.format(count=count))
    return path


def _started_sweep(tmp_path: Path) -> tuple[subprocess.Popen, Path]:
    """A sweep on two local workers, returned once its first certificate is on disk."""
    out = tmp_path / "out"
    proc = pendverify_process("certify", "--sweep", str(_sweep(tmp_path)), "-o", str(out), "--workers", "2")
    deadline = time.monotonic() + TIMEOUT_S
    while not list(out.glob("*.cert.json")):
        assert proc.poll() is None and time.monotonic() < deadline, proc.communicate(timeout=TIMEOUT_S)
        time.sleep(0.05)
    return proc, out


def _gone(sid: int) -> bool:
    """Whether every process of session ``sid`` has ended (a moment is allowed for the kernel)."""
    for _ in range(40):
        if not session_processes(sid):
            return True
        time.sleep(0.05)
    return False


def test_kill_9_of_the_main_process_takes_its_workers_and_closes_the_callers_pipes(tmp_path):
    proc, _ = _started_sweep(tmp_path)
    os.kill(proc.pid, signal.SIGKILL)
    # communicate returns only once every holder of the pipes (the workers too) has closed them
    proc.communicate(timeout=TIMEOUT_S)
    assert proc.returncode == -signal.SIGKILL
    assert _gone(proc.pid), "workers outlived the killed sweep"


def test_kill_9_with_capture_output_returns(tmp_path):
    # as a CI step runs it: subprocess.run(capture_output=True) of a command that kills the sweep
    sweep, out = _sweep(tmp_path), tmp_path / "out"
    script = (
        "import os, signal, subprocess, sys, time, pathlib\n"
        "cmd = [sys.executable, '-m', 'pendverify.cli', 'certify', '--sweep', sys.argv[1], '-o', sys.argv[2],"
        " '--workers', '2']\n"
        "p = subprocess.Popen(cmd)\n"  # inherits this script's stdout and stderr: the caller's pipes
        "out = pathlib.Path(sys.argv[2])\n"
        "while not list(out.glob('*.cert.json')) and p.poll() is None: time.sleep(0.05)\n"
        "os.kill(p.pid, signal.SIGKILL)\n"
        "p.wait()\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script, str(sweep), str(out)],
        capture_output=True,
        timeout=TIMEOUT_S,
        start_new_session=True,
    )
    assert done.returncode == 0, done.stderr.decode()
    assert 1 <= len(list(out.glob("*.cert.json"))) < SETS


@pytest.mark.parametrize("group", [False, True], ids=["main process", "process group"])
def test_sigterm_is_handled_as_ctrl_c_with_status_143(tmp_path, group):
    proc, out = _started_sweep(tmp_path)
    if group:
        os.killpg(proc.pid, signal.SIGTERM)  # as a CI runner or a container stop does
    else:
        os.kill(proc.pid, signal.SIGTERM)
    _, err = proc.communicate(timeout=TIMEOUT_S)
    err = err.decode()
    assert proc.returncode == 143, (proc.returncode, err)
    assert "Traceback" not in err and "terminated" in err and "--resume" in err, err
    assert _gone(proc.pid), "workers outlived the sweep"
    finished = sorted(out.glob("*.cert.json"))
    assert 1 <= len(finished) < SETS
    for cert in finished:
        json.loads(cert.read_text())
    assert not [p for p in out.iterdir() if p.name.startswith(".")], "stray temporary files"


def test_sigterm_during_report_leaves_no_temporary_folder(tmp_path):
    scenes = tmp_path / "scenes"
    scenes.mkdir()
    for stem in ("a", "b", "c"):
        short_scene(scenes / f"{stem}.toml")
    site = tmp_path / "site"
    site.mkdir()
    proc = pendverify_process("report", "-o", str(site / "review"), "--scenes", str(scenes), "--no-erd")
    deadline = time.monotonic() + TIMEOUT_S
    while not list(site.glob(".review.*.tmp")):  # the folder being built
        assert proc.poll() is None and time.monotonic() < deadline, proc.communicate(timeout=TIMEOUT_S)
        time.sleep(0.02)
    os.kill(proc.pid, signal.SIGTERM)
    _, err = proc.communicate(timeout=TIMEOUT_S)
    assert proc.returncode == 143, err.decode()
    assert err.decode() == "pendverify: terminated (SIGTERM)\n"
    assert list(site.iterdir()) == []


def test_an_output_folder_removed_mid_sweep_stops_it_with_one_line(tmp_path):
    proc, out = _started_sweep(tmp_path)
    out.rename(tmp_path / "moved")  # removed from where the sweep writes, in one step (no race)
    stdout, err = proc.communicate(timeout=TIMEOUT_S)
    err = err.decode()
    assert proc.returncode == 2, (proc.returncode, err)
    assert len(err.strip().splitlines()) == 1 and "removed or replaced during the sweep" in err, err
    assert b"certificate(s) written" not in stdout
    assert _gone(proc.pid)


def test_certificates_removed_mid_sweep_are_not_counted(tmp_path, monkeypatch, capsys):
    real = issue.write_sweep_certificates
    written = []

    def write_then_lose_the_first(sweep, results, output, *args):
        n = real(sweep, results, output, *args)
        written.extend(r.name for r in results)
        if len(written) == 2:
            (Path(output) / f"{written[0]}.cert.json").unlink()
        return n

    monkeypatch.setattr(issue, "write_sweep_certificates", write_then_lose_the_first)
    out = tmp_path / "out"
    assert main(["certify", "--sweep", str(_sweep(tmp_path, 3)), "-o", str(out), "--workers", "1"]) == 1
    captured = capsys.readouterr()
    assert "3 certificate(s) written or kept, but only 2 of the sweep's are in" in captured.err
    assert "certificate(s) written to" not in captured.out
