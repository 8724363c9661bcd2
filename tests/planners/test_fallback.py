"""The ``fallback`` suspension strategy on a real task folder (carry_object): the tree's branch where its
stages can run, a plan to the derived goal where they cannot, the trace's note saying which and why."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from planners.examples import example_context
from planners.loader import load_task
from planners.pddl_task import PddlTaskType
from tasker.errors import PlanningFailed
from tasker.task import Strategy, TaskContext
from tasker.world import WorldState

DOMAINS = Path(__file__).resolve().parents[2] / "domains"


@pytest.fixture(scope="module")
def carry() -> PddlTaskType:
    task = load_task(DOMAINS / "carry_object")
    assert isinstance(task, PddlTaskType)
    return task


def _holding(task: PddlTaskType, at: str, suspension: str = "fallback") -> TaskContext:
    """The example's world with the robot at ``at`` holding the vase, interrupted."""
    ctx = example_context(task, strategy=Strategy("planned", suspension, "strict"))
    assert ctx is not None and isinstance(ctx.world, WorldState)
    world = ctx.world.updated([("holding", "robot", "vase"), ("at", "robot", at), ("clear", "kitchen")],
                              [("hand_empty", "robot"), ("at", "vase", "kitchen"), ("at", "robot", "livingroom")])
    return replace(ctx, world=world, suspended=True)


def test_where_the_trees_stages_can_run_fallback_runs_them_as_written(carry: PddlTaskType) -> None:
    plan = carry.generate_suspension(_holding(carry, "livingroom"))  # a surface: it may put the vase down here
    static = carry.generate_suspension(_holding(carry, "livingroom", "static"))
    assert plan.strategy == "fallback" and plan.info == {"fallback": "tree"}
    assert [s.label for s in plan.stages] == [s.label for s in static.stages] == ["place(robot, vase, livingroom)"]
    assert plan.goal == static.goal == (("hand_empty", "robot"),)
    assert plan.note is not None and "runs as written" in plan.note


def _cluttered(ctx: TaskContext, place: str) -> TaskContext:
    """``ctx`` with ``place`` not clear: someone left something there."""
    assert isinstance(ctx.world, WorldState)
    return replace(ctx, world=ctx.world.updated(delete=[("clear", place)]))


def test_where_a_stage_of_the_tree_cannot_run_fallback_plans_to_the_derived_goal_and_says_why(
        carry: PddlTaskType) -> None:
    # the tree puts the vase down where the robot stands, a surface -- but someone left a box there
    plan = carry.generate_suspension(_cluttered(_holding(carry, "livingroom"), "livingroom"))
    assert plan.strategy == "fallback" and plan.info["fallback"] == "planned"
    assert plan.note is not None and "place(robot, vase, livingroom) needs (clear livingroom)" in plan.note
    labels = [s.label for s in plan.stages]
    assert labels[-1].startswith("place(robot, vase, ") and labels[-1] != "place(robot, vase, livingroom)"
    assert ("not", "holding", "robot", "vase") in (plan.goal or ())
    static = carry.generate_suspension(_cluttered(_holding(carry, "livingroom", "static"), "livingroom"))
    assert [s.label for s in static.stages] == ["place(robot, vase, livingroom)"]  # static stays the pure tree
    assert static.strategy == "static"


def test_asked_again_after_a_stage_of_exesusp_failed_fallback_plans_at_once(carry: PddlTaskType) -> None:
    ctx = replace(_holding(carry, "livingroom"), recovering="stage place failed: someone put a box there")
    plan = carry.generate_suspension(ctx)
    assert plan.info["fallback"] == "planned" and "someone put a box there" in (plan.note or "")


def test_when_no_plan_reaches_the_derived_goal_fallback_fails_genSusp_with_both_reasons(carry: PddlTaskType) -> None:
    ctx = _holding(carry, "livingroom")
    assert isinstance(ctx.world, WorldState)
    full = WorldState(frozenset(f for f in ctx.world.facts if f[0] != "clear"), ctx.world.poses, ctx.world.objects)
    with pytest.raises(PlanningFailed) as err:  # no surface anywhere is clear
        carry.generate_suspension(replace(ctx, world=full))
    assert "needs (clear livingroom)" in str(err.value) and "no plan reaches the derived goal" in str(err.value)
