"""Where the seconds of a cold scenario run go.

    python benchmarks/profile_cold.py [SCENARIO] [--first]     # default: paper, disk cache primed

Runs the scenario once in a fresh process (its on-disk cache, :mod:`tasker.support.diskcache`, a
fresh folder: ``--first`` leaves it empty, as on a first run — no task folder's checks, no
robot dimensions, MuJoCo source or roadmap remembered; otherwise a first run primes it) and
prints the wall seconds of ``run_scenario`` split by what ran: loading the scenario (of
which the task folders; the robot's dimensions are read there too, the roadmap is grown or
loaded in the rest), Fast Downward (translator in-process, ``downward`` binary), the robot's motion estimates, the
simulation's physics, and the rest (the TaskER loop, problem rendering, metrics).
Phases are timed by wrapping the functions named below, so nested time is counted once,
in the outermost phase that lists it.  Not a ``bench_*`` script: it prints no ratio, only
where to look.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

_CHILD = r"""
import functools, importlib, json, sys, time
sys.path.insert(0, {root!r})
t0 = time.perf_counter()
from experiments.run.runner import run_scenario
imported = time.perf_counter() - t0
PHASES = [  # (label, module, attribute path); outermost first
    ("scenario load", "experiments.inputs.scenario", "load"),
    ("  task folders", "planners.bundled", "_bundled"),
    ("Fast Downward translate", "planners.fd", "_translate"),
    ("Fast Downward search", "planners.fd", "_search"),
    ("motion estimates", "robot.estimator", "MotionEstimator.estimate"),
    ("motion estimates", "robot.estimator", "MotionEstimator.estimate_ignoring_doors"),
    ("motion estimates", "robot.estimator", "MotionEstimator.estimate_ignoring_people"),
    ("motion estimates", "robot.estimator", "MotionEstimator.approach"),
    ("motion estimates", "robot.estimator", "MotionEstimator.table"),
    ("physics and skills", "robot.sim", "Simulation.advance"),
    ("physics and skills", "robot.sim", "Simulation.poll"),
]
spent, calls, active = {{}}, {{}}, []

def wrap(label, owner, name):
    f = getattr(owner, name)
    @functools.wraps(f)
    def timed(*a, **k):
        if active and not label.startswith("  "):
            return f(*a, **k)
        active.append(label)
        t = time.perf_counter()
        try:
            return f(*a, **k)
        finally:
            active.pop()
            spent[label] = spent.get(label, 0.0) + time.perf_counter() - t
            calls[label] = calls.get(label, 0) + 1
    setattr(owner, name, timed)

for label, mod, path in PHASES:
    owner = importlib.import_module(mod)
    *outer, name = path.split(".")
    for part in outer:
        owner = getattr(owner, part)
    wrap(label, owner, name)
t = time.perf_counter()
r = run_scenario({scenario!r}, pictures=False)
wall = time.perf_counter() - t
order = list(dict.fromkeys(label for label, _, _ in PHASES if label in spent))
print(json.dumps({{"order": order, "imports": imported, "wall": wall, "sim": r.trace.events[-1]["t"],
                  "spent": spent, "calls": calls}}))
"""


def run(scenario: str, cache: Path) -> dict[str, object]:
    env = {**os.environ, "TASKER_CACHE": str(cache)}
    out = subprocess.run([sys.executable, "-c", _CHILD.format(root=str(ROOT), scenario=scenario)],
                         capture_output=True, text=True, check=True, env=env)
    result: dict[str, object] = json.loads(out.stdout.strip().splitlines()[-1])
    return result


def main(argv: list[str]) -> int:
    first = "--first" in argv
    names = [a for a in argv if not a.startswith("--")]
    scenario = names[0] if names else "paper"
    with tempfile.TemporaryDirectory() as tmp:
        cache = Path(tmp)
        if not first:
            run(scenario, cache)  # a first run records the checks
        r = run(scenario, cache)
    spent: dict[str, float] = r["spent"]  # type: ignore[assignment]
    calls: dict[str, int] = r["calls"]  # type: ignore[assignment]
    wall, sim = float(r["wall"]), float(r["sim"])  # type: ignore[arg-type]
    state = "first run (empty disk cache)" if first else "disk cache primed"
    print(f"{scenario}, cold, {state}: {sim:.1f} s simulated in {wall:.2f} s = {sim / wall:.0f}x "
          f"(imports before run_scenario: {float(r['imports']):.2f} s, not counted)")
    top = 0.0
    for label in r["order"]:  # type: ignore[attr-defined]
        if not label.startswith("  "):
            top += spent[label]
        print(f"  {label:26s} {spent[label]:6.2f} s  {spent[label] / wall:5.1%}  ({calls[label]} calls)")
    print(f"  {'the rest':26s} {wall - top:6.2f} s  {(wall - top) / wall:5.1%}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
