"""Running a sweep: chunks of sets streamed to workers, each bundle written as it arrives, Ctrl-C handled.

Tasks run on local processes (``concurrent.futures``) by default, or on a Dask
distributed cluster (``--scheduler tcp://HOST:PORT``) through its Client's
executor.  A task is a chunk of ``chunk`` sets (``sweep_task.certify_chunk``: default
``chunk_size``), made from the sweep's sets as they are needed: at most ``in_flight``
chunks (default two per worker: one running, one queued) are submitted and not yet
finished at any time, and ``run_sweep`` hands each result to ``write`` as soon as its
chunk arrives and then drops it, so the main process holds neither all the sets, nor
their results, nor their futures: its memory does not grow with the number of sets
(``SweepSummary`` keeps counters, the worst figure per battery item and the first
failures).  A sweep stopped part way keeps the certificates of the sets it finished.

On SIGINT (Ctrl-C) the run stops: queued tasks are cancelled, local workers are
terminated (they ignore SIGINT themselves, so a terminal's Ctrl-C reaches only
the main process), a Dask client cancels its futures and closes, and the run
returns marked ``interrupted``.  A bundle being written is finished first; a
second SIGINT ends the process at once with status 130 (workers killed).  The
sweep's progress bar is the only one: tasks draw none.
"""

from __future__ import annotations

import itertools
import math
import os
import signal
import sys
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from contextlib import contextmanager
from dataclasses import dataclass

from pendverify.certify.sweep import Sweep
from pendverify.certify.sweep_summary import SweepSummary
from pendverify.certify.sweep_task import certify_chunk
from pendverify.display import shortened
from pendverify.errors import InputError, PendverifyError
from pendverify.progress import bar

INTERRUPTED = 130  # 128 + SIGINT
POLL_S = 0.2  # how often the run looks for an interruption
MAX_CHUNK = 8  # sets per task at most: a chunk's results arrive together
CHUNKS_PER_WORKER = 4  # smaller chunks below this many per worker, so the workers finish together
SCHEDULER_SCHEMES = ("tcp", "tls", "ws", "wss")  # Dask's comms that need no extra package


@dataclass
class SweepRun:
    summary: SweepSummary  # the sets computed in this run: counts, worst figures, first failures
    written: int  # bundles written in this run
    skipped: int  # sets whose valid bundle was already there (--resume)
    total: int
    interrupted: bool = False
    chunk: int = 1  # sets per task
    in_flight: int = 0  # tasks submitted and not finished, at most (the bound)
    peak_in_flight: int = 0  # the most there were at once
    submitted: int = 0  # tasks


def chunk_size(sets: int, workers: int) -> int:
    """Sets per task: ``MAX_CHUNK`` at most, fewer when the sweep would give a worker under
    ``CHUNKS_PER_WORKER`` chunks."""
    return max(1, min(MAX_CHUNK, math.ceil(sets / (CHUNKS_PER_WORKER * max(1, workers)))))


def _ignore_interrupts() -> None:
    """A local worker's initializer: Ctrl-C is the main process's to handle."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


class Workers:
    """Local worker processes, or a Dask cluster through a Client (``close`` stops either);
    ``count``: how many tasks they run at once."""

    def __init__(self, scheduler: str | None = None, workers: int | None = None):
        self.client = None
        if scheduler is None:
            self.count = workers or os.cpu_count() or 1
            self.executor = ProcessPoolExecutor(max_workers=self.count, initializer=_ignore_interrupts)
            return
        try:
            from distributed import Client
        except ImportError:
            raise PendverifyError("--scheduler needs Dask: pip install 'pendverify[dask]'") from None
        scheme, _, rest = scheduler.partition("://")
        host, _, port = rest.rpartition(":")
        if not (scheme in SCHEDULER_SCHEMES and host and port.isdigit()):
            schemes = ", ".join(f"{s}://" for s in SCHEDULER_SCHEMES)
            raise InputError(
                "<command line>",
                "--scheduler",
                shortened(scheduler, 80),
                f"a Dask scheduler address HOST:PORT after {schemes} (e.g. tcp://HOST:PORT)",
            )
        try:
            self.client = Client(scheduler, timeout="10s")
        except Exception as exc:  # Dask's connect: unreachable, refused, TLS unset, ...
            raise PendverifyError(
                f"cannot reach the Dask scheduler at {shortened(scheduler, 80)}: {type(exc).__name__}: {exc}"
            ) from None
        self.executor = self.client.get_executor()
        self.count = max(1, sum(self.client.nthreads().values()))  # tasks the cluster runs at once

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


def run_sweep(
    sweep: Sweep,
    workers: Workers,
    write,
    skip=frozenset(),
    replace=frozenset(),
    chunk: int | None = None,
    in_flight: int | None = None,
) -> SweepRun:
    """Compute every set not in ``skip``; ``write(result, replace: bool) -> bundles written`` is
    called for each result as its chunk arrives (``replace`` for the sets in ``replace``).

    ``chunk``: sets per task (default ``chunk_size``); ``in_flight``: tasks submitted and not
    finished at most (default two per worker)."""
    settings = sweep.settings.as_dict()
    total = len(sweep.sets)
    skipped = sum(name in skip for name, _ in sweep.sets) if skip else 0
    chunk = chunk or chunk_size(total - skipped, workers.count)
    in_flight = in_flight or 2 * workers.count
    todo = ((name, values) for name, values in sweep.sets if name not in skip)
    chunks = iter(lambda: list(itertools.islice(todo, chunk)), [])
    run = SweepRun(SweepSummary(), 0, skipped, total, chunk=chunk, in_flight=in_flight)
    pending: dict = {}  # future → its chunk's size
    with Interrupts(workers) as interrupts, bar(total, "sweep", "set", initial=skipped) as progress:
        try:
            exhausted = False
            while not interrupts.requested:
                while not exhausted and len(pending) < in_flight and not interrupts.requested:
                    sets = next(chunks, None)
                    if sets is None:
                        exhausted = True
                        break
                    task = (sweep.model, sets, settings, sweep.urdf, sweep.base)
                    pending[workers.submit(certify_chunk, *task)] = len(sets)
                    run.submitted += 1
                    run.peak_in_flight = max(run.peak_in_flight, len(pending))
                if not pending:
                    break
                finished, _ = wait(list(pending), timeout=POLL_S, return_when=FIRST_COMPLETED)
                for future in finished:
                    del pending[future]
                    for result in future.result():
                        run.summary.add(result)
                        with interrupts.writing():
                            run.written += write(result, result["name"] in replace)
                        progress.update(1)
        finally:
            workers.close(cancel=bool(pending) or interrupts.requested)
    run.interrupted = interrupts.requested and run.summary.sets < total - skipped
    return run
