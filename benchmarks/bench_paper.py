"""Benchmark: the paper scenario end to end (planning, OMPL, MuJoCo included).

    python benchmarks/bench_paper.py

Prints the real-time factor (simulated seconds / wall seconds; target >= 20x) with
planned and with static strategies, measured in the same run, and their ratio.  The
first run pays one-off costs (roadmap growth, model conversion); it is reported apart.
"""

from __future__ import annotations

import statistics
import time

from experiments.runner import run_scenario


def once(**kw: str) -> tuple[float, float]:
    t0 = time.perf_counter()
    r = run_scenario("paper", pictures=False, **kw)
    wall = time.perf_counter() - t0
    return r.trace.events[-1]["t"], wall


def main() -> None:
    sim, wall = once()
    print(f"first run (warm-up: roadmap, TIAGo conversion): {sim:.0f} s simulated in {wall:.2f} s = {sim / wall:.0f}x")
    rows = {}
    for label, kw in (("planned", {}), ("static", {"update": "static", "suspension": "static"})):
        rtfs = []
        for _ in range(3):
            s, w = once(**kw)
            rtfs.append(s / w)
        rows[label] = statistics.median(rtfs)
        print(f"{label:8s} upTsk/genSusp: real-time factor {rows[label]:6.1f}x (median of 3)  "
              f"{'OK' if rows[label] >= 20 else 'BELOW 20x TARGET'}")
    print(f"planned / static real-time factor: {rows['planned'] / rows['static']:.2f}")


if __name__ == "__main__":
    main()
