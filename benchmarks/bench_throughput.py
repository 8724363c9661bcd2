"""Benchmark: simulation throughput in CPU seconds, against a pinned baseline commit.

    python benchmarks/bench_throughput.py [--baseline COMMIT] [--seeds N] [--no-baseline]
    python benchmarks/bench_throughput.py --profile      # where the day's CPU time goes (docs/robot.md)

Two measurements, each taken on this code and on ``--baseline`` (default ``4b70084``,
the commit before the throughput work) in the same run: the baseline is checked out with
``git worktree add --detach`` into a temporary folder and run in subprocesses whose
``PYTHONPATH`` is that folder.  Every figure is CPU seconds of the process that ran it
(``resource.getrusage(RUSAGE_CHILDREN)`` around the subprocess, or ``time.process_time``
inside it), never wall time: the machine is shared.

* **A 1-hour robot day, end to end** (``benchmarks/day_hour.toml``: the paper apartment,
  Peter and Sara falling in turn 36 times, the robot guiding John across the flat every
  50 s, so it drives about half the day with people in the scene), run as a user runs it
  (``python -m experiments.cli run benchmarks/day_hour.toml --no-pictures``, every file
  written): simulated seconds per CPU second of the whole process, imports included;
  target >= 500x.
* **The household scenario as a sweep worker runs it**
  (``run_scenario("household", seed=s, randomize=True)``, seeds 1..N, imports done
  before the clock starts): CPU seconds of the runs; target: the baseline takes >= 3x
  as many.

Both get an on-disk cache (``$TASKER_CACHE``) of their own, primed by one household run
before anything is measured, so neither pays for growing the roadmap or checking the
task folders.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
DAY = ROOT / "benchmarks" / "day_hour.toml"
BASELINE = "4b70084"

_WORKER = """
import json, sys, time, warnings
warnings.simplefilter("ignore")
try:
    from experiments.run.runner import run_scenario
except ImportError:  # the baseline, before experiments/ was layered
    from experiments.runner import run_scenario
cpu = []
for seed in range(1, {seeds} + 1):
    t = time.process_time()
    r = run_scenario("household", seed=seed, randomize=True, pictures=False)
    cpu.append(time.process_time() - t)
print(json.dumps([cpu, r.trace.events[-1]["t"]]))
"""


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _run(code_root: Path, cache: Path, argv: list[str]) -> tuple[float, str]:
    """(CPU seconds, stdout) of ``python argv`` with ``code_root`` first on the path."""
    env = {**os.environ, "TASKER_CACHE": str(cache), "PYTHONPATH": str(code_root), "PYTHONWARNINGS": "ignore"}
    before = _children_cpu()
    out = subprocess.run([sys.executable, *argv], cwd=code_root, env=env, capture_output=True, text=True)
    cpu = _children_cpu() - before
    if out.returncode != 0:
        raise SystemExit(f"{' '.join(argv)} in {code_root} failed:\n{out.stderr[-2000:]}")
    return cpu, out.stdout


def household(code_root: Path, cache: Path, seeds: int) -> tuple[list[float], float]:
    """CPU seconds of each household run (seeds 1..``seeds``) in one worker process."""
    _, out = _run(code_root, cache, ["-c", _WORKER.format(seeds=seeds)])
    cpu, _ = json.loads(out.strip().splitlines()[-1])
    return [float(c) for c in cpu], float(sum(cpu))


def day(code_root: Path, cache: Path, out: Path) -> tuple[float, float]:
    """(simulated s, CPU s) of the hour's day run with ``tasker run``."""
    cpu, _ = _run(code_root, cache, ["-m", "experiments.cli", "run", str(DAY), "--out", str(out),
                                     "--no-pictures", "-q"])
    last = (out / "trace.jsonl").read_text().splitlines()[-1]
    return float(json.loads(last)["t"]), cpu


# where the time goes: CPU seconds of calls to these entry points, each call's own time
# less that of the entry points it calls (so the rows add up); the rest is the loop,
# the harmoniser and the agents.  Looked up by name: one that is missing is skipped.
ENTRY_POINTS = (
    ("MuJoCo physics (mj_step)", "robot.mjworld", "MjApartment.step"),
    ("simulation ticks: people, skills, control, sync, recording", "robot.sim", "Simulation.advance"),
    ("simulation ticks: people, skills, control, sync, recording", "robot.sim", "Simulation.begin"),
    ("snapshots of the world (Simulation.snapshot)", "robot.sim", "Simulation.snapshot"),
    ("facts and roles observed (tasker.meaning.Monitor.observe)", "tasker.meaning", "Monitor.observe"),
    ("motion estimates and paths (robot.estimator, robot.motion)", "robot.estimator", "MotionEstimator.estimate"),
    ("motion estimates and paths (robot.estimator, robot.motion)", "robot.estimator", "MotionEstimator.approach"),
    ("motion estimates and paths (robot.estimator, robot.motion)", "robot.estimator",
     "MotionEstimator.estimate_ignoring_doors"),
    ("motion estimates and paths (robot.estimator, robot.motion)", "robot.estimator",
     "MotionEstimator.estimate_ignoring_people"),
    ("motion estimates and paths (robot.estimator, robot.motion)", "robot.motion", "BasePlanner.plan"),
    ("motion estimates and paths (robot.estimator, robot.motion)", "robot.motion", "BasePlanner.plan_ignoring_people"),
    ("task plans (planners.planner.Planner.solve: Fast Downward's translator in-process)", "planners.planner",
     "Planner.solve"),
    ("schedule-parameter estimates, less plans and motion (planners.estimates)", "planners.estimates",
     "Estimator.estimate"),
    ("writing the run's files (trajectory, trace, problems)", "experiments.run.runner", "_save"),
)


def _instrument(totals: dict[str, float], calls: dict[str, int]) -> None:
    import functools
    import importlib
    import time

    stack: list[float] = []  # CPU seconds of entry points called inside the current one

    def wrap(label: str, fn: Callable[..., Any]) -> Callable[..., Any]:
        @functools.wraps(fn)
        def timed(*args: Any, **kwargs: Any) -> Any:
            t = time.process_time()
            stack.append(0.0)
            try:
                return fn(*args, **kwargs)
            finally:
                spent = time.process_time() - t
                inner = stack.pop()
                totals[label] = totals.get(label, 0.0) + spent - inner
                calls[label] = calls.get(label, 0) + 1
                if stack:
                    stack[-1] += spent
        return timed

    for label, module, name in ENTRY_POINTS:
        try:
            owner: Any = importlib.import_module(module)
        except ImportError:
            continue
        *path, attr = name.split(".")
        for part in path:
            owner = getattr(owner, part, None)
        if owner is not None and callable(getattr(owner, attr, None)):
            setattr(owner, attr, wrap(label, getattr(owner, attr)))


def profile() -> int:
    """Print a Markdown table of where the CPU time of the hour's day goes, run in this
    process as ``tasker run`` runs it (see :data:`ENTRY_POINTS`)."""
    import time
    import warnings

    warnings.simplefilter("ignore")
    sys.path.insert(0, str(ROOT))
    from experiments.run.runner import run_scenario

    totals: dict[str, float] = {}
    calls: dict[str, int] = {}
    with tempfile.TemporaryDirectory() as tmp:
        run_scenario("household", seed=1, randomize=True, pictures=False)  # imports, disk cache
        _instrument(totals, calls)
        child, cpu = _children_cpu(), time.process_time()
        run_scenario(DAY, out=Path(tmp) / "day", pictures=False)
        child, cpu = _children_cpu() - child, time.process_time() - cpu
        last = (Path(tmp) / "day" / "trace.jsonl").read_text().splitlines()[-1]
    totals["the loop, harmoniser, agents and the rest"] = cpu - sum(totals.values())
    totals["Fast Downward's search (child processes)"] = child
    whole = cpu + child
    print(f"| where the CPU time goes ({DAY.name}, 1 hour) | CPU s | share |\n|---|---:|---:|")
    for label, t in sorted(totals.items(), key=lambda kv: -kv[1]):
        print(f"| {label} | {t:.2f} | {t / whole:.0%} |")
    print(f"| **all** | {whole:.2f} | 100% |")
    from robot.mjworld import TIMESTEP
    from robot.sim import CONTROL_DT

    print(f"\nphysics ticks: {calls.get(ENTRY_POINTS[0][0], 0)}, each {round(CONTROL_DT / TIMESTEP)} MuJoCo steps "
          f"of {TIMESTEP * 1000:g} ms; CPU s of this process {cpu:.2f}, of child processes {child:.2f}")
    # what the target leaves: at 500x the hour may cost sim / 500 CPU-s in all, imports included
    sim = float(json.loads(last)["t"])
    physics = totals.get(ENTRY_POINTS[0][0], 0.0)
    if sim:
        print(f"500x leaves {sim / 500:.2f} CPU-s for the {sim:.0f} s simulated; MuJoCo's steps alone took "
              f"{physics:.2f} ({physics / (sim / 500):.0%} of it), everything else {whole - physics:.2f}")
    return 0


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--baseline", default=BASELINE, help=f"commit to compare with (default {BASELINE})")
    ap.add_argument("--seeds", type=int, default=3, help="household seeds 1..N (default 3)")
    ap.add_argument("--no-baseline", action="store_true", help="measure this code only")
    ap.add_argument("--profile", action="store_true", help="print where the day's CPU time goes (a table), only")
    args = ap.parse_args(argv)
    if args.profile:
        return profile()
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout
    with tempfile.TemporaryDirectory() as tmp:
        roots = {"this": ROOT}
        if not args.no_baseline:
            base = Path(tmp) / "baseline"
            subprocess.run(["git", "worktree", "add", "--detach", "-q", str(base), args.baseline], cwd=ROOT, check=True)
            roots["baseline"] = base
        try:
            rows = {}
            for label, code in roots.items():
                cache = Path(tmp) / f"cache-{label}"
                household(code, cache, 1)  # primes the disk cache: roadmap, robot, folder checks
                rows[label] = (household(code, cache, args.seeds), day(code, cache, Path(tmp) / f"day-{label}"))
        finally:
            if not args.no_baseline:
                subprocess.run(["git", "worktree", "remove", "--force", str(base)], cwd=ROOT, check=False)
    print(f"this code: {head.strip() or '?'} (uncommitted changes count); baseline: {args.baseline}")
    for label, ((runs, total), (sim, cpu)) in rows.items():
        print(f"{label:9s} household x{args.seeds} (sweep worker, randomised seeds 1..{args.seeds}): "
              f"{total:6.2f} CPU-s  ({', '.join(f'{c:.2f}' for c in runs)})")
        print(f"{label:9s} 1-hour day (tasker run {DAY.name}): {sim:.0f} s simulated in {cpu:.2f} CPU-s "
              f"= {sim / cpu:.0f}x")
    (_, total), (sim, cpu) = rows["this"]
    ok = 'OK' if sim / cpu >= 500 else 'MISS'
    print(f"1-hour day: {sim / cpu:.0f}x simulated s per CPU s   target >= 500x: {ok}")
    if "baseline" in rows:
        (_, btotal), (bsim, bcpu) = rows["baseline"]
        ratio = btotal / total
        print(f"household: baseline / this = {ratio:.2f}x CPU-s   target >= 3x: {'OK' if ratio >= 3 else 'MISS'}")
        print(f"1-hour day: baseline {bsim / bcpu:.0f}x -> this {sim / cpu:.0f}x ({(sim / cpu) / (bsim / bcpu):.2f}x)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
