"""Sweeps: many runs of scenarios × seeds × strategies, in parallel, resumable — the driver.

A :class:`~experiments.sweep.spec.SweepSpec` (usually read from a small TOML file by
:func:`experiments.sweep.spec.load_spec`) expands to a list of jobs; :func:`run_sweep` runs
those whose key is not in the results database yet, on local worker processes or on a Dask
cluster (:mod:`experiments.sweep.workers`), and this driving process stores each result
(:mod:`experiments.metrics.store`) the moment it arrives.  Killing a sweep loses only the runs in
flight; running it again resumes.  A job that raises, or that kills its worker process, is
stored as an ``error`` run and the sweep goes on.  :func:`lease` keeps a second driver off
the same database.

The function that runs one job is injectable (``run_fn``): a picklable top-level
function ``job -> (record, metrics)``.  The default, :func:`experiments.sweep.workers.run_job`,
calls :func:`experiments.run.runner.run_scenario` with ``randomize=True``, so each seed is a
different randomised variant of the scenario.  See ``docs/sweeps.md``.
"""

from __future__ import annotations

import dataclasses
import fcntl
import os
import platform
import socket
import sys
import time
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import tasker
from experiments.metrics.store import ResultStore, RunRow, Status
from experiments.sweep.spec import Job, SweepSpec, looks_like_path
from experiments.sweep.workers import RunFn, run_dask, run_job, run_local
from tasker.errors import SweepError as SweepError  # defined there; re-exported here


@dataclass(frozen=True)
class SweepSummary:
    """What :func:`run_sweep` did: ``total`` jobs in the spec, ``skipped`` because stored, and the rest."""

    total: int
    skipped: int
    ran: int
    ok: int
    errors: int
    not_run: int
    wall: float
    backend: str
    job_wall: float = 0.0
    """Worker wall seconds of the jobs this call ran (their sum), for an estimate of the rest."""
    workers: int = 1

    def remaining_s(self, mean_job_s: float | None = None) -> float | None:
        """Wall seconds the ``not_run`` jobs should take on as many workers, at ``mean_job_s`` a job
        (default: the mean of the jobs this call ran); None with nothing to go by."""
        per = mean_job_s if mean_job_s is not None else (self.job_wall / self.ran if self.ran else None)
        if per is None or not self.not_run:
            return None if per is None else 0.0
        return per * self.not_run / max(1, self.workers)


@contextmanager
def lease(db_path: str | Path) -> Iterator[None]:
    """Hold the sweep lease of a results database: one driver at a time, or a clear :class:`SweepError`.

    An exclusive ``flock`` on ``<db>.lock``, which says who holds it, removed when the lease
    ends.  The kernel drops the lock when the holder dies, even by ``kill -9``, so a stale
    lease (a file left by a killed driver) never blocks a resumption.  Readers (``tasker
    report``) take no lease.
    """
    lock = Path(f"{db_path}.lock")
    try:
        lock.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise SweepError(f"{db_path}: cannot take the sweep lease ({lock}: {exc.strerror or exc})") from None
    while True:
        try:
            fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            raise SweepError(f"{db_path}: cannot take the sweep lease ({lock}: {exc.strerror or exc})") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 512, 0).decode("utf-8", "replace").strip() or "another process"
            os.close(fd)
            raise SweepError(f"{db_path}: another sweep is running on this database ({holder}); two drivers "
                             "would run the same jobs. Wait for it to end (then run again to resume), or use "
                             "another database") from None
        try:  # the holder before us deletes the file as it ends: a lock on a deleted file holds nothing
            same = os.fstat(fd).st_ino == os.stat(lock).st_ino
        except FileNotFoundError:
            same = False
        if same:
            break
        os.close(fd)
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"pid {os.getpid()} on {socket.gethostname()}, since "
                      f"{datetime.now(UTC).isoformat(timespec='seconds')}".encode(), 0)
        yield
    finally:
        try:  # removed while still held, so no one can take a lock on the file being removed
            lock.unlink()
        except OSError:
            pass
        fcntl.flock(fd, fcntl.LOCK_UN)
        os.close(fd)


def absolute_source(source: str) -> str:
    """A job's scenario as an absolute path (a shipped scenario name stays a name): workers may run elsewhere."""
    p = Path(source)
    if p.is_absolute():
        return source
    if p.exists() or looks_like_path(source):
        return str(p.resolve())
    return source


def precheck(jobs: Iterable[Job]) -> None:
    """Every check a job would fail, before any job runs: each distinct scenario is loaded once, and
    for each of its strategies the first job's run is built — its randomised variant drawn (with the
    spec's interruption grid), its world, task types and scheduler made — without running it.  A
    fault is a :class:`SweepError` naming the scenario and the strategy (the file's own errors keep
    their file and line): values that pass the spec's checks and then fail every job stop here."""
    from experiments.inputs import scenario as scenarios
    from experiments.inputs import synthetic
    from experiments.run.runner import build_robot

    first: dict[tuple[str, str], Job] = {}
    for j in jobs:
        first.setdefault((j.source, j.strategy.label), j)
    loaded: dict[str, Any] = {}
    for (source, label), job in sorted(first.items()):
        path = scenarios.resolve(source)
        if source not in loaded:  # its own faults: the scenario's error, with its file and line
            robot = scenarios.kind_of(path) == "robot"
            loaded[source] = (scenarios.load(path, task_paths=job.task_paths) if robot else synthetic.load(path))
        scn, st = loaded[source], job.strategy
        try:
            if isinstance(scn, scenarios.RobotScenario):
                variant = scenarios.randomize(scn, job.seed, interruption=job.interruption)
                build_robot(variant, job.options())
            else:
                synthetic.build(scn, seed=job.seed, scheduler=st.scheduler)
        except Exception as exc:  # noqa: BLE001 - whatever it is, every job like it would fail
            raise SweepError(f"scenario {job.scenario!r} with strategy {label!r} (seed {job.seed}) cannot run, so no "
                             f"job of it would: {type(exc).__name__}: {exc}") from None


def _setup(workers: int, address: str | None) -> dict[str, Any]:
    return {"backend": "dask" if address else "local", "workers": None if address else workers,
            "scheduler_address": address,
            "host": socket.gethostname(), "platform": platform.platform(), "python": sys.version.split()[0],
            "tasker": tasker.__version__, "date": datetime.now(UTC).isoformat(timespec="seconds")}


def run_sweep(
    spec: SweepSpec | Iterable[Job],
    db_path: str | Path,
    *,
    workers: int | None = None,
    scheduler_address: str | None = None,
    run_fn: RunFn = run_job,
    retry_errors: bool = False,
    max_jobs: int | None = None,
    progress: bool = True,
) -> SweepSummary:
    """Run the jobs of ``spec`` that ``db_path`` does not hold yet; store each as it finishes.

    ``workers`` local processes (default: the CPU count) unless ``scheduler_address``
    names a Dask scheduler, whose workers are used instead.  A job that raises is stored
    with status ``error`` and its message; it is run again only with ``retry_errors``.
    So is a job that kills its worker process (a segfault, ``os._exit``, the OOM
    killer): locally, the jobs that were in flight are run again one at a time, each
    alone in a fresh process, to find it (the others are stored as they end), and the
    sweep goes on in a fresh pool; on Dask, once Dask gives up retrying it (``KilledWorker``).
    ``max_jobs`` stops after starting that many jobs (the rest stay missing, for a later
    resumption).  Results are written by this process only, one transaction per run.
    """
    jobs = [dataclasses.replace(j, source=absolute_source(j.source))
            for j in (spec.jobs() if isinstance(spec, SweepSpec) else list(spec))]
    keys = [j.key for j in jobs]
    if len(set(keys)) != len(keys):
        raise SweepError("two jobs have the same key (scenario, seed, strategy)")
    if workers is not None and workers < 1:
        raise SweepError(f"workers: expected a positive number, got {workers}")
    n_workers = workers or os.cpu_count() or 1
    start = time.perf_counter()
    backend = "dask" if scheduler_address else "local"
    if run_fn is run_job:
        precheck(jobs)
    with lease(db_path), ResultStore(db_path) as store:
        if retry_errors:
            store.forget(set(keys) & store.keys(Status.ERROR))
        stored = store.keys()
        todo = [j for j in jobs if j.key not in stored]
        missing = len(todo)
        if max_jobs is not None:
            todo = todo[:max(0, max_jobs)]
        spec_json = spec.to_json() if isinstance(spec, SweepSpec) else {"jobs": [list(k) for k in keys]}
        store.log_sweep(spec_json, _setup(n_workers, scheduler_address) | {"to_run": len(todo)})
        ok = errors = 0
        job_wall = 0.0
        if todo:
            from tqdm import tqdm

            outcomes = (run_dask(run_fn, todo, scheduler_address) if scheduler_address
                        else run_local(run_fn, todo, n_workers))
            by_key = {j.key: j for j in todo}
            with tqdm(total=len(todo), unit="run", disable=not progress, desc=f"sweep ({backend})") as bar:
                for out in outcomes:
                    job = by_key[out.key]
                    store.add(RunRow(job.scenario, job.seed, job.strategy.label, out.status,
                                     dict(out.record), dict(out.metrics), out.error, out.wall, out.worker))
                    job_wall += out.wall
                    if out.status is Status.OK:
                        ok += 1
                    else:
                        errors += 1
                    bar.update()
                    bar.set_postfix(errors=errors, refresh=False)
    ran = ok + errors
    return SweepSummary(total=len(jobs), skipped=len(jobs) - missing, ran=ran, ok=ok, errors=errors,
                        not_run=missing - ran, wall=time.perf_counter() - start, backend=backend,
                        job_wall=job_wall, workers=n_workers)
