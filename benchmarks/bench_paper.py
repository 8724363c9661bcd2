"""Benchmark: whole scenarios end to end (planning, OMPL, MuJoCo included).

    python benchmarks/bench_paper.py

Prints real-time factors (simulated seconds / wall seconds of ``run_scenario``), each
cold figure the median of three fresh processes:

* the paper scenario **cold**: a fresh process, so the task folders and every plan are
  paid (target >= 60x).  Its on-disk cache (:mod:`tasker.support.diskcache`, ``$TASKER_CACHE``)
  is a fresh folder of this run, never the user's: first **empty** (a first run:
  unified-planning checks every task folder and solves its example, Pinocchio builds TIAGo
  for its dimensions, the DAE meshes are converted for MuJoCo, OMPL grows the roadmap),
  then as that first run left it (every later run: the folders' checks, the robot's
  dimensions and MuJoCo source and the roadmap are remembered; plans are never cached on
  disk).  The **baseline**, measured in the same run with the same primed cache, is the
  previous path of the domains: unified-planning still imported to read every domain (now
  Fast Downward's own parser reads them, :mod:`planners.schema`);
* the paper scenario warm (same process) with planned and static strategies;
* a **1-hour day** in the paper apartment (36 falls, Peter and Sara in turn, each
  getting up 70 s later; 3,700 s horizon), cold in a fresh process with the primed disk
  cache (target >= 500x),
  against the same day with every control tick stepped (the still-tick skipping of
  :meth:`robot.sim.Simulation._fast_forward` switched off), measured in the same run.
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from experiments.run.runner import run_scenario  # noqa: E402


def day_scenario(path: Path, falls: int = 36) -> Path:
    """Write the 1-hour day's scenario file."""
    lines = ['kind = "robot"', 'name = "day"', 'world = "paper"', "seed = 1", "", "[settings]",
             'scheduler = "alg2"', 'mode = "IT"', 'update = "planned"', 'suspension = "planned"',
             "horizon = 3700.0", ""]
    for k in range(falls):
        t = 60.0 + 100.0 * k
        who = "peter" if k % 2 == 0 else "sara"
        lines += ["[[world_events]]", f"t = {t}", f'posture = ["{who}", "fallen"]', "",
                  "[[requests]]", f"t = {t}", 'task = "human_fell"', f'args = {{ person = "{who}" }}', "",
                  "[[world_events]]", f"t = {t + 70.0}", f'posture = ["{who}", "standing"]', ""]
    path.write_text("\n".join(lines))
    return path


_COLD = """
import json, sys, time
sys.path.insert(0, {root!r})
if {slow}:
    from robot.sim import Simulation
    Simulation._fast_forward = lambda self, now: False
if {legacy}:  # the previous path: remembered task folders still read by unified-planning
    import planners.checks, planners.loader
    planners.loader.remembered_domain = planners.checks.load_domain
from experiments.run.runner import run_scenario
t = time.perf_counter()
r = run_scenario({scenario!r}, pictures=False)
print(json.dumps([r.trace.events[-1]["t"], time.perf_counter() - t]))
"""


def cold(scenario: str, cache: str | Path, slow: bool = False, legacy: bool = False) -> tuple[float, float]:
    """(simulated s, wall s) of one run in a fresh process whose on-disk cache is ``cache``."""
    code = _COLD.format(root=str(ROOT), scenario=scenario, slow=slow, legacy=legacy)
    env = {**os.environ, "TASKER_CACHE": str(cache)}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, env=env)
    sim, wall = json.loads(out.stdout.strip().splitlines()[-1])
    return float(sim), float(wall)


def median_cold(runs: list[tuple[float, float]]) -> tuple[float, float]:
    """(simulated s, median wall s) of runs of one scenario (the simulated time never varies)."""
    sims = {round(s, 6) for s, _ in runs}
    if len(sims) != 1:
        raise SystemExit(f"runs of one scenario simulated different times {sorted(sims)}: not deterministic")
    return runs[0][0], statistics.median(w for _, w in runs)


def once(**kw: str) -> tuple[float, float]:
    t0 = time.perf_counter()
    r = run_scenario("paper", pictures=False, **kw)
    wall = time.perf_counter() - t0
    return r.trace.events[-1]["t"], wall


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        caches = [Path(tmp) / f"cache{k}" for k in range(3)]
        first = median_cold([cold("paper", c) for c in caches])  # each cache empty: a first run, which primes it
        remembered, legacy = [], []
        for c in caches:  # interleaved, so load on the machine hits both alike
            remembered.append(cold("paper", c))
            legacy.append(cold("paper", c, legacy=True))
        now, before = median_cold(remembered), median_cold(legacy)
        sim = now[0]
        for label, (_, wall) in (("first run (empty disk cache)", first),
                                 ("disk cache primed (every later run)", now)):
            rtf = sim / wall
            print(f"paper, cold, {label}: {sim:.1f} s simulated in {wall:.2f} s = {rtf:.0f}x   "
                  f"target >= 60x: {'OK' if rtf >= 60 else 'MISS'}")
        print(f"  baseline, disk cache primed but every domain read by unified-planning (the previous path): "
              f"{before[1]:.2f} s = {sim / before[1]:.0f}x; now {before[1] / now[1]:.2f}x faster, "
              f"{before[1] - now[1]:.2f} s less")
        rows = {}
        for label, kw in (("planned", {}), ("static", {"update": "static", "suspension": "static"})):
            rtfs = []
            for _ in range(3):
                s, w = once(**kw)
                rtfs.append(s / w)
            rows[label] = statistics.median(rtfs)
            print(f"paper, warm, {label:8s} upTsk/genSusp: real-time factor {rows[label]:6.1f}x (median of 3)")
        print(f"planned / static real-time factor: {rows['planned'] / rows['static']:.2f}")
        print(f"  cold (disk cache primed) costs {now[1] - sim / rows['planned']:.2f} s more than a warm run")
        day = str(day_scenario(Path(tmp) / "day.toml"))
        sim, wall = cold(day, caches[0])
        sim_s, wall_s = cold(day, caches[0], slow=True)
    fast, slow = sim / wall, sim_s / wall_s
    print(f"1-hour day (36 falls), cold: {sim:.0f} s simulated in {wall:.2f} s = {fast:.0f}x   "
          f"target >= 500x: {'OK' if fast >= 500 else 'MISS'}")
    print(f"  baseline, every control tick stepped: {sim_s:.0f} s in {wall_s:.2f} s = {slow:.0f}x; "
          f"skipping still ticks: {fast / slow:.1f}x faster")


if __name__ == "__main__":
    main()
