"""The worker side of a sweep: running one job, and the two backends that run many.

:func:`run_job` (the default ``run_fn``) runs one :class:`~experiments.sweep.spec.Job`;
:func:`execute` turns whatever it does into an :class:`Outcome` (an exception becomes an
``error`` outcome).  :func:`run_local` runs jobs on a pool of local worker processes and
survives a job that kills its process (it is re-run alone to find it); :func:`run_dask` runs
them on a Dask cluster.  Both yield outcomes as they finish; the driver
(:func:`experiments.sweep.driver.run_sweep`) stores them.  :func:`die_with_parent` makes every
worker process die with its driver.
"""

from __future__ import annotations

import ctypes
import itertools
import logging
import multiprocessing
import os
import signal
import socket
import sys
import tempfile
import threading
import time
import traceback
from collections import deque
from collections.abc import Callable, Generator, Iterator, Mapping, Sequence
from concurrent.futures import FIRST_COMPLETED, CancelledError, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from experiments.metrics.store import JobKey, Status
from experiments.sweep.spec import Job
from tasker.errors import TaskerError

_PR_SET_PDEATHSIG = 1  # <linux/prctl.h>

log = logging.getLogger("experiments.sweep.driver")  # the logger docs/sweeps.md names for the sweep's warnings

RunFn = Callable[[Job], tuple[Mapping[str, Any], Mapping[str, Any]]]
"""Runs one job and returns ``(record, metrics)``; must be a picklable top-level function."""


@dataclass(frozen=True)
class Outcome:
    """What a worker sends back for one job."""

    key: JobKey
    status: Status
    record: Mapping[str, Any]
    metrics: Mapping[str, Any]
    error: str | None
    wall: float
    worker: str


def run_job(job: Job) -> tuple[dict[str, Any], dict[str, Any]]:
    """The default ``run_fn``: a randomised run of the job's scenario with its seed and strategy."""
    from experiments.run.runner import run_scenario  # imported in the worker, never shared across processes

    result = run_scenario(job.source, job.options())
    return result.record.to_json(), dict(result.metrics)


def execute(run_fn: RunFn, job: Job) -> Outcome:
    """Run one job in a worker; an exception becomes an ``error`` outcome with its message."""
    worker = f"{socket.gethostname()}:{os.getpid()}"
    start = time.perf_counter()
    try:
        record, metrics = run_fn(job)
    except (Exception, SystemExit) as exc:  # a failing run is a result, and the sweep goes on
        # a mistake in the input (a TaskerError: bad scenario, protocol, world) is its message,
        # as on the command line; anything else is a bug and keeps the end of its traceback
        tb = "" if isinstance(exc, TaskerError) else "\n" + traceback.format_exc(limit=-3)
        return Outcome(job.key, Status.ERROR, {}, {}, f"{type(exc).__name__}: {exc}{tb}",
                       time.perf_counter() - start, worker)
    return Outcome(job.key, Status.OK, dict(record), dict(metrics), None, time.perf_counter() - start, worker)


def _failed(job: Job, error: str, wall: float = 0.0, worker: str = "") -> Outcome:
    """An ``error`` outcome made by the driving process (the worker could not send one)."""
    return Outcome(job.key, Status.ERROR, {}, {}, error, wall, worker)


def _exception_message(exc: BaseException) -> str:
    return f"{type(exc).__name__}: {exc}"


def _alive(pid: int) -> bool:
    """Is ``pid`` running (a zombie, killed but not yet reaped by its parent, is not)?"""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except (OSError, IndexError):  # no /proc (not Linux): the signal test alone
        return True


def die_with_parent(driver: int) -> None:
    """Make this worker process die when its parent does — even when the driver is killed with ``kill -9``.

    On Linux the kernel sends SIGKILL when the parent dies (``prctl(PR_SET_PDEATHSIG)``);
    everywhere a daemon thread also polls the parent and the driver (``driver`` is its
    pid) twice a second and exits when either is gone.  Used as the worker initializer,
    so an orphaned worker never goes on running (or holding memory) after its sweep.
    """
    parent = os.getppid()
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
        except (OSError, AttributeError):  # no libc prctl: the watchdog alone
            pass
    if not _alive(driver) or (parent == 1 and driver != 1):  # the parent died before prctl took effect
        os._exit(1)

    def watch() -> None:
        while True:
            if os.getppid() != parent or not _alive(driver):
                os._exit(1)
            time.sleep(0.5)

    threading.Thread(target=watch, name="tasker-sweep-watchdog", daemon=True).start()


def _mp_context() -> multiprocessing.context.BaseContext:
    # never fork: MuJoCo and OMPL objects (and threads) of the parent must not leak into workers
    method = "forkserver" if "forkserver" in multiprocessing.get_all_start_methods() else "spawn"
    return multiprocessing.get_context(method)


def _execute_marked(run_fn: RunFn, job: Job, mark: str) -> Outcome:
    """:func:`execute`, after leaving a file at ``mark``: the driver then knows the job had started."""
    try:
        Path(mark).write_text(str(os.getpid()), encoding="utf-8")
    except OSError:  # only a hint; without it the driver suspects every job the broken pool held
        pass
    return execute(run_fn, job)


def _died(exitcode: int | None, hook: str | None = None) -> str:
    """The message of a job whose worker process died while running it alone (in ``hook``, a
    ``task.py`` hook named with its folder, when one was running)."""
    if exitcode is None:
        how = "exit code unknown"
    elif exitcode < 0:
        try:
            name = signal.Signals(-exitcode).name
        except ValueError:
            name = f"signal {-exitcode}"
        how = f"killed by {name}, exit code {exitcode}"
    else:
        how = f"exit code {exitcode}"
    if hook is not None:
        return (f"worker process died ({how}) while running this job alone, in the task.py hook {hook} "
                "(a hook that calls os._exit or kills its process ends the run it is in)")
    return (f"worker process died ({how}) while running this job alone "
            "(a crash in native code, os._exit, or the OOM killer)")


def _alone_child(conn: Any, run_fn: RunFn, job: Job, driver: int, mark: str) -> None:
    """The body of the process that runs one job alone: send its outcome back, or die trying
    (leaving in ``mark`` the task.py hook that was running, :mod:`tasker.support.hookmark`)."""
    from tasker.support import hookmark

    die_with_parent(driver)
    hookmark.use(mark)
    out = execute(run_fn, job)
    try:
        conn.send(out)
    except Exception as exc:  # e.g. a record that cannot be pickled
        conn.send(_failed(job, f"the result could not be sent back: {_exception_message(exc)}", out.wall,
                          out.worker))
    conn.close()


def _alone(run_fn: RunFn, job: Job, ctx: Any) -> Outcome:  # a multiprocessing context (spawn or forkserver)
    """Run one job alone in a fresh worker process; if the process dies, an ``error`` outcome that says
    so, naming the ``task.py`` hook (and its folder) that was running if one was."""
    from tasker.support import hookmark

    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="tasker-alone-") as tmp:
        mark = hookmark.create(Path(tmp) / "hook")
        receiver, sender = ctx.Pipe(duplex=False)
        proc = ctx.Process(target=_alone_child, args=(sender, run_fn, job, os.getpid(), str(mark)),
                           name=f"tasker-sweep-alone-{job.seed}")
        proc.start()
        sender.close()  # so that receiving ends (EOFError) when the process dies without sending
        out: Outcome | None = None
        try:
            out = receiver.recv()
        except EOFError:  # it died without sending: wait for its exit code
            proc.join(timeout=30)
        finally:
            receiver.close()
            if proc.is_alive():  # interrupted (Ctrl-C), or it closed the pipe and kept going
                proc.terminate()
            proc.join()
        hook = hookmark.read(mark)
    if out is not None:
        return out
    return _failed(job, _died(proc.exitcode, hook), time.perf_counter() - start,
                   f"{socket.gethostname()}:{proc.pid}")


def _pool_pass(run_fn: RunFn, queue: deque[Job], workers: int, ctx: multiprocessing.context.BaseContext,
               marks: Path, serial: Iterator[int]) -> Generator[Outcome, None, list[Job]]:
    """Run jobs from ``queue`` on one pool of ``workers`` processes, yielding outcomes as they finish.

    Returns ``[]`` when the queue is empty and every job finished.  If a worker process
    dies (the pool breaks), returns the jobs that had started and sent no result (those
    that may have killed it), after yielding every result that did arrive and putting
    the jobs that had not started back at the front of ``queue``.
    """
    pending: dict[Future[Outcome], tuple[Job, Path]] = {}
    with ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=die_with_parent,
                             initargs=(os.getpid(),)) as pool:
        try:
            broken = False
            while not broken:
                while len(pending) < 2 * workers and queue:
                    job = queue.popleft()
                    mark = marks / str(next(serial))
                    try:
                        fut = pool.submit(_execute_marked, run_fn, job, str(mark))
                    except BrokenProcessPool:
                        queue.appendleft(job)
                        broken = True
                        break
                    pending[fut] = (job, mark)
                if not pending:
                    return []
                if not broken:
                    done, _ = wait(pending, return_when=FIRST_COMPLETED)
                    for fut in done:
                        try:
                            out = fut.result()
                        except BrokenProcessPool:
                            broken = True
                            continue
                        except Exception as exc:  # e.g. a result that could not be pickled
                            out = _failed(pending[fut][0], _exception_message(exc))
                        pending.pop(fut)
                        yield out
            # The pool is broken: every future it held fails at once.  Keep what did arrive.
            wait(pending, timeout=60)
            started: list[Job] = []
            not_started: list[Job] = []
            for fut, (job, mark) in pending.items():  # in the order submitted
                error = fut.exception(timeout=0) if fut.done() and not fut.cancelled() else BrokenProcessPool()
                if error is None:
                    yield fut.result()  # finished before the pool broke
                elif not isinstance(error, BrokenProcessPool):
                    yield _failed(job, _exception_message(error))
                else:
                    (started if mark.exists() else not_started).append(job)
            pending.clear()
            if not started:  # no job says it started (e.g. a worker died before taking one): suspect them all
                started, not_started = not_started, []
            queue.extendleft(reversed(not_started))
            return started
        finally:
            for fut in pending:
                fut.cancel()


def run_local(run_fn: RunFn, jobs: Sequence[Job], workers: int) -> Iterator[Outcome]:
    """Outcomes as they finish from a pool of local worker processes (at most 2×workers queued).

    A job that kills its worker process breaks the pool.  Then the jobs that were in
    flight are run again one at a time, each alone in a fresh process: one that kills
    that process too becomes an ``error`` outcome that says so, the others run normally;
    and the remaining jobs go on in a fresh pool.  Every job thus ends with an outcome.
    """
    ctx = _mp_context()
    queue = deque(jobs)
    serial = itertools.count()
    with tempfile.TemporaryDirectory(prefix="tasker-sweep-") as marks:
        while queue:
            suspects = yield from _pool_pass(run_fn, queue, workers, ctx, Path(marks), serial)
            if suspects:
                log.warning("a worker process died; running the %d job(s) that were in flight one at a time to "
                            "find the one that kills it", len(suspects))
            for job in suspects:
                out = _alone(run_fn, job, ctx)
                if out.status is Status.ERROR and out.error and out.error.startswith("worker process died"):
                    log.warning("%s: %s", job.key, out.error)
                yield out


def run_dask(run_fn: RunFn, jobs: Sequence[Job], address: str) -> Iterator[Outcome]:
    """Outcomes as they finish from the Dask cluster at ``address``.

    A job whose worker process dies is retried by Dask on other workers (up to the
    scheduler's ``allowed-failures``); when Dask gives up (``KilledWorker``), or the
    job's future fails otherwise, the job gets an ``error`` outcome.  A cancelled
    future (e.g. the cluster restarted) leaves its job for a later resumption.
    """
    import distributed
    from distributed.scheduler import KilledWorker

    with distributed.Client(address, set_as_default=False) as client:
        futures = {client.submit(execute, run_fn, job, pure=False): job for job in jobs}
        try:
            for fut in distributed.as_completed(list(futures), loop=client.loop):
                job = futures[fut]
                if fut.cancelled():
                    log.warning("%s: Dask cancelled the job; it stays for a later resumption", job.key)
                    continue
                try:
                    out = fut.result()
                except KilledWorker as exc:
                    out = _failed(job, f"worker process died while running this job, on every worker Dask "
                                       f"tried ({_exception_message(exc)})")
                except CancelledError:
                    log.warning("%s: Dask cancelled the job; it stays for a later resumption", job.key)
                    continue
                except Exception as exc:  # the future failed outside run_fn (e.g. a result that did not pickle)
                    out = _failed(job, _exception_message(exc))
                yield out
        finally:
            client.cancel([f for f in futures if not f.done()])
