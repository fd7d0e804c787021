"""Sweeps in a pipeline: Ctrl-C keeps what finished and --resume goes on; output and size
checked before any work; one progress bar; a report folder appears whole or not at all."""

from __future__ import annotations

import fcntl
import json
import os
import pty
import re
import select
import shutil
import signal
import struct
import subprocess
import sys
import termios
import time
from pathlib import Path

import pytest

from pendverify.certify import sweep_run
from pendverify.certify.certificate import verify_digest
from pendverify.cli import main

SWEEP = """
model = "double_pendulum"
mode = "random"
count = {count}
seed = 3
samples = 20
duration = 0.3
[ranges]
m1 = [0.5, 2.0]
I1 = {{ min = 0.001, max = 0.05, scale = "log" }}
"""
SETS = 10
#: a hard bound on every wait for a sweep's process [s]: a hang fails the test.  A wait is for a
#: few seconds of a process's work; on a 2-core machine shared with other processes that stretches
#: several-fold, so the bound is far above it (a process that does not exit, not a slow one)
HANG_S = 120
# No wall time is asserted (tests never do): that the sweep stopped is shown by the sets it did not
# compute (fewer than SETS certificates), that it did not hang by ``communicate``'s timeout; the
# README quotes the measured time from SIGINT to exit (0.24–0.74 s).


def _sweep(folder: Path, count: int = SETS) -> Path:
    path = folder / "sweep.toml"
    path.write_text(SWEEP.format(count=count))
    return path


def pendverify_process(*args: str, **kw) -> subprocess.Popen:
    cmd = [sys.executable, "-c", "import sys; from pendverify.cli import main; sys.exit(main())", *args]
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True, **kw)


def _items(folder: Path) -> dict[str, list]:
    """Every certificate's battery figures, by set name (dates and versions aside)."""
    return {
        p.name: [json.loads(p.read_text())[k] for k in ("parameters", "checks", "urdf")]
        for p in sorted(folder.glob("*.cert.json"))
    }


#: fields of /proc/PID/stat after the command's name: 0 state, 1 parent's pid, 3 session id
PARENT_FIELD, SESSION_FIELD = 1, 3


def live_processes(field: int, value: int) -> list[int]:
    """Processes alive (not zombies) whose /proc stat field ``field`` is ``value``."""
    alive = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[field]) == value and fields[0] != "Z":
            alive.append(int(stat.parent.name))
    return alive


def session_processes(sid: int) -> list[int]:
    """Processes still alive in session ``sid`` (the sweep and its workers)."""
    return live_processes(SESSION_FIELD, sid)


def _interrupt_after_first_bundle(sweep: Path, out: Path, signals: int = 1, where=("--workers", "2")):
    proc = pendverify_process("certify", "--sweep", str(sweep), "-o", str(out), *where)
    deadline = time.monotonic() + HANG_S
    while not list(out.glob("*.cert.json")):
        assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
        time.sleep(0.05)
    sent = time.monotonic()
    for _ in range(signals):
        os.killpg(proc.pid, signal.SIGINT)  # as a terminal's Ctrl-C: the whole process group
    _, err = proc.communicate(timeout=HANG_S)
    return proc, time.monotonic() - sent, err.decode()


@pytest.fixture(scope="module")
def uninterrupted(tmp_path_factory):
    folder = tmp_path_factory.mktemp("full")
    out = folder / "out"
    assert main(["certify", "--sweep", str(_sweep(folder)), "-o", str(out), "--workers", "2"]) == 0
    return out


@pytest.mark.sweep
def test_ctrl_c_keeps_finished_sets_and_resume_completes_the_sweep(tmp_path, uninterrupted, capfd):
    sweep, out = _sweep(tmp_path), tmp_path / "out"
    proc, elapsed, err = _interrupt_after_first_bundle(sweep, out)
    assert proc.returncode == 130, (proc.returncode, elapsed, err)
    assert "Traceback" not in err and "interrupted" in err and "--resume" in err, err
    assert not session_processes(proc.pid), "workers outlived the sweep"
    finished = sorted(out.glob("*.cert.json"))
    assert 1 <= len(finished) < SETS
    assert not [p for p in out.iterdir() if p.name.startswith(".")], "stray temporary files"
    assert main(["recheck", str(finished[0])]) == 0
    for cert in finished[1:]:  # the others: their digests (recheck would re-run each battery)
        verify_digest(json.loads(cert.read_text()), str(cert))
    # a half-written bundle (certificate missing) and a killed writer's temporary are redone and removed
    half = finished[0].name.removesuffix(".cert.json")
    finished[0].unlink()
    (out / f".{half}.urdf.abcd1234.tmp").write_text("half")
    capfd.readouterr()
    assert main(["certify", "--sweep", str(sweep), "-o", str(out), "--resume", "--workers", "2"]) == 0
    assert f"{len(finished) - 1} set(s) already certified" in capfd.readouterr().out
    assert _items(out) == _items(uninterrupted)
    assert not [p for p in out.iterdir() if p.name.startswith(".")]


@pytest.mark.sweep
def test_a_second_ctrl_c_exits_at_once(tmp_path):
    out = tmp_path / "out"
    proc, elapsed, err = _interrupt_after_first_bundle(_sweep(tmp_path), out, signals=2)
    assert proc.returncode == 130, (proc.returncode, elapsed, err)
    assert len(list(out.glob("*.cert.json"))) < SETS, "the sweep computed every set"
    assert "Traceback" not in err, err
    time.sleep(0.5)
    assert not session_processes(proc.pid), "workers outlived the sweep"


@pytest.mark.sweep
def test_ctrl_c_on_a_dask_sweep_cancels_its_tasks(tmp_path):
    distributed = pytest.importorskip("distributed", reason="the dask extra is part of the test extras")
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, host="127.0.0.1", dashboard_address=":0", processes=True
    ) as cluster:
        where = ("--scheduler", cluster.scheduler_address)
        out = tmp_path / "out"
        proc, elapsed, err = _interrupt_after_first_bundle(_sweep(tmp_path), out, where=where)
        assert proc.returncode == 130, (proc.returncode, elapsed, err)
        assert len(list(out.glob("*.cert.json"))) < SETS, "the sweep computed every set"
        assert "Traceback" not in err, err
        with distributed.Client(cluster.scheduler_address) as client:
            for _ in range(30):  # the scheduler forgets a closed client's tasks within moments
                left = client.run_on_scheduler(lambda dask_scheduler: len(dask_scheduler.tasks))
                if not left:
                    break
                time.sleep(0.1)
        assert left == 0, f"{left} task(s) of the sweep still on the cluster"


@pytest.mark.sweep
def test_resume_refuses_an_edited_certificate(tmp_path, uninterrupted, capsys, monkeypatch):
    out = tmp_path / "out"
    shutil.copytree(uninterrupted, out)
    cert = sorted(out.glob("*.cert.json"))[2]
    data = json.loads(cert.read_text())
    data["parameters"]["m1"] *= 1.01
    cert.write_text(json.dumps(data))
    monkeypatch.setattr(sweep_run, "Workers", _no_work)
    assert main(["certify", "--sweep", str(_sweep(tmp_path)), "-o", str(out), "--resume"]) == 2
    err = capsys.readouterr().err
    assert f"{cert}: digest mismatch" in err and len(err.strip().splitlines()) == 1


def _no_work(*args, **kw):
    raise AssertionError("a set was computed")


@pytest.mark.parametrize(
    "case",
    ["existing bundle", "missing parent", "file in its place", "unwritable"],
)
def test_output_is_checked_before_any_set_is_computed(case, tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(sweep_run, "Workers", _no_work)
    out = tmp_path / "out"
    if case == "existing bundle":
        out.mkdir()
        (out / "double_pendulum-7.params.toml").write_text("")
    elif case == "missing parent":
        out = tmp_path / "nowhere" / "out"
    elif case == "file in its place":
        out.write_text("")
    elif os.geteuid() == 0:
        out = Path("/proc/pendverify-out")  # not writable, even by root
    else:
        out.mkdir(mode=0o500)
    assert main(["certify", "--sweep", str(_sweep(tmp_path)), "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(out) in err, err
    if case == "existing bundle":
        assert "--resume" in err and "--force" in err


@pytest.mark.parametrize(
    ("text", "key", "count"),
    [
        (SWEEP.format(count=10**9), "count", "1,000,000,000"),
        (
            'model = "double_pendulum"\nmode = "grid"\n[ranges]\n'
            "m1 = { min = 0.5, max = 2.0, points = 100000 }\n"
            "l1 = { min = 0.5, max = 1.0, points = 100000 }\n",
            "ranges",
            "10,000,000,000",
        ),
    ],
)
def test_a_huge_sweep_is_refused_up_front(text, key, count, tmp_path, capsys, monkeypatch):
    """Refused before any set is made (counted from the ranges, not enumerated): making a set fails."""
    from pendverify.certify.sweep import SweepSets

    def made(self):
        raise AssertionError("a set of the refused sweep was made")

    monkeypatch.setattr(SweepSets, "_rows", made)
    sweep = tmp_path / "huge.toml"
    sweep.write_text(text)
    assert main(["certify", "--sweep", str(sweep), "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert f"key '{key}'" in err and f"{count} sets exceed the limit of 100,000" in err, err
    assert "--max-sets" in err and len(err.splitlines()) == 1


def test_max_sets_raises_or_lowers_the_limit(tmp_path, capsys):
    from pendverify.certify.sweep import load_sweep

    sweep = _sweep(tmp_path, count=3)
    assert len(load_sweep(sweep, max_sets=3).sets) == 3
    assert main(["certify", "--sweep", str(sweep), "-o", str(tmp_path / "out"), "--max-sets", "2"]) == 2
    assert "3 sets exceed the limit of 2" in capsys.readouterr().err


def test_a_sweep_task_never_draws_a_bar(tmp_path, monkeypatch):
    """Even on a terminal, a worker's task (battery, simulations) opens only disabled bars."""
    import tqdm

    from pendverify.certify.sweep import load_sweep
    from pendverify.certify.sweep_task import certify_chunk

    bars = []

    class Spy(tqdm.tqdm):
        def __init__(self, *args, **kw):
            bars.append((kw.get("desc"), kw.get("disable")))
            super().__init__(*args, **{**kw, "disable": True})

    monkeypatch.setattr(tqdm, "tqdm", Spy)
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    sweep = load_sweep(_sweep(tmp_path, 1))
    name, values = sweep.sets[0]
    certify_chunk(sweep.model, [(name, values)], sweep.settings.as_dict())
    assert bars and all(disabled for _, disabled in bars), bars


@pytest.mark.sweep
def test_a_sweep_on_a_terminal_shows_one_bar(tmp_path):
    """Under a pseudo-terminal, only the sweep's bar is drawn: workers stay quiet."""
    leader, follower = pty.openpty()
    fcntl.ioctl(follower, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))  # a terminal's size
    sweep = ["--sweep", str(_sweep(tmp_path, 4)), "-o", str(tmp_path / "out"), "--workers", "2"]
    proc = subprocess.Popen(
        [sys.executable, "-m", "pendverify.cli", "certify", *sweep],
        stdin=follower,
        stdout=follower,
        stderr=follower,
        close_fds=True,
    )
    os.close(follower)
    chunks = []
    while True:
        ready, _, _ = select.select([leader], [], [], 120)
        try:
            chunk = os.read(leader, 65536) if ready else b""
        except OSError:  # the terminal closed
            chunk = b""
        if not chunk:
            break
        chunks.append(chunk)
    os.close(leader)
    assert proc.wait(timeout=HANG_S) == 0
    text = b"".join(chunks).decode(errors="replace")
    descriptions = set(re.findall(r"([\w()/ .-]+?): *\d+%\|", text))
    assert descriptions == {"sweep"}, (descriptions, text[-2000:])
    assert "4/4" in text


def test_no_bar_off_a_terminal(tmp_path, capfd):
    assert main(["check", "--samples", "10"]) == 0
    assert "%|" not in capfd.readouterr().err


def test_an_error_mid_report_leaves_no_folder(tmp_path, monkeypatch):
    from pendverify.viz import review_folder

    scenes = tmp_path / "scenes"
    scenes.mkdir()
    for stem in ("a", "b"):
        short_scene(scenes / f"{stem}.toml")
    calls = []

    def failing_plot(*args):  # each scene's energy plot: Ctrl-C during the second scene
        calls.append(args)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(*args)

    real = review_folder.energy_plot_svg
    monkeypatch.setattr(review_folder, "energy_plot_svg", failing_plot)
    site = tmp_path / "site"
    site.mkdir()
    out = site / "review"
    # Ctrl-C: exit status 130 (pendverify.exitcodes)
    assert main(["report", "-o", str(out), "--scenes", str(scenes), "--samples", "5", "--no-erd"]) == 130
    assert len(calls) == 2 and list(site.iterdir()) == []
    out.mkdir()
    (out / "old.txt").write_text("old")
    monkeypatch.setattr(review_folder, "energy_plot_svg", real)
    assert main(["report", "-o", str(out), "--scenes", str(scenes), "--samples", "5", "--no-erd"]) == 2
    assert (out / "old.txt").exists()
    args = ["report", "-o", str(out), "--scenes", str(scenes), "--samples", "5", "--no-erd", "--force"]
    assert main(args) == 0
    assert (out / "index.html").exists() and not (out / "old.txt").exists()
    assert [p.name for p in site.iterdir()] == ["review"]


def short_scene(path: Path) -> None:
    path.write_text(
        'name = "short"\nmodel = "double_pendulum"\n[initial]\nq = [0.4, 0.9]\n'
        "[time]\nduration = 0.5\nsample_rate = 20.0\n"
        '[integrator]\nmethod = "DOP853"\nrtol = 1e-8\natol = 1e-8\n[effects]\ngravity = true\n'
    )
