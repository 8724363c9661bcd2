"""Benchmark of the TaskER core: harmonisation tick cost and loop real-time factor.

    python benchmarks/bench_core.py

1. One harmonisation tick (``f^harm`` with ``pf_schedule`` of Alg. 2 comparing the
   best candidate with the executing agent) with 10, 100 and 1,000 waiting agents.
   Baseline, measured in the same run: the 10-agent tick; growth must be no worse
   than linear (ratio per agent <= 1).  Target: <= 1 ms at 1,000 agents.
2. Real-time factor of the simulation loop on 50 synthetic tasks with every rate at
   10 Hz (sFreq, repRate, taskExeRate, SPupRate).  Target: >= 1,000x real time.
"""

from __future__ import annotations

import statistics
import time

from tasker import schedulers
from tasker.agent import Rates
from tasker.loop import SimulationLoop
from tasker.stage import Stage, StageKind
from tasker.store import TaskStore
from tasker.synthetic import SyntheticTask, TimedExecutor


def _stages() -> list[Stage]:
    return [Stage("approach", duration=20.0), Stage("work", duration=10.0, kind=StageKind.BLOCKING),
            Stage("leave", duration=20.0)]


def tick_cost(n: int, repeats: int = 200) -> float:
    """Median seconds of one harmoniser step with ``n`` waiting agents and a forced schedule."""
    task = SyntheticTask("t", _stages())
    loop = SimulationLoop(TaskStore([task]), schedulers.create("alg2"), core=TimedExecutor(),
                          rates=Rates(rep_rate=0.01, task_exe_rate=10.0, sp_up_rate=0.01))
    loop.request(0.0, "t", {"weight": 1000.0, "site": [0.0, 0.0]})  # d1: executes, never worth leaving
    for i in range(n):
        loop.request(0.5, "t", {"weight": 1.0 + i * 1e-3, "site": [float(i % 10), 1.0]})
    loop.run(until=1.0)
    h = loop.harmoniser
    assert h.exe_da == "d1" and len(h.idle_da) == n, (h.exe_da, len(h.idle_da))
    samples = []
    for _ in range(repeats):
        h._new_data = True  # a report changed: shdl_event
        t0 = time.perf_counter()
        h.step(1.0, timer=True)
        samples.append(time.perf_counter() - t0)
    assert h.irr_da is None, "the benchmark must measure a compare-and-stay decision"
    return statistics.median(samples)


def real_time_factor(n_tasks: int = 50, hz: float = 10.0) -> tuple[float, float, float]:
    tasks = [SyntheticTask("guide", _stages(), weight=1.0),
             SyntheticTask("fell", [Stage("approach", duration=15.0), Stage("check", duration=5.0)], weight=3.0)]
    loop = SimulationLoop(TaskStore(tasks), schedulers.create("alg2", classes=[["fell"], ["guide"]], hysteresis=0.9),
                          core=TimedExecutor(seed=1, jitter=0.2), s_freq=hz, rates=Rates(hz, hz, hz), seed=1)
    for i in range(n_tasks):
        kind = "fell" if i % 5 == 4 else "guide"
        loop.request(i * 20.0, kind, {"site": [float(i % 7), float(i % 3)]})
    t0 = time.perf_counter()
    trace = loop.run()
    wall = time.perf_counter() - t0
    sim = trace.events[-1]["t"]
    assert len(trace.of("end")) == n_tasks
    return sim / wall, sim, wall


def main() -> None:
    print("harmonisation tick (Alg. 2 compare), median of 200")
    base = tick_cost(10)
    for n in (10, 100, 1000):
        t = base if n == 10 else tick_cost(n)
        per_agent_ratio = (t / base) / (n / 10)
        print(f"  {n:5d} waiting agents: {t * 1e3:8.3f} ms   x{t / base:6.1f} vs 10 agents   "
              f"growth/linear = {per_agent_ratio:4.2f}   {'OK' if n < 1000 or t <= 1e-3 else 'ABOVE 1 ms TARGET'}")
    rtf, sim, wall = real_time_factor()
    print(f"loop, 50 synthetic tasks at 10 Hz: {sim:.0f} s simulated in {wall:.2f} s wall = "
          f"{rtf:,.0f}x real time (target >= 1,000x) {'OK' if rtf >= 1000 else 'BELOW TARGET'}")


if __name__ == "__main__":
    main()
