"""A task that finds a door closed opens it (issue 9): every bundled domain whose robot moves.

The example world of each task folder is turned into a "shut in" world: the robot's place
becomes a room whose only way out is one closed door (what carry_object's suspension leaves
in the compound scenario).  The task must still plan its goal, by opening that door; its
suspension must close a door left open; with the door open, nothing is opened.  Nothing
here names a bundled action: doors are found by their effects on ``open`` facts.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import domains
from experiments.run.runner import run_scenario
from planners.examples import example_world
from planners.pddl_task import PddlTaskType
from planners.validate import validate_plan
from tasker.stage import Purpose, Stage
from tasker.world import WorldState
from tests.domains.conftest import BUNDLED, apply, make_ctx, steps, up_problem

ROOT = Path(__file__).parents[2]
COMPOUND = ROOT / "experiments" / "sweep" / "specs" / "scenarios" / "compound.toml"
DOOR = "shut_door"


def moving(tasks: dict[str, PddlTaskType]) -> list[PddlTaskType]:
    return [t for t in tasks.values() if any(a.skill == "navigate" for a in t.spec.actions.values())]


def shut_in(task: PddlTaskType, *, open_: bool = False) -> WorldState:
    """The example world with the robot's place closed off by one door (closed unless ``open_``)."""
    world = example_world(task)
    assert world is not None
    robot = [f[2] for f in world.facts if f[0] == "at" and f[1] == "robot"][0]
    places = sorted(n for n, t in world.objects.items() if t == "place" and n != robot)
    facts = {("door_at", DOOR, robot)}
    facts |= {("door_between", DOOR, a, b) for p in places for a, b in ((robot, p), (p, robot))}
    if open_:
        facts.add(("open", DOOR))
    return WorldState(world.facts | facts, world.poses, {**world.objects, DOOR: "door"}, world.time)


def opens(stages: list[Stage]) -> list[Stage]:
    return [s for s in stages if ["open", DOOR] in [list(f) for f in s.data["add"]]]


def closes(stages: list[Stage]) -> list[Stage]:
    return [s for s in stages if ["open", DOOR] in [list(f) for f in s.data["delete"]]]


def test_every_bundled_task_moves(tasks: dict[str, PddlTaskType]) -> None:
    assert {t.name for t in moving(tasks)} == set(domains.bundled_names())  # the tests below are not vacuous


@pytest.mark.slow
@pytest.mark.parametrize("name", BUNDLED)
def test_a_closed_door_is_opened_on_the_way(tasks: dict[str, PddlTaskType], name: str) -> None:
    task = tasks[name]
    ctx = make_ctx(task, world=shut_in(task))
    plan = task.update_task(ctx)
    assert plan.stages, f"{name}: shut in by a closed door, upTsk found no plan: {plan.note}"
    check = validate_plan(up_problem(task, task.planning_problem(ctx, Purpose.UP_TSK)), steps(plan.stages))
    assert check.valid, check.reason
    assert len(opens(plan.stages)) == 1 and plan.stages[0] is opens(plan.stages)[0], steps(plan.stages)


@pytest.mark.slow
@pytest.mark.parametrize("name", BUNDLED)
def test_an_open_door_is_passed_not_opened(tasks: dict[str, PddlTaskType], name: str) -> None:
    task = tasks[name]
    ctx = make_ctx(task, world=shut_in(task, open_=True))
    plan = task.update_task(ctx)
    assert plan.stages and not opens(plan.stages), steps(plan.stages)
    check = validate_plan(up_problem(task, task.planning_problem(ctx, Purpose.UP_TSK)), steps(plan.stages))
    assert check.valid, check.reason


def test_without_door_facts_plans_do_not_change(tasks: dict[str, PddlTaskType]) -> None:
    """A door object in a world with no ``door_between`` fact (every bundled world but flat): the
    plan is the one of the world without it, step for step."""
    for task in moving(tasks):
        world = example_world(task)
        assert world is not None
        with_door = WorldState(world.facts | {("open", DOOR)}, world.poses, {**world.objects, DOOR: "door"})
        assert steps(task.update_task(make_ctx(task, world=with_door)).stages) == \
            steps(task.update_task(make_ctx(task, world=world)).stages), task.name


@pytest.mark.parametrize("strategy", ["planned", "static"])
@pytest.mark.parametrize("name", BUNDLED)
def test_suspension_closes_the_door_it_opened(tasks: dict[str, PddlTaskType], name: str, strategy: str) -> None:
    """Interrupted right after opening the door (nothing else to make safe): close it."""
    task = tasks[name]
    ctx = make_ctx(task, world=shut_in(task))
    exe = task.update_task(ctx)
    ctx_1 = make_ctx(task, strategy=strategy, world=apply(ctx.world, exe.stages[:1]))
    assert ctx_1.world is not None and ctx_1.world.holds("open", DOOR)
    ctx_1.plan, ctx_1.stage_index, ctx_1.interrupted = exe, 1, exe.stages[1]
    susp = task.generate_suspension(ctx_1)
    assert susp.strategy == strategy and closes(susp.stages), f"{name}: {susp.note}: {steps(susp.stages)}"
    assert not ctx_1.world.holds("open", DOOR) or apply(ctx_1.world, susp.stages).facts.isdisjoint({("open", DOOR)})


@pytest.mark.slow
def test_compound_scenario_nobody_is_shut_in(tasks: dict[str, PddlTaskType]) -> None:
    """carry_object's suspension closes the bedroom door from inside: every task still finishes (a task
    that must pass opens it), and carry leaves the door closed, as it found it ([problem] restore)."""
    r = run_scenario(COMPOUND, pictures=False)
    ends = {e["agent"]: e for e in r.trace.of("end")}
    assert len(ends) == 3 and all(e["cause"] == "finished" for e in ends.values()), \
        {a: e["reason"] for a, e in ends.items()}
    carry = r.trace.of("request")[0]["agent"]
    closes = [s["action"] for p in r.trace.of("plan", agent=carry, purpose="upTsk") for s in p["stages"]]
    assert closes and closes[-1] == "close_door"  # its last plan ends closing the door it opened


def opens_a_door(task: PddlTaskType, action: str) -> bool:
    return any(e.fluent == "open" and e.positive for e in task.domain.actions[action].effects)


def _type(r: object, agent: str) -> str:
    return next(e["task_type"] for e in r.trace.of("request") if e["agent"] == agent)  # type: ignore[attr-defined]
