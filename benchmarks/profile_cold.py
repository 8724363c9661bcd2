"""Where the seconds of a cold scenario run go.

    python benchmarks/profile_cold.py [SCENARIO] [--first] [--baseline COMMIT] [--repeat N]

Runs the scenario once in a fresh process (its on-disk cache, :mod:`tasker.support.diskcache`, a
fresh folder: ``--first`` leaves it empty, as on a first run — no task folder's checks, no
robot dimensions, MuJoCo source or roadmap remembered; otherwise a first run primes it) and
prints the wall and CPU seconds of ``run_scenario`` split by what ran: loading the scenario (of
which the task folders; the robot's dimensions are read there too, the roadmap is grown or
loaded in the rest), Fast Downward (translator in-process, ``downward`` binary), the robot's
motion estimates, the simulation's physics, and the rest (the TaskER loop, problem rendering,
metrics).  CPU seconds count this process and the children it waited for (the ``downward``
binary).  Phases are timed by wrapping the functions named below, so nested time is counted
once, in the outermost phase that lists it.

``--baseline COMMIT`` runs the same profile on that commit too (checked out into a temporary
git worktree, run in its own fresh processes, alternating with this tree's runs; ``--repeat``
of each, the median kept) and prints the two side by side.  Not a ``bench_*`` script: it prints
no target, only where to look.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]

_CHILD = r"""
import functools, importlib, json, os, sys, time
sys.path.insert(0, {root!r})
t0 = time.perf_counter()
from experiments.run.runner import run_scenario
imported = time.perf_counter() - t0

def cpu():
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system

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
spent, used, calls, active = {{}}, {{}}, {{}}, []

def wrap(label, owner, name):
    f = getattr(owner, name)
    @functools.wraps(f)
    def timed(*a, **k):
        if active and not label.startswith("  "):
            return f(*a, **k)
        active.append(label)
        t, c = time.perf_counter(), cpu()
        try:
            return f(*a, **k)
        finally:
            active.pop()
            spent[label] = spent.get(label, 0.0) + time.perf_counter() - t
            used[label] = used.get(label, 0.0) + cpu() - c
            calls[label] = calls.get(label, 0) + 1
    setattr(owner, name, timed)

for label, mod, path in PHASES:
    owner = importlib.import_module(mod)
    *outer, name = path.split(".")
    for part in outer:
        owner = getattr(owner, part)
    wrap(label, owner, name)
t, c = time.perf_counter(), cpu()
r = run_scenario({scenario!r}, pictures=False)
wall, used_all = time.perf_counter() - t, cpu() - c
order = list(dict.fromkeys(label for label, _, _ in PHASES if label in spent))
print(json.dumps({{"order": order, "imports": imported, "wall": wall, "cpu": used_all, "sim": r.trace.events[-1]["t"],
                  "spent": spent, "used": used, "calls": calls}}))
"""

Profile = dict[str, Any]

_LAYOUTS = r"""
import importlib, importlib.util, sys, types
sys.path.insert(0, {root!r})
# experiments/ moved into layers (experiments.run.runner, experiments.inputs.scenario): with
# --baseline, one side may name a module by the other layout; each name then finds it
def _has(name):
    try:
        return importlib.util.find_spec(name) is not None
    except ModuleNotFoundError:
        return False
for a, b in (("experiments.runner", "experiments.run.runner"), ("experiments.scenario", "experiments.inputs.scenario")):
    for want, have in ((a, b), (b, a)):
        if not _has(want) and _has(have):
            parent = want.rpartition(".")[0]
            if parent not in sys.modules and not _has(parent):
                sys.modules[parent] = types.ModuleType(parent)
            sys.modules[want] = importlib.import_module(have)
"""


def run(scenario: str, cache: Path, root: Path = ROOT) -> Profile:
    env = {**os.environ, "TASKER_CACHE": str(cache)}
    code = _LAYOUTS.format(root=str(root)) + _CHILD.format(root=str(root), scenario=scenario)
    out = subprocess.run([sys.executable, "-c", code],
                         capture_output=True, text=True, check=True, env=env, cwd=root)
    result: Profile = json.loads(out.stdout.strip().splitlines()[-1])
    return result


def median(runs: list[Profile]) -> Profile:
    """Per figure, the median over ``runs`` (a phase absent from a run counts 0)."""
    def med(key: str, label: str | None = None) -> float:
        return statistics.median(float(r[key] if label is None else r[key].get(label, 0.0)) for r in runs)

    labels = list(runs[0]["order"])
    return {"order": labels, "imports": med("imports"), "wall": med("wall"), "cpu": med("cpu"), "sim": runs[0]["sim"],
            "spent": {k: med("spent", k) for k in labels}, "used": {k: med("used", k) for k in labels},
            "calls": {k: med("calls", k) for k in labels}}


def report(r: Profile, title: str) -> None:
    spent, used, calls = r["spent"], r["used"], r["calls"]
    wall, cpu, sim = float(r["wall"]), float(r["cpu"]), float(r["sim"])
    print(f"{title}: {sim:.1f} s simulated in {wall:.2f} s = {sim / wall:.0f}x, CPU {cpu:.2f} s "
          f"(imports before run_scenario: {float(r['imports']):.2f} s, not counted)")
    print(f"  {'':26s} {'wall':>7s} {'':6s} {'CPU':>7s}")
    top_wall = top_cpu = 0.0
    for label in r["order"]:
        if not label.startswith("  "):
            top_wall += spent[label]
            top_cpu += used[label]
        print(f"  {label:26s} {spent[label]:6.2f} s {spent[label] / wall:6.1%} {used[label]:6.2f} s "
              f"{used[label] / cpu:6.1%}  ({calls[label]:.0f} calls)")
    print(f"  {'the rest':26s} {wall - top_wall:6.2f} s {(wall - top_wall) / wall:6.1%} {cpu - top_cpu:6.2f} s "
          f"{(cpu - top_cpu) / cpu:6.1%}")


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenario", nargs="?", default="paper")
    ap.add_argument("--first", action="store_true", help="leave the on-disk cache empty (a first run)")
    ap.add_argument("--baseline", metavar="COMMIT", help="profile this commit too, side by side")
    ap.add_argument("--repeat", type=int, default=1, help="runs of each tree; the median is printed")
    args = ap.parse_args(argv)
    state = "first run (empty disk cache)" if args.first else "disk cache primed"
    with tempfile.TemporaryDirectory() as tmp:
        trees = {"this tree": ROOT}
        base = Path(tmp) / "baseline"
        if args.baseline:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", "-q", str(base), args.baseline],
                           check=True)
            trees[f"baseline {args.baseline}"] = base
        try:
            runs: dict[str, list[Profile]] = {name: [] for name in trees}
            for k in range(args.repeat):
                for name, root in trees.items():  # alternating, so a busy spell hits both alike
                    cache = Path(tmp) / f"cache-{root.name}-{k}"
                    if not args.first:
                        run(args.scenario, cache, root)  # a first run records the checks
                    runs[name].append(run(args.scenario, cache, root))
        finally:
            if args.baseline:
                subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(base)], check=False)
    profiles = {name: median(rs) for name, rs in runs.items()}
    suffix = f", median of {args.repeat}" if args.repeat > 1 else ""
    for name, profile in profiles.items():
        report(profile, f"{args.scenario}, cold, {state}{suffix}" + (f" [{name}]" if args.baseline else ""))
    if args.baseline:
        now, before = (profiles[n] for n in runs)
        print(f"CPU, this tree / baseline: run_scenario {now['cpu'] / before['cpu']:.2f}"
              + "".join(f", {label.strip()} {now['used'][label] / before['used'][label]:.2f}"
                        for label in now["order"] if before["used"].get(label)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
