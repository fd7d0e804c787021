"""Running a sweep: tasks on workers, each set's bundle written as it finishes, Ctrl-C handled.

Tasks run on local processes (``concurrent.futures``) by default, or on a Dask
distributed cluster (``--scheduler tcp://HOST:PORT``) through its Client's
executor.  ``run_sweep`` hands every result to ``write`` as soon as it arrives,
so a sweep stopped part way keeps the certificates of the sets it finished.

On SIGINT (Ctrl-C) the run stops: queued tasks are cancelled, local workers are
terminated (they ignore SIGINT themselves, so a terminal's Ctrl-C reaches only
the main process), a Dask client cancels its futures and closes, and the run
returns marked ``interrupted``.  A bundle being written is finished first; a
second SIGINT ends the process at once with status 130 (workers killed).  The
sweep's progress bar is the only one: tasks draw none.
"""

from __future__ import annotations

import os
import signal
import sys
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from contextlib import contextmanager
from dataclasses import dataclass

from pendverify.certify.sweep import Sweep
from pendverify.certify.sweep_task import certify_task
from pendverify.errors import InputError, PendverifyError
from pendverify.progress import bar

INTERRUPTED = 130  # 128 + SIGINT
POLL_S = 0.2  # how often the run looks for an interruption


@dataclass
class SweepRun:
    results: list[dict]  # the sets computed in this run, in the sweep's order
    written: int  # bundles written in this run
    skipped: int  # sets whose valid bundle was already there (--resume)
    total: int
    interrupted: bool = False


def _ignore_interrupts() -> None:
    """A local worker's initializer: Ctrl-C is the main process's to handle."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


class Workers:
    """Local worker processes, or a Dask cluster through a Client (``close`` stops either)."""

    def __init__(self, scheduler: str | None = None, workers: int | None = None):
        self.client = None
        if scheduler is None:
            self.executor = ProcessPoolExecutor(max_workers=workers, initializer=_ignore_interrupts)
            return
        try:
            from distributed import Client
        except ImportError:
            raise PendverifyError("--scheduler needs Dask: pip install 'pendverify[dask]'") from None
        scheme, _, rest = scheduler.partition("://")
        host, _, port = rest.rpartition(":")
        if not (scheme and host and port.isdigit()):
            raise InputError(
                "<command line>", "--scheduler", scheduler, "a Dask scheduler address, e.g. tcp://HOST:PORT"
            )
        try:
            self.client = Client(scheduler, timeout="10s")
        except (OSError, ValueError) as exc:  # unreachable, refused, or an address Dask cannot parse
            raise PendverifyError(f"cannot reach the Dask scheduler at {scheduler}: {exc}") from None
        self.executor = self.client.get_executor()

    def submit(self, *args):
        return self.executor.submit(*args)

    def _processes(self) -> list:
        return list((getattr(self.executor, "_processes", None) or {}).values())

    def kill(self) -> None:
        """End the local workers at once (SIGKILL)."""
        for process in self._processes():
            process.kill()

    def close(self, cancel: bool = False) -> None:
        """Shut down; with ``cancel``, drop queued tasks and end the running ones."""
        if self.client is not None:
            self.executor.shutdown(wait=not cancel)  # wait=False cancels the futures
            self.client.close(timeout=5)
            return
        processes = self._processes()
        self.executor.shutdown(wait=not cancel, cancel_futures=cancel)
        if cancel:
            for process in processes:
                process.terminate()
            for process in processes:
                process.join(timeout=2)
                if process.is_alive():
                    process.kill()


class Interrupts:
    """SIGINT during a run: the first one asks the run to stop; a second ends the process (130)."""

    def __init__(self, workers: Workers):
        self.workers = workers
        self.requested = False
        self._writing = False
        self._exit_pending = False
        self._previous = None

    def __enter__(self) -> Interrupts:
        try:
            self._previous = signal.signal(signal.SIGINT, self._handle)
        except ValueError:  # not the main thread: Ctrl-C stays a KeyboardInterrupt
            self._previous = None
        return self

    def __exit__(self, *exc) -> None:
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)

    def _handle(self, signum, frame) -> None:
        if not self.requested:
            self.requested = True
        elif self._writing:
            self._exit_pending = True
        else:
            self.exit_now()

    def exit_now(self) -> None:
        self.workers.kill()
        sys.stdout.flush()
        print("pendverify: interrupted again: stopped at once", file=sys.stderr, flush=True)
        os._exit(INTERRUPTED)

    @contextmanager
    def writing(self):
        """A bundle being written is finished before a second Ctrl-C ends the process."""
        self._writing = True
        try:
            yield
        finally:
            self._writing = False
            if self._exit_pending:
                self.exit_now()


def run_sweep(sweep: Sweep, workers: Workers, write, skip=frozenset(), replace=frozenset()) -> SweepRun:
    """Compute every set not in ``skip``; ``write(result, replace: bool) -> bundles written`` is
    called for each result as it arrives (``replace`` for the sets in ``replace``)."""
    settings = sweep.settings.as_dict()
    todo = [(i, name, values) for i, (name, values) in enumerate(sweep.sets) if name not in skip]
    skipped = len(sweep.sets) - len(todo)
    done: dict[int, dict] = {}
    written = 0
    pending: set = set()
    with Interrupts(workers) as interrupts, bar(len(sweep.sets), "sweep", "set", initial=skipped) as progress:
        try:
            futures = {}
            for i, name, values in todo:
                if interrupts.requested:
                    break
                task = (sweep.model, name, values, settings, sweep.urdf, sweep.base)
                futures[workers.submit(certify_task, *task)] = (i, name)
            pending = set(futures)
            while pending and not interrupts.requested:
                finished, pending = wait(pending, timeout=POLL_S, return_when=FIRST_COMPLETED)
                for future in sorted(finished, key=lambda f: futures[f][0]):
                    i, name = futures[future]
                    done[i] = future.result()
                    with interrupts.writing():
                        written += write(done[i], name in replace)
                    progress.update(1)
        finally:
            workers.close(cancel=bool(pending) or interrupts.requested)
    results = [done[i] for i in sorted(done)]
    stopped = interrupts.requested and len(done) < len(todo)
    return SweepRun(results, written, skipped, len(sweep.sets), stopped)
