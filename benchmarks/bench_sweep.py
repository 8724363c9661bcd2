"""Benchmark of sweeps: speed-up of 2 local worker processes over 1.

    python benchmarks/bench_sweep.py [--jobs N] [--job-seconds S]

The same sweep of CPU-bound jobs (each job runs the synthetic demo scenario with
many seeds, about ``S`` seconds of work) is run into a fresh results database with
1 worker and with 2, alternately, ``--rounds`` times in the same run; each count's
best wall time is kept (a shared machine only ever makes a run slower).  Wall
times include starting the worker processes and storing every result, as a user
sees them.  Baseline: the 1-worker sweep.  Target: speed-up >= 1.7x on a machine
with at least 2 free cores.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from experiments.inputs import synthetic  # noqa: E402
from experiments.inputs.strategy import Strategy  # noqa: E402
from experiments.metrics.store import ResultStore  # noqa: E402
from experiments.sweep.driver import run_sweep  # noqa: E402
from experiments.sweep.spec import Job, SweepSpec  # noqa: E402

DEMO = ROOT / "experiments" / "inputs" / "scenarios" / "synthetic_demo.toml"


def cpu_job(job: Job) -> tuple[dict[str, Any], dict[str, Any]]:
    """``REPS`` synthetic runs (seeds derived from the job's): pure-Python CPU work, no I/O."""
    reps = int(os.environ["BENCH_SWEEP_REPS"])
    scenario = synthetic.load(job.source)
    events = 0
    for i in range(reps):
        events += len(synthetic.run(scenario, seed=job.seed * 10_000 + i).events)
    return {"seed": job.seed, "reps": reps}, {"events": events}


def _one_run_seconds() -> float:
    scenario = synthetic.load(DEMO)
    synthetic.run(scenario, seed=0)
    start = time.perf_counter()
    for i in range(20):
        synthetic.run(scenario, seed=i)
    return (time.perf_counter() - start) / 20


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=24, help="jobs in the sweep (default 24)")
    parser.add_argument("--job-seconds", type=float, default=0.2, help="CPU seconds per job (default 0.2)")
    parser.add_argument("--rounds", type=int, default=2, help="alternate 1 and 2 workers this many times (default 2)")
    args = parser.parse_args()
    reps = max(1, round(args.job_seconds / _one_run_seconds()))
    os.environ["BENCH_SWEEP_REPS"] = str(reps)  # read by the workers, which inherit the environment
    spec = SweepSpec(("demo",), tuple(range(args.jobs)), (Strategy(),), sources={"demo": str(DEMO)})
    load = os.getloadavg()[0]
    print(f"sweep of {args.jobs} jobs x {reps} synthetic runs each; {os.cpu_count()} CPUs, load average {load:.2f}")
    if load > 0.5:
        print("  warning: the machine is busy; a speed-up measured now understates what 2 free cores give",
              file=sys.stderr)
    times: dict[int, list[float]] = {1: [], 2: []}
    job_walls: dict[int, list[float]] = {1: [], 2: []}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(args.rounds):
            for workers in (1, 2):
                start = time.perf_counter()
                summary = run_sweep(spec, Path(tmp) / f"r{r}w{workers}.db", workers=workers, run_fn=cpu_job,
                                    progress=False)
                times[workers].append(time.perf_counter() - start)
                with ResultStore(Path(tmp) / f"r{r}w{workers}.db") as store:
                    job_walls[workers] += [row.wall or 0.0 for row in store.rows()]
                if summary.ok != args.jobs:
                    print(f"  {workers} workers: {summary.errors} jobs failed", file=sys.stderr)
                    return 1
    for workers, ts in times.items():
        print(f"  {workers} worker{'s' if workers > 1 else ' '}: best {min(ts):5.2f} s "
              f"({args.jobs / min(ts):.1f} jobs/s); all: {', '.join(f'{t:.2f}' for t in ts)}; "
              f"mean job {sum(job_walls[workers]) / len(job_walls[workers]):.3f} s, workers busy "
              f"{sum(job_walls[workers]) / (sum(ts) * workers):.0%}")
    print("  (a job slower on 2 workers than on 1 means the 2 cores were not both free)")
    ratio = min(times[1]) / min(times[2])
    print(f"speed-up 2 workers / 1 worker: {ratio:.2f}x (target >= 1.7x) {'OK' if ratio >= 1.7 else 'BELOW TARGET'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
