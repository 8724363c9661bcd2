"""The planners' benchmarks run to the end (their figures are pasted in docs/planners.md).

Not a timing test: it checks that the scripts work and that what they compare agrees
(equal plan costs), never how fast anything is.  ``bench_planner.py`` once failed
unnoticed, after the package stopped registering ``tasker-fd`` on import."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

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


@pytest.mark.slow
def test_bench_planner_engines_table_lists_the_schedules_and_their_answers() -> None:
    out = _run("bench_planner.py", "--engines")
    rows = {line.split("|")[1].strip(): line for line in out.splitlines() if line.startswith("| `")}
    assert {"`tasker-fd`", "`tasker-anytime`", "`tasker-opt`", "`tasker-first`", "`fast-downward-opt`"} <= set(rows)
    assert "GPL-3.0-only" in rows["`tasker-fd`"] and "cost 6, optimal | cost 1, optimal" in rows["`tasker-fd`"]
    assert rows["`fast-downward-opt`"].count("refused (UP's reader)") == 5


@pytest.mark.slow
def test_bench_planner_ipc_runs_tasker_plan_on_a_folder_of_domains(tmp_path: Path) -> None:
    from tests.planners.pddl_cases import EITHER

    (tmp_path / "either").mkdir()
    (tmp_path / "either" / "domain.pddl").write_text(EITHER.domain)
    (tmp_path / "either" / "p01.pddl").write_text(EITHER.problem)
    out = _run("bench_planner.py", "--ipc", str(tmp_path), "--domains", "either", "--timeout", "20")
    assert ("tasker-anytime: 1/1 solved, 1 proven optimal, 0 validated by UP, 1 read by FD's translator; "
            "exit 3: 0") in out
    assert "tasker-opt: 1/1 solved" in out


def test_bench_estimates_measures_every_case() -> None:
    out = _run("bench_estimates.py", "--repeat", "1")
    assert "paper world, OMPL" in out and "worst cached estimate with people moving" in out
