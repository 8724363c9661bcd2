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
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DAY = ROOT / "benchmarks" / "day_hour.toml"
BASELINE = "4b70084"

_WORKER = """
import json, sys, time, warnings
warnings.simplefilter("ignore")
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


# where the time goes: a function's own CPU time is booked to the first group whose file
# (and, for robot/sim.py, name) it matches; a library or built-in function's time is booked
# to the groups of its callers, in proportion to the time it spent for each
_SNAPSHOT = {"snapshot", "_facts_now", "_bound_facts", "facts_key", "person_place", "nearest_place",
             "_memo_place", "place_of", "room_of", "objects"}
GROUPS = (
    ("MuJoCo physics (mj_step)", lambda f, n: n.startswith("<built-in method mujoco._functions.mj_step")),
    ("snapshots and facts (Simulation.snapshot, tasker.meaning)",
     lambda f, n: (f.endswith("robot/sim.py") and n in _SNAPSHOT) or f.endswith("tasker/meaning.py")),
    ("simulation ticks (people, skills, control, sync, recording)",
     lambda f, n: any(f.endswith(f"robot/{m}.py") for m in ("sim", "people", "skills", "control", "mjworld",
                                                              "recording", "drive"))),
    ("motion estimates and paths (robot.estimator, motion, scene, visibility, roadmap)",
     lambda f, n: any(f.endswith(f"robot/{m}.py") for m in ("estimator", "motion", "scene", "visibility",
                                                              "roadmap", "spec", "tiago"))),
    ("task planning (planners/, Fast Downward's translator)",
     lambda f, n: "/planners/" in f or "/fast_downward/" in f or "/domains/" in f),
    ("harmoniser, agents, trace (tasker/)", lambda f, n: "/tasker/" in f and "/site-packages/" not in f),
    ("scenario, metrics, output files (experiments/)", lambda f, n: "/experiments/" in f),
)


def _group(func: tuple[str, int, str], stats: dict, memo: dict, depth: int = 0) -> dict[str, float]:
    """Shares of ``func``'s own time per group (see :data:`GROUPS`)."""
    if func in memo:
        return memo[func]
    f, _, n = func
    for label, match in GROUPS:
        if match(f, n):
            memo[func] = {label: 1.0}
            return memo[func]
    callers = stats[func][4]
    total = sum(c[2] + 1e-12 for c in callers.values())
    out: dict[str, float] = {}
    if depth < 30 and callers:
        memo[func] = {"other": 1.0}  # a cycle back here counts as other
        for caller, c in callers.items():
            for label, share in _group(caller, stats, memo, depth + 1).items():
                out[label] = out.get(label, 0.0) + share * (c[2] + 1e-12) / total
    memo[func] = out or {"other": 1.0}
    return memo[func]


def profile() -> int:
    """Print a Markdown table of where the time of the hour's day goes (cProfile, in this
    process, as ``tasker run`` runs it).  cProfile's own clock is kept: timing it with
    ``time.process_time`` costs a system call per Python call and swamps what it measures;
    the shares are those of a profiled run (the profiler slows Python calls, not C)."""
    import cProfile
    import pstats
    import time
    import warnings

    warnings.simplefilter("ignore")
    sys.path.insert(0, str(ROOT))
    from experiments.runner import run_scenario

    with tempfile.TemporaryDirectory() as tmp:
        run_scenario("household", seed=1, randomize=True, pictures=False)  # imports, disk cache
        prof = cProfile.Profile()
        cpu = time.process_time()
        child = _children_cpu()
        prof.enable()
        run_scenario(DAY, out=Path(tmp) / "day", pictures=False)
        prof.disable()
        child, cpu = _children_cpu() - child, time.process_time() - cpu
    stats = pstats.Stats(prof).stats  # type: ignore[attr-defined]
    memo: dict = {}
    totals: dict[str, float] = {}
    for func, (_, _, tt, _, _) in stats.items():
        for label, share in _group(func, stats, memo).items():
            totals[label] = totals.get(label, 0.0) + tt * share
    whole = sum(totals.values())
    steps = next((v[1] for k, v in stats.items() if k[2].startswith("<built-in method mujoco._functions.mj_step")), 0)
    print(f"| where the time goes ({DAY.name}, 1 hour) | s | share |\n|---|---:|---:|")
    for label, t in sorted(totals.items(), key=lambda kv: -kv[1]):
        print(f"| {label} | {t:.2f} | {t / whole:.0%} |")
    print(f"| **all** (profiled) | {whole:.2f} | 100% |")
    print(f"\nprofiled run: {cpu:.1f} CPU-s in this process, {child:.2f} CPU-s in child processes (Fast Downward's "
          f"search); mj_step calls: {steps}")
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
