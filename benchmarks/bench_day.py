"""Benchmark: how long one day of a protocol takes on each backend.

    python benchmarks/bench_day.py                 # tabsa-short on both backends, tabsa synthetic
    python benchmarks/bench_day.py tabsa-short tabsa   # the robot day of each (tabsa: minutes)

One day (seed 1, ``alg2``) through :func:`experiments.days.runner.run_day`, the path the
day report takes; the baseline is the same day on the synthetic backend, measured in the
same run.  Prints wall and CPU seconds, simulated seconds per CPU second, and the ratio
robot / synthetic.  This is what decides how many robot days a machine can run
(``docs/benchmark.md``).
"""

from __future__ import annotations

import sys
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


def main(argv: list[str]) -> int:
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
