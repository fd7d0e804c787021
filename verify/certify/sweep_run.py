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

On SIGINT (Ctrl-C) or SIGTERM the run stops: queued tasks are cancelled, local
workers are killed (they ignore SIGINT and SIGTERM themselves, so a terminal's Ctrl-C
or a ``kill`` of the process group reaches only the main process), a Dask client
cancels its futures and closes, and the run returns marked ``interrupted`` with the
signal's status (130 for SIGINT, 143 for SIGTERM).  A bundle being written is
finished first; a second signal ends the process at once with that status (workers
killed).

A sweep whose workers cannot go on stops with one line instead of waiting: a Dask
client that lost its scheduler, a Dask cluster with no worker for ``worker_timeout``
seconds (``--worker-timeout``, default ``WORKER_TIMEOUT_S``), or a local worker process
that died (killed, out of memory).  The run returns marked ``lost`` (the reason); the
certificates written so far stay.  Local workers die with the main process however it ends, ``kill -9``
included (``pendverify.signals.die_with_parent``), so none outlives it holding the
caller's standard output.  The sweep's progress bar is the only one: tasks draw none.
"""

from __future__ import annotations

import itertools
import logging
import math
import multiprocessing
import os
import signal
import sys
import time
from concurrent.futures import FIRST_COMPLETED, CancelledError, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
from dataclasses import dataclass

from pendverify.certify.sweep import Sweep
from pendverify.certify.sweep_limits import WORKER_TIMEOUT_S
from pendverify.certify.sweep_summary import SweepSummary
from pendverify.certify.sweep_task import certify_chunk
from pendverify.display import shortened
from pendverify.errors import InputError, PendverifyError
from pendverify.exitcodes import INTERRUPTED, TERMINATED
from pendverify.progress import bar
from pendverify.signals import die_with_parent

STATUS = {signal.SIGINT: INTERRUPTED, signal.SIGTERM: TERMINATED}  # a stopping signal's exit status
POLL_S = 0.2  # how often the run looks for an interruption
MAX_CHUNK = 8  # sets per task at most: a chunk's results arrive together
CHUNKS_PER_WORKER = 4  # smaller chunks below this many per worker, so the workers finish together
SCHEDULER_SCHEMES = ("tcp", "tls", "ws", "wss")  # Dask's comms that need no extra package
WORKER_CHECK_S = 1.0  # how often the run asks the Dask scheduler how many workers it has


@dataclass
class SweepRun:
    summary: SweepSummary  # the sets computed in this run: counts, worst figures, first failures
    written: int  # bundles written in this run
    skipped: int  # sets whose valid bundle was already there (--resume)
    total: int
    interrupted: bool = False
    lost: str | None = None  # why the workers could not go on (the sweep stopped), or None
    status: int = INTERRUPTED  # when interrupted: the exit status of the signal that stopped it
    chunk: int = 1  # sets per task
    in_flight: int = 0  # tasks submitted and not finished, at most (the bound)
    peak_in_flight: int = 0  # the most there were at once
    submitted: int = 0  # tasks


def chunk_size(sets: int, workers: int) -> int:
    """Sets per task: ``MAX_CHUNK`` at most, fewer when the sweep would give a worker under
    ``CHUNKS_PER_WORKER`` chunks."""
    return max(1, min(MAX_CHUNK, math.ceil(sets / (CHUNKS_PER_WORKER * max(1, workers)))))


def _start_worker(parent: int | None) -> None:
    """A local worker's initializer: Ctrl-C and SIGTERM are the main process's to handle, and
    the worker dies with ``parent`` (the main process, or None: the fork server that forked it)."""
    for signum in STATUS:
        signal.signal(signum, signal.SIG_IGN)
    die_with_parent(parent)


class Workers:
    """Local worker processes, or a Dask cluster through a Client (``close`` stops either);
    ``count``: how many tasks they run at once."""

    def __init__(
        self,
        scheduler: str | None = None,
        workers: int | None = None,
        worker_timeout: float = WORKER_TIMEOUT_S,
    ):
        self.client = None
        self.scheduler = scheduler
        self.worker_timeout = worker_timeout
        self._checked = -math.inf  # when the Dask scheduler was last asked for its workers
        self._no_worker_since = None  # since when it has had none (time.monotonic), or None
        if scheduler is None:
            self.count = workers or os.cpu_count() or 1
            forked_by_main = multiprocessing.get_start_method() != "forkserver"
            self.executor = ProcessPoolExecutor(
                max_workers=self.count,
                initializer=_start_worker,
                initargs=(os.getpid() if forked_by_main else None,),
            )
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

    def lost(self) -> str | None:
        """Why a Dask cluster can no longer run the sweep's tasks, or None (local workers: None)."""
        if self.client is None:
            return None
        if self.client.status != "running":
            return f"lost the Dask scheduler at {shortened(self.scheduler, 80)} (client {self.client.status})"
        now = time.monotonic()
        if now - self._checked < WORKER_CHECK_S:
            return None
        self._checked = now
        try:  # an RPC with a bound: a scheduler that does not answer counts as one without workers
            identity = self.client.sync(self.client.scheduler.identity, callback_timeout=WORKER_CHECK_S * 5)
            answered = True
        except (OSError, TimeoutError):
            identity, answered = {}, False
        if identity.get("workers"):
            self._no_worker_since = None
            return None
        if self._no_worker_since is None:
            self._no_worker_since = now
        if now - self._no_worker_since < self.worker_timeout:
            return None
        how = "had no worker" if answered else "not answered"
        return (
            f"the Dask cluster at {shortened(self.scheduler, 80)} has {how} for "
            f"{self.worker_timeout:g} s (--worker-timeout)"
        )

    def _processes(self) -> list:
        return list((getattr(self.executor, "_processes", None) or {}).values())

    def kill(self) -> None:
        """End the local workers at once (SIGKILL)."""
        for process in self._processes():
            process.kill()

    def close(self, cancel: bool = False) -> None:
        """Shut down; with ``cancel``, drop queued tasks and end the running ones."""
        if self.client is not None:
            if self.client.status != "running":  # the scheduler is gone: the sweep says so in one line
                _silence_dask_logs()
            self.executor.shutdown(wait=not cancel)  # wait=False cancels the futures
            try:
                self.client.close(timeout=5)
            except (OSError, TimeoutError):  # the scheduler is gone: nothing left to tell it
                pass
            return
        processes = self._processes()
        self.executor.shutdown(wait=not cancel, cancel_futures=cancel)
        if cancel:  # the workers ignore SIGTERM: SIGKILL (a task is a pure function: nothing to save)
            for process in processes:
                process.kill()
            for process in processes:
                process.join(timeout=2)


def _silence_dask_logs() -> None:
    """No more of Dask's own log lines (their tracebacks of a lost connection) in this process."""
    for name in ["distributed", *logging.Logger.manager.loggerDict]:
        if name == "distributed" or name.startswith("distributed."):
            logging.getLogger(name).disabled = True


class Interrupts:
    """SIGINT or SIGTERM during a run: the first one asks the run to stop; a second ends the
    process (130 or 143: ``status``, the first signal's)."""

    def __init__(self, workers: Workers):
        self.workers = workers
        self.requested = False
        self.status = INTERRUPTED
        self._writing = False
        self._exit_pending = False
        self._previous = {}

    def __enter__(self) -> Interrupts:
        try:
            for signum in STATUS:
                self._previous[signum] = signal.signal(signum, self._handle)
        except ValueError:  # not the main thread: Ctrl-C stays a KeyboardInterrupt
            self._previous = {}
        return self

    def __exit__(self, *exc) -> None:
        for signum, previous in self._previous.items():
            signal.signal(signum, previous)

    def _handle(self, signum, frame) -> None:
        if not self.requested:
            self.requested = True
            self.status = STATUS[signum]
        elif self._writing:
            self._exit_pending = True
        else:
            self.exit_now()

    def exit_now(self) -> None:
        self.workers.kill()
        sys.stdout.flush()
        print("pendverify: interrupted again: stopped at once", file=sys.stderr, flush=True)
        os._exit(self.status)

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


def _died(exc: BaseException) -> str:
    if isinstance(exc, BrokenProcessPool):
        return "a local worker process died (killed, or out of memory)"
    return "the cluster cancelled a task of the sweep"


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
                    try:
                        pending[workers.submit(certify_chunk, *task)] = len(sets)
                    except BrokenProcessPool as exc:  # a worker died since the last results came
                        run.lost = _died(exc)
                        break
                    run.submitted += 1
                    run.peak_in_flight = max(run.peak_in_flight, len(pending))
                if run.lost or not pending:
                    break
                finished, _ = wait(list(pending), timeout=POLL_S, return_when=FIRST_COMPLETED)
                run.lost = None if finished else workers.lost()
                if run.lost:
                    break
                for future in finished:
                    del pending[future]
                    try:
                        results = future.result()
                    except (BrokenProcessPool, CancelledError) as exc:  # not the task's own error
                        run.lost = workers.lost() or _died(exc)
                        break
                    for result in results:
                        run.summary.add(result)
                        with interrupts.writing():
                            run.written += write(result, result.name in replace)
                        progress.update(1)
                if run.lost:
                    break
        finally:
            workers.close(cancel=bool(pending) or interrupts.requested or run.lost is not None)
    run.interrupted = interrupts.requested and run.summary.sets < total - skipped and not run.lost
    run.status = interrupts.status
    return run
