"""Benchmark of the TaskER core: harmonisation tick cost and loop real-time factor.

    python benchmarks/bench_core.py

1. One harmonisation tick (``f^harm`` with ``pf_schedule`` of Alg. 2 comparing the
   best candidate with the executing agent) with 10, 100 and 1,000 waiting agents.
   Baselines, measured in the same run: the 10-agent tick (growth must be no worse
   than linear: ratio per agent <= 1), and the same tick with the scan the
   candidate index replaces (``TaskHarmoniser.incremental = False``: every waiting
   agent read at every decision), printed beside it.  Target: <= 1 ms at 1,000.
2. Real-time factor of the simulation loop on 50 synthetic tasks with every rate at
   10 Hz (sFreq, repRate, taskExeRate, SPupRate).  Target: >= 1,000x real time.
3. At the scale of a day (issue 12): the tick with 10,000 waiting agents (target <= 1 ms),
   with the scan beside it, and its worst case for the index: every waiting agent
   reported since the last tick, so all are re-keyed (one ``heapify``) — what a
   tick costs when reports are as frequent as decisions;
   and the loop over 100, 300 and 1,000 synthetic tasks, rates at 1 Hz (as in the
   scenarios), at two loads: a task every 60 s (the robot keeps up: a queue forms and
   drains, as in a day) and every 10 s (overload: the queue grows all run long).
   Baseline, measured in the same run: the 100-task loop's wall time per task.  Under a
   steady load, growth must stay linear (wall per task at n / at 100 <= 1.5) and 1,000
   tasks run >= 1,000x real time.  Under overload, every waiting agent reports at
   ``repRate`` (Alg. 1), so reports grow with queue length x time, i.e. quadratically in
   n: that case is printed, not held to the target.
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


def tick_cost(n: int, repeats: int = 200, *, incremental: bool = True, all_reported: bool = False) -> float:
    """Median seconds of one harmoniser step with ``n`` waiting agents and a forced schedule.

    ``incremental=False``: the scan (the reference); ``all_reported``: every agent
    marked as having reported since the last tick (the index's worst case)."""
    task = SyntheticTask("t", _stages())
    loop = SimulationLoop(TaskStore([task]), schedulers.create("alg2"), core=TimedExecutor(),
                          rates=Rates(rep_rate=0.01, task_exe_rate=10.0, sp_up_rate=0.01))
    loop.request(0.0, "t", {"weight": 1000.0, "site": [0.0, 0.0]})  # d1: executes, never worth leaving
    for i in range(n):
        loop.request(0.5, "t", {"weight": 1.0 + i * 1e-3, "site": [float(i % 10), 1.0]})
    loop.run(until=1.0)
    h = loop.harmoniser
    h.incremental = incremental
    assert h.exe_da == "d1" and len(h.idle_da) == n, (h.exe_da, len(h.idle_da))
    samples = []
    for _ in range(repeats):
        h._new_data = True  # a report changed: shdl_event
        if all_reported and h._index is not None:
            for agent in h.agents:
                h._index.touch(agent)
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


def queue_factor(n_tasks: int, every: float) -> tuple[float, float, float]:
    """(real-time factor, simulated s, wall s) of ``n_tasks`` tasks arriving every ``every`` s,
    each ~45 s of work plus travel."""
    tasks = [SyntheticTask("guide", _stages(), weight=1.0),
             SyntheticTask("fell", [Stage("approach", duration=15.0), Stage("check", duration=5.0)], weight=3.0)]
    loop = SimulationLoop(TaskStore(tasks), schedulers.create("alg2", classes=[["fell"], ["guide"]], hysteresis=0.9),
                          core=TimedExecutor(seed=1, jitter=0.2), s_freq=1.0, rates=Rates(1.0, 10.0, 1.0), seed=1)
    for i in range(n_tasks):
        loop.request(i * every, "fell" if i % 5 == 4 else "guide", {"site": [float(i % 7), float(i % 3)]})
    t0 = time.perf_counter()
    trace = loop.run()
    wall = time.perf_counter() - t0
    assert len(trace.of("end")) == n_tasks
    sim = trace.events[-1]["t"]
    return sim / wall, sim, wall


def main() -> None:
    print("harmonisation tick (Alg. 2 compare), median of 200; scan = the same tick without the candidate index")
    base = tick_cost(10)
    for n in (10, 100, 1000):
        t = base if n == 10 else tick_cost(n)
        scan = tick_cost(n, incremental=False)
        per_agent_ratio = (t / base) / (n / 10)
        print(f"  {n:5d} waiting agents: {t * 1e3:8.3f} ms   x{t / base:6.1f} vs 10 agents   "
              f"growth/linear = {per_agent_ratio:4.2f}   scan {scan * 1e3:7.3f} ms = x{scan / t:6.1f}   "
              f"{'OK' if n < 1000 or t <= 1e-3 else 'ABOVE 1 ms TARGET'}")
    rtf, sim, wall = real_time_factor()
    print(f"loop, 50 synthetic tasks at 10 Hz: {sim:.0f} s simulated in {wall:.2f} s wall = "
          f"{rtf:,.0f}x real time (target >= 1,000x) {'OK' if rtf >= 1000 else 'BELOW TARGET'}")
    big = tick_cost(10_000, repeats=20)
    scan = tick_cost(10_000, repeats=20, incremental=False)
    print(f"  10000 waiting agents: {big * 1e3:8.3f} ms   x{big / base:6.1f} vs 10 agents   "
          f"growth/linear = {(big / base) / 1000:4.2f}   scan {scan * 1e3:7.3f} ms = x{scan / big:6.1f}   "
          f"{'OK' if big <= 1e-3 else 'ABOVE 1 ms TARGET'}")
    worst = tick_cost(10_000, repeats=20, all_reported=True)
    print(f"  10000 waiting agents, all re-reported since the last tick: {worst * 1e3:8.3f} ms   "
          f"scan {scan * 1e3:7.3f} ms = x{scan / worst:4.2f}   (printed only: reports as frequent as decisions)")
    for every, held in ((60.0, True), (10.0, False)):
        print(f"loop, a task every {every:.0f} s (~45 s of work each; rates 1 Hz)"
              + ("" if held else ": overload, printed only"))
        per_task0 = None
        sizes = (100, 300, 1000) if held else (100, 300)
        for n in sizes:
            rtf, sim, wall = queue_factor(n, every)
            per_task = wall / n
            per_task0 = per_task0 or per_task
            growth = per_task / per_task0
            verdict = ("" if not held else
                       f"({'linear' if growth <= 1.5 else 'SUPERLINEAR'})"
                       + ("" if n < 1000 else (" OK" if rtf >= 1000 else " BELOW 1,000x TARGET")))
            print(f"  {n:5d} tasks: {sim:9.0f} s simulated in {wall:6.2f} s = {rtf:8,.0f}x real time   "
                  f"wall/task x{growth:4.2f} vs 100 tasks {verdict}")


if __name__ == "__main__":
    main()
