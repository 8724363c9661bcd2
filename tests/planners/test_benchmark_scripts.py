"""The planners' benchmarks run to the end (their figures are pasted in docs/planners.md).

Not a timing test: it checks that the scripts work and that what they compare agrees
(equal plan costs), never how fast anything is.  ``bench_planner.py`` once failed
unnoticed, after the package stopped registering ``tasker-fd`` on import."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"


def _run(script: str, *args: str) -> str:
    done = subprocess.run([sys.executable, str(BENCHMARKS / script), *args], capture_output=True, text=True,
                          timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout


def test_bench_planner_compares_every_problem_with_fast_downward_opt() -> None:
    out = _run("bench_planner.py", "--repeat", "1")
    assert "plan costs equal on every problem: yes" in out and "overall median speed-up" in out
    assert "SAS identical on every problem: yes" in out


def test_bench_estimates_measures_every_case() -> None:
    out = _run("bench_estimates.py", "--repeat", "1")
    assert "paper world, OMPL" in out and "worst cached estimate with people moving" in out
