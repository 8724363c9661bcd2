"""Running many days: each (day, scheduler, strategy) a job of the sweep runner, stored as it ends.

:func:`run_days` runs N days x schedulers (x strategies) of a protocol on a backend (days made
by :mod:`experiments.days.pipeline`): local processes or Dask, each day stored in a results
database as it ends (so a stopped run resumes; :mod:`experiments.days.resume` checks what it
resumes), a failed day stored and listed while the others go on.  :func:`run_day` is one day:
its metrics (:mod:`experiments.metrics.day`, and on the robot backend
:mod:`experiments.metrics.paths`).
"""

from __future__ import annotations

import dataclasses
import functools
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from experiments.days import pipeline as day_pipeline
from experiments.days import protocol as protocols
from experiments.days.resume import check_resumable, scenario_key
from experiments.inputs.strategy import Strategy
from experiments.metrics.day import day_metrics, hazard_metrics
from experiments.metrics.paths import path_metrics
from experiments.metrics.store import ResultStore, Status
from experiments.sweep.driver import run_sweep
from experiments.sweep.spec import Job
from experiments.trace.timeline import Timeline
from tasker.errors import ConfigError


def scheduler_options(proto: protocols.Protocol, name: str, backend: str = "synthetic", seed: int = 0,
                      ) -> dict[str, Any]:
    """Options each scheduler gets from the protocol (:func:`experiments.days.pipeline.scheduler_options`)."""
    return day_pipeline.scheduler_options(proto, name, backend, seed)


def run_day(protocol: str, seed: int, scheduler: str, backend: str = "synthetic",
            keep: str | None = None, strategy: Strategy | None = None) -> dict[str, Any]:
    """One day under one scheduler: its metrics (a top-level function, so processes can run it).

    ``keep``: a folder to keep the run's files in (trace; robot: trajectory, run.json).
    ``strategy``: its update/suspension/policy/hazard-waiting factors (robot backend only;
    its scheduler, if any, must be ``scheduler``)."""
    settings = {k: v for k, v in (strategy.items() if strategy else []) if k != "scheduler"}
    if strategy is not None and strategy.scheduler not in (None, scheduler):
        raise ConfigError(f"run_day: strategy {strategy.label!r} names another scheduler than {scheduler!r}")
    day = day_pipeline.make(protocol, seed, backend=backend, scheduler=scheduler)
    run = day.run(out=keep, **settings)
    proto = day.protocol
    kinds = {v: k for k, v in day_pipeline.task_names(proto, backend).items()}
    tl = Timeline.of(run.events)  # the day's trace, read once
    out = {"scheduler": scheduler, "seed": seed, "backend": backend, "strategy": Strategy(**settings).label,
           **day_metrics(tl, day_end=proto.length_s, kinds=kinds, step_s=proto.step_s)}
    if backend == "robot":
        out |= path_metrics(tl, run.samples)
        out |= hazard_metrics(tl)
        out["wall_time_s"] = run.record.get("wall_time_s")  # not in the table: how long the day took here
    return out


def day_job(job: Job, *, backend: str, keep: str | None = None,
            digest: str | None = None) -> tuple[dict[str, Any], dict[str, Any]]:
    """A sweep's ``run_fn`` for days: the job's scenario is ``PROTOCOL@BACKEND``, its source the
    protocol, its strategy's scheduler the day's.  Returns ``(record, metrics)``; the metrics are
    :func:`run_day`'s, the record holds the protocol's ``digest`` (:meth:`Protocol.digest`)."""
    st = job.strategy
    if st.scheduler is None:
        raise ConfigError(f"day job {job.key}: its strategy names no scheduler")
    rest = dataclasses.replace(st, scheduler=None)
    where = None if keep is None else str(Path(keep) / _folder(rest) / st.scheduler / str(job.seed))
    metrics = run_day(job.source, job.seed, st.scheduler, backend, where, strategy=rest)
    record = {"protocol": job.source, "backend": backend, "seed": job.seed, "scheduler": st.scheduler,
              "strategy": rest.label, "wall_time_s": metrics.get("wall_time_s"), "protocol_digest": digest}
    return record, metrics


def _folder(strategy: Strategy) -> str:
    """Where ``--keep-runs`` puts a strategy's days: nowhere extra for the day's own settings."""
    return "" if strategy.label == "default" else strategy.label.replace(",", "_").replace("=", "-")



def run_days(protocol: str | Path, days: int, names: Sequence[str], *, first_seed: int = 1,
             workers: int = 2, backend: str = "synthetic", db: Path | None = None,
             keep: Path | None = None, strategies: Sequence[Strategy] = (Strategy(),),
             address: str | None = None, progress: bool = False,
             retry_errors: bool = False) -> list[dict[str, Any]]:
    """Every (day, scheduler, strategy); results sorted by strategy, scheduler, then seed.

    The days are the jobs of a sweep (:func:`experiments.sweep.driver.run_sweep`, ``run_fn`` =
    :func:`day_job`): ``workers`` local processes, or the Dask cluster at ``address``;
    each day is stored in the results database ``db`` (a temporary one if ``None``) as it
    ends, and days already there are not run again (resumption).  A day that raises, or
    kills its worker, is stored as an ``error`` and the others go on: it comes back as
    ``{"scheduler", "seed", "strategy", "error"}`` (no metrics), which :func:`report` lists
    apart (``retry_errors``: run those again).  ``keep``: keep each run's files in
    ``keep/[STRATEGY/]SCHEDULER/SEED``."""
    proto = day_pipeline.load(protocol)  # a bad protocol fails here, once, with its file and line
    scenario = scenario_key(protocol, backend)
    if db is not None:
        check_resumable(db, scenario, proto)
    jobs = [Job(scenario, str(protocol), seed, dataclasses.replace(st, scheduler=name))
            for seed in range(first_seed, first_seed + days) for st in strategies for name in names]
    # seed-major: a run stopped early leaves every scheduler with (nearly) as many days
    run_fn = functools.partial(day_job, backend=backend, keep=None if keep is None else str(keep),
                               digest=proto.digest())
    with tempfile.TemporaryDirectory(prefix="tasker-days-") as tmp:
        path = db if db is not None else Path(tmp) / "days.db"
        run_sweep(jobs, path, workers=workers, scheduler_address=address, run_fn=run_fn, progress=progress,
                  retry_errors=retry_errors)
        with ResultStore(path, readonly=True) as store:
            rows = {r.key: r for r in store.rows()}
    results = []
    for job in jobs:
        row = rows.get(job.key)
        if row is None:  # not run (e.g. Dask cancelled it): left for a resumption
            continue
        st = dataclasses.replace(job.strategy, scheduler=None)
        if row.status is Status.OK:
            results.append(dict(row.metrics))
        else:
            results.append({"scheduler": job.strategy.scheduler, "seed": job.seed, "backend": backend,
                            "strategy": st.label, "error": row.error or "failed"})
    s_order = {st.label: k for k, st in enumerate(strategies)}
    order = {n: k for k, n in enumerate(names)}
    return sorted(results, key=lambda r: (s_order.get(r.get("strategy", "default"), 0), order[r["scheduler"]],
                                          r["seed"]))
