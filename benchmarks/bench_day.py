"""Benchmark: how long one day of a protocol takes on each backend.

    python benchmarks/bench_day.py                 # tabsa-short on both backends, tabsa synthetic
    python benchmarks/bench_day.py tabsa-short tabsa   # the robot day of each (tabsa: minutes)
    python benchmarks/bench_day.py --workers [PROTOCOL]  # a synthetic `tasker day` on 1 and 2 workers

One day (seed 1, ``alg2``) through :func:`experiments.days.runner.run_day`, the path the
day report takes; the baseline is the same day on the synthetic backend, measured in the
same run.  Prints wall and CPU seconds, simulated seconds per CPU second, and the ratio
robot / synthetic.  This is what decides how many robot days a machine can run
(``docs/benchmark.md``).

``--workers``: the days of ``PROTOCOL`` (default ``tabsa-original``, whose synthetic day
costs a few tenths of a CPU second) for five schedulers, as ``tasker day`` runs them
(:func:`experiments.days.runner.run_days`), on 1 and on 2 local workers, alternately, twice;
wall seconds, since the speed-up is what a user waits for (target >= 1.7x with two free
cores; it warns when the machine is busy).
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from experiments.days import pipeline as days  # noqa: E402
from experiments.days import runner as day_runner  # noqa: E402


def one(protocol: str, backend: str) -> tuple[float, float, dict[str, object]]:
    wall, cpu = time.perf_counter(), time.process_time()
    m = day_runner.run_day(protocol, 1, "alg2", backend)
    return time.perf_counter() - wall, time.process_time() - cpu, m


SCALING_SCHEDULERS = ("alg2", "edf", "lookahead", "tabsa-simple", "tabsa-distance")


def scaling(protocol: str, n_days: int = 8, rounds: int = 2) -> int:
    """Print the wall seconds of the same synthetic days on 1 and on 2 workers, and the speed-up."""
    from experiments.days.runner import run_days

    load = os.getloadavg()[0]
    jobs = n_days * len(SCALING_SCHEDULERS)
    print(f"tasker day --protocol {protocol}: {n_days} days x {len(SCALING_SCHEDULERS)} schedulers = {jobs} "
          f"synthetic day-runs; {os.cpu_count()} CPUs, load average {load:.2f}")
    if load > 0.5:
        print("  warning: the machine is busy; a speed-up measured now understates what 2 free cores give",
              file=sys.stderr)
    times: dict[int, list[float]] = {1: [], 2: []}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(rounds):
            for workers in (1, 2):
                start = time.perf_counter()
                rows = run_days(protocol, n_days, SCALING_SCHEDULERS, workers=workers,
                                db=Path(tmp) / f"r{r}w{workers}.db")
                times[workers].append(time.perf_counter() - start)
                failed = [r for r in rows if "error" in r]
                if len(rows) != jobs or failed:
                    print(f"  {workers} workers: {len(rows)} of {jobs} days, {len(failed)} failed", file=sys.stderr)
                    return 1
    for workers, ts in times.items():
        print(f"  {workers} worker{'s' if workers > 1 else ' '}: best {min(ts):6.2f} s ({jobs / min(ts):.1f} days/s); "
              f"all: {', '.join(f'{t:.2f}' for t in ts)}")
    ratio = min(times[1]) / min(times[2])
    print(f"speed-up 2 workers / 1 worker: {ratio:.2f}x (target >= 1.7x) {'OK' if ratio >= 1.7 else 'BELOW TARGET'}")
    return 0


def main(argv: list[str]) -> int:
    if argv[:1] == ["--workers"]:
        return scaling(argv[1] if len(argv) > 1 else "tabsa-original")
    robot = argv or ["tabsa-short"]
    print(f"{'protocol':12} {'backend':9} {'day (s)':>8} {'wall s':>8} {'cpu s':>8} {'sim s / cpu s':>13} "
          f"{'cpu ratio':>9}  completed")
    for name in robot:
        length = days.load(name).length_s
        base_wall, base_cpu, base = one(name, "synthetic")
        rob_wall, rob_cpu, rob = one(name, "robot")
        for backend, wall, cpu, m in (("synthetic", base_wall, base_cpu, base), ("robot", rob_wall, rob_cpu, rob)):
            print(f"{name:12} {backend:9} {length:8.0f} {wall:8.1f} {cpu:8.1f} {length / cpu:13.0f} "
                  f"{cpu / base_cpu:9.0f}  {m['completed']}/{m['requested']}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
