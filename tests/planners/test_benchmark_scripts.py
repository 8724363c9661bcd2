"""The planners' benchmarks still work: their functions, called on one small problem.

A benchmark is not a test, and no test runs one (``python benchmarks/run_all.py`` does; their
figures are pasted in docs/planners.md).  These tests import the scripts and call the pieces
they are built of on a tiny input, so a script that stopped importing or whose comparison
broke fails here — ``bench_planner.py`` once failed unnoticed, after the package stopped
registering ``tasker-fd`` on import.  They check what the scripts compare (equal plan costs,
identical SAS), never how fast anything is.
"""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path
from types import ModuleType

import pytest

from planners.bundled import task_types
from planners.examples import StraightLineMotion, example_context
from planners.pddl_task import PddlTaskType
from tasker.task import Strategy

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"


def _script(name: str) -> ModuleType:
    """A benchmark script imported as a module (its ``main`` is not called)."""
    module_name = f"_bench_{name}"
    if module_name in sys.modules:
        return sys.modules[module_name]
    spec = importlib.util.spec_from_file_location(module_name, BENCHMARKS / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[module_name] = module
    spec.loader.exec_module(module)
    return module


def _task(name: str) -> PddlTaskType:
    task = {t.name: t for t in task_types()}[name]
    assert isinstance(task, PddlTaskType)
    return task


@pytest.mark.slow
def test_bench_planner_engines_table_lists_the_schedules_and_their_answers(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert _script("bench_planner").engines() == 0
    out = capsys.readouterr().out
    rows = {line.split("|")[1].strip(): line for line in out.splitlines() if line.startswith("| `")}
    assert {"`tasker-fd`", "`tasker-anytime`", "`tasker-opt`", "`tasker-first`", "`fast-downward-opt`"} <= set(rows)
    assert "GPL-3.0-only" in rows["`tasker-fd`"] and "cost 6, optimal | cost 1, optimal" in rows["`tasker-fd`"]
    assert rows["`fast-downward-opt`"].count("refused (UP's reader)") == 5


@pytest.mark.slow
def test_bench_planner_ipc_runs_tasker_plan_on_a_folder_of_domains(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from tests.planners.pddl_cases import EITHER

    (tmp_path / "either").mkdir()
    (tmp_path / "either" / "domain.pddl").write_text(EITHER.domain)
    (tmp_path / "either" / "p01.pddl").write_text(EITHER.problem)
    assert _script("bench_planner").ipc(tmp_path, ["either"], 20.0, None) == 0
    out = capsys.readouterr().out
    assert ("tasker-anytime: 1/1 solved, 1 proven optimal, 0 validated by UP, 1 read by FD's translator; "
            "exit 3: 0") in out
    assert "tasker-opt: 1/1 solved" in out


def test_bench_planner_compares_a_problem_with_fast_downward_opt() -> None:
    from planners.checks import load_problem_text
    from planners.planner import Planner

    bench = _script("bench_planner")
    task = _task("human_fell")
    problems = bench.problems_of(task)
    assert problems, "the example world gives no problem to compare"
    label, text = problems[0]
    model = load_problem_text(task.domain.checked, text.problem)
    _, ours = bench.timed(lambda: Planner(cache_size=0).solve(text).cost, 1)
    _, engine = bench.timed(bench.up_solver("tasker-fd", model), 1)
    _, optimal = bench.timed(bench.up_solver("fast-downward-opt", model), 1)
    assert ours is not None and math.isfinite(ours) and ours == engine == optimal, (label, ours, engine, optimal)
    assert bench.translator([text], 1)  # the reuse path writes the SAS the library's main() writes


def test_bench_estimates_measures_a_stale_plan_against_a_fresh_one() -> None:
    bench = _script("bench_estimates")
    task = _task("human_fell")
    ctx = example_context(task, motion=StraightLineMotion(), strategy=Strategy())
    assert ctx is not None
    stale = bench.stale_context(task, ctx)
    assert stale.suspended and stale.stage_index >= 1
    row = bench.measure("human_fell (example world)", task, stale, 1)
    assert set(row) == {"stale walk", "stale walk, moved", "cold", "cached", "cached, moved"}
    assert all(v >= 0 for v in row.values())
