"""Benchmark: how fast the ``tasker`` command starts, as ratios to a bare ``python -c pass``.

Each command runs in a fresh process, ``--repeat`` times (median); the baseline is
measured in the same run, interleaved with the commands, so a busy machine moves both.

* ``tasker --help`` — the parser of every subcommand (target <= 15x);
* ``tasker plan`` on a small problem (the delivery problem of the planner tests), with a
  cold check cache (a new, empty ``TASKER_CACHE`` each time: UP's reader checks the
  PDDL) and a warm one (straight to Fast Downward) (target <= 30x warm);
* ``tasker plan`` on the cook task's example problem (its stages come from the bundled
  task folder, so that folder is loaded);
* ``tasker domains`` — every bundled task folder loaded, cold (each example solved)
  and warm (the check cache says they passed).

Run: ``python benchmarks/bench_startup.py [--repeat N]``.  Exit 1 if a target is missed.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

TARGET_HELP = 15.0
TARGET_PLAN_WARM = 30.0


def _tasker(*args: str) -> list[str]:
    return [sys.executable, "-c", "import sys; from experiments.cli import main; sys.exit(main())", *args]


def _time(cmd: list[str], env: dict[str, str], cwd: str) -> float:
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, env=env, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, check=False)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(cmd[3:])} failed ({proc.returncode}): {proc.stderr.decode()[-500:]}")
    return wall


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=7, help="runs per command (median; default 7)")
    args = parser.parse_args(argv)

    from planners.bundled import task_types
    from planners.examples import example_context
    with tempfile.TemporaryDirectory(prefix="tasker-bench-startup-") as tmp:
        # a small delivery problem (the cheap route a-b-c beats the direct a-c)
        data = ROOT / "benchmarks" / "data"
        d, p = data / "delivery_domain.pddl", data / "delivery_problem.pddl"
        cook = next(t for t in task_types() if t.name == "cook")
        ctx = example_context(cook)  # type: ignore[arg-type]
        assert ctx is not None
        # upTsk's own inputs: the request's facts and task.py's extra_facts (without them it has no plan)
        world, goal, extra = cook.update_inputs(ctx)  # type: ignore[attr-defined]
        text, _, _ = cook.problem_text(ctx, world, goal, extra)  # type: ignore[attr-defined]
        cook_problem = Path(tmp) / "cook_problem.pddl"
        cook_problem.write_text(text.problem)
        cook_domain = str(ROOT / "domains" / "cook" / "domain.pddl")

        base_env = {k: v for k, v in os.environ.items() if k != "TASKER_TASKS"}
        base_env["PYTHONPATH"] = str(ROOT)
        warm_env = {**base_env, "TASKER_CACHE": str(Path(tmp) / "warm-cache")}
        commands: list[tuple[str, list[str], str, float | None]] = [
            ("tasker --help", _tasker("--help"), "warm", TARGET_HELP),
            ("tasker plan (small, cold cache)", _tasker("plan", str(d), str(p)), "cold", None),
            ("tasker plan (small, warm cache)", _tasker("plan", str(d), str(p)), "warm", TARGET_PLAN_WARM),
            ("tasker plan (cook, cold cache)", _tasker("plan", cook_domain, str(cook_problem)), "cold", None),
            ("tasker plan (cook, warm cache)", _tasker("plan", cook_domain, str(cook_problem)), "warm", None),
            ("tasker domains (cold cache)", _tasker("domains"), "cold", None),
            ("tasker domains (warm cache)", _tasker("domains"), "warm", None),
        ]
        for _, cmd, _, _ in commands:  # fill the warm cache (and the OS file cache)
            _time(cmd, warm_env, tmp)
        base: list[float] = []
        times: dict[str, list[float]] = {name: [] for name, *_ in commands}
        for r in range(args.repeat):
            base.append(_time([sys.executable, "-c", "pass"], base_env, tmp))
            for name, cmd, cache, _ in commands:
                env = warm_env if cache == "warm" else {**base_env, "TASKER_CACHE": str(Path(tmp) / f"cold-{r}-{name}")}
                times[name].append(_time(cmd, env, tmp))
        b0 = statistics.median(base)
        print(f"baseline python -c pass: {b0 * 1000:.0f} ms (median of {args.repeat})")
        print(f"{'command':34s} {'median ms':>9s} {'x python':>9s} {'target':>7s}")
        missed = []
        for name, _, _, target in commands:
            m = statistics.median(times[name])
            ratio = m / b0
            mark = "" if target is None else (f"<= {target:g}" + ("" if ratio <= target else " MISSED"))
            if target is not None and ratio > target:
                missed.append(name)
            print(f"{name:34s} {m * 1000:9.0f} {ratio:9.1f} {mark:>7s}")
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
