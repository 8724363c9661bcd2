"""Benchmark: simulation throughput in CPU seconds, against a pinned baseline commit.

    python benchmarks/bench_throughput.py [--baseline COMMIT] [--seeds N] [--no-baseline]

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


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--baseline", default=BASELINE, help=f"commit to compare with (default {BASELINE})")
    ap.add_argument("--seeds", type=int, default=3, help="household seeds 1..N (default 3)")
    ap.add_argument("--no-baseline", action="store_true", help="measure this code only")
    args = ap.parse_args(argv)
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
