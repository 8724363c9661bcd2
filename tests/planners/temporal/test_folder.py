"""Task folders with a temporal domain: their schema, durations, one thing at a time, and a run."""

from __future__ import annotations

import shutil
from fractions import Fraction as F
from pathlib import Path

import pytest

from planners.checks import CheckedDomain, DefinitionError
from planners.loader import load_task
from planners.planner import PddlText
from planners.results import PlanStatus
from planners.scaffold import scaffold
from planners.temporal.folder import FolderPlanner, TemporalDomainModel, domain_model, overlap
from planners.temporal.results import TimedStep
from tests.planners.temporal.conftest import pair

PLANSYS2 = Path(__file__).resolve().parents[3] / "domains" / "plansys2" / "simple_example"


def test_the_schema_of_a_durative_domain() -> None:
    d, _ = pair("plansys2_simple")
    dm = domain_model(CheckedDomain(d, d.read_text()))
    assert isinstance(dm, TemporalDomainModel)
    assert dm.predicates["robot_at"] == ("robot", "room") and set(dm.types) == {"robot", "room"}
    move = dm.actions["move"]
    assert move.constant_cost == 5.0  # (= ?duration 5): the stage's duration by default
    # at start (not (robot_at ?r ?r1)), at end (robot_at ?r ?r2): the net effect of the whole action
    assert dm.ground("move", ["leia", "a", "b"]) == ([("robot_at", "leia", "b")], [("robot_at", "leia", "a")])
    # at-start and over-all conditions are what must hold as the stage starts
    assert dm.unmet("move", ["leia", "a", "b"], {("robot_at", "leia", "a"), ("connected", "a", "b")}) == [
        ("battery_full", "leia")]


def test_at_start_add_and_at_end_delete_is_a_delete(tmp_path: Path) -> None:
    d, _ = pair("tasker_concurrency")
    dm = domain_model(CheckedDomain(d, d.read_text()))
    add, delete = dm.ground("hold_lamp", ["r", "s"])
    assert ("lit", "s") not in add and ("lit", "s") in delete and ("free", "r") in add
    # over all (lit ?s) must hold as inspect starts: alone, in a world without light, it cannot run
    assert dm.unmet("inspect", ["r", "s"], set()) == [("lit", "s")]
    assert dm.unmet("inspect", ["r", "s"], {("lit", "s")}) == []


def test_overlap_names_the_file_the_actions_and_the_times() -> None:
    a = TimedStep(F(0), "hold_lamp", ("robot", "corner"), F(10))
    b = TimedStep(F(2), "inspect", ("robot", "corner"), F(3))
    why = overlap((a, b), "lamp/domain.pddl")
    assert why is not None and why.startswith("lamp/domain.pddl: the plan needs the one robot to do two things at once")
    assert "(hold_lamp robot corner) from 0 s to 10 s" in why and "(inspect robot corner) from 2 s to 5 s" in why
    after = TimedStep(F(10) + F(1, 10**4), "inspect", ("robot", "corner"), F(3))
    assert overlap((a, after), "d") is None
    assert overlap((a, TimedStep(F(3), "note", (), F(0))), "d") is None  # an instant takes no time


@pytest.mark.slow
def test_a_plan_that_needs_two_things_at_once_is_refused() -> None:
    d, p = pair("tasker_concurrency")
    result = FolderPlanner(d, timeout=30).solve(PddlText(d.read_text(), p.read_text()))
    assert result.status is PlanStatus.ERROR and result.plan is None
    assert "two things at once" in result.message and str(d) in result.message


@pytest.mark.slow
def test_folder_planner_gives_steps_in_start_order_and_caches() -> None:
    d, p = pair("plansys2_simple")
    planner = FolderPlanner(d, timeout=30)
    first = planner.solve(PddlText(d.read_text(), p.read_text()))
    assert first.solved and first.plan is not None and first.plan[-1] == ("move", "leia", "bedroom", "bathroom")
    assert first.cost is not None and 30 <= first.cost < 31  # the makespan
    again = planner.solve(PddlText(d.read_text(), p.read_text()))
    assert again.cached and again.plan == first.plan and planner.hits == 1


def test_an_expression_duration_needs_travel_or_duration(tmp_path: Path) -> None:
    folder = tmp_path / "f"
    shutil.copytree(PLANSYS2, folder)
    toml = folder / "task.toml"
    toml.write_text(toml.read_text().replace('to = "?r2"\ntravel = ["?r1", "?r2"]\n\n[actions.askcharge]',
                                             'to = "?r2"\n\n[actions.askcharge]'))
    with pytest.raises(DefinitionError, match=r"the :duration of move in domain.pddl is not a fixed number"):
        load_task(folder, use_cache=False)


@pytest.mark.slow
def test_the_bundled_plansys2_example_plans_its_stages() -> None:
    from planners.examples import StraightLineMotion, example_context

    task = load_task(PLANSYS2, use_cache=False)
    ctx = example_context(task, motion=StraightLineMotion())
    assert ctx is not None
    plan = task.update_task(ctx)
    assert [s.action for s in plan.stages] == ["askcharge", "charge", "move"]
    assert [s.skill for s in plan.stages] == ["navigate", "wait", "navigate"]
    assert plan.stages[1].duration == 5.0  # the domain's :duration, no skill measures it


@pytest.mark.slow
def test_tasker_new_temporal_loads_and_plans(tmp_path: Path) -> None:
    files = scaffold("fetch_t", tmp_path / "fetch_t", temporal=True)
    assert "(:durative-action navigate" in (tmp_path / "fetch_t" / "domain.pddl").read_text()
    assert {f.name for f in files} == {"domain.pddl", "task.toml", "scenario.toml", "problem.pddl"}
    task = load_task(tmp_path / "fetch_t")
    assert isinstance(task.domain, TemporalDomainModel) and task.planner.name == "kairos,lpg,aries"


@pytest.mark.slow
def test_the_plansys2_example_runs_on_the_robot_the_same_twice(tmp_path: Path) -> None:
    from experiments.cli import main

    out = []
    for k in range(2):
        argv = ["run", str(PLANSYS2 / "scenario.toml"), "--path", str(PLANSYS2), "--out", str(tmp_path / f"o{k}"),
                "--quiet"]
        assert main(argv) == 0
        out.append((tmp_path / f"o{k}" / "trace.jsonl").read_bytes())
    assert out[0] == out[1]
    trace = out[0].decode()
    assert '"action":"charge"' in trace and '"reason":"finished"' in trace
