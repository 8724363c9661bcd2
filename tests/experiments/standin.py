"""A stand-in ``run_fn`` for sweep tests: a synthetic scenario run, metrics read from its trace.

It returns the same shape as :func:`experiments.sweep.workers.run_job` (a record with the
scenario, seed, settings, planner, host, date and version; flat numeric metrics)
without the robot or the planner, so sweep tests stay fast.
"""

from __future__ import annotations

import os
import socket
import time
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import tasker
from experiments.inputs import synthetic
from experiments.sweep.spec import Job
from tasker.trace import Trace

DEMO = Path(__file__).parents[2] / "experiments" / "inputs" / "scenarios" / "synthetic_demo.toml"


def trace_metrics(trace: Trace) -> dict[str, Any]:
    """A few metrics computed from the trace alone (a stand-in for ``experiments.metrics.run``)."""
    requested = {e["agent"]: e["t"] for e in trace.of("request")}
    ends = trace.of("end")
    durations = [e["t"] - requested[e["agent"]] for e in ends if e["agent"] in requested]
    return {
        "task_duration": sum(durations) / len(durations) if durations else 0.0,
        "makespan": trace.events[-1]["t"] if trace.events else 0.0,
        "switches": sum(1 for e in trace.of("command") if e["flag"] == "susp"),
        "failed_tasks": sum(1 for e in ends if e["cause"] == "failed"),
        "finished_tasks": sum(1 for e in ends if e["cause"] == "finished"),
        "stages": len(trace.of("stage", status="done")),
    }


def run(job: Job) -> tuple[dict[str, Any], dict[str, Any]]:
    """Run the job's synthetic scenario with its seed (and scheduler, if the strategy names one)."""
    scenario = synthetic.load(job.source)
    trace = synthetic.run(scenario, seed=job.seed, scheduler=job.strategy.scheduler)
    record = {
        "scenario": scenario.name, "path": job.source, "seed": job.seed,
        "settings": dict(job.strategy.items()), "planner": None, "host": socket.gethostname(),
        "date": datetime.now(UTC).isoformat(timespec="seconds"), "version": tasker.__version__,
    }
    return record, trace_metrics(trace)


def slow_run(job: Job) -> tuple[dict[str, Any], dict[str, Any]]:
    """:func:`run`, plus a pause, so a sweep can be killed while runs are in flight."""
    time.sleep(float(os.environ.get("STANDIN_SLEEP", "0.25")))
    return run(job)


def flaky_run(job: Job) -> tuple[dict[str, Any], dict[str, Any]]:
    """:func:`run`, except that seed 1 raises (a run that fails is stored as an error)."""
    if job.seed == 1:
        raise ValueError(f"seed {job.seed} is cursed")
    return run(job)


CRASH_SEED = 4


def crashing_run(job: Job) -> tuple[dict[str, Any], dict[str, Any]]:
    """:func:`run`, except that seed ``CRASH_SEED`` kills its worker process (as a segfault in native code would)."""
    if job.seed == CRASH_SEED:
        os._exit(3)
    time.sleep(0.05)  # so that other jobs are in flight when the worker dies
    return run(job)
