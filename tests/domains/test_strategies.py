"""Static strategies (Alg. 3, eq. 47), fallbacks, failures, and R6 for the bundled task types."""

from __future__ import annotations

import dataclasses

import pytest

from planners.examples import StraightLineMotion
from planners.pddl_task import INTERRUPTION_KEY, PddlTaskType
from planners.planner import Planner
from planners.stages import place_of
from planners.taskspec import Branch
from tasker.errors import PlanningFailed
from tasker.stage import Purpose
from tasker.task import Strategy
from tasker.world import WorldState
from tests.domains.conftest import apply, make_ctx


def test_static_update_is_the_template(task: PddlTaskType) -> None:
    plan = task.update_task(make_ctx(task, strategy="static"))
    assert plan.strategy == "static" and plan.sim_time == task.spec.static_time_s
    assert [s.action for s in plan.stages] == [t.action for t in task.spec.static_update]


def test_static_suspension_is_the_decision_list(task: PddlTaskType) -> None:
    plan = task.generate_suspension(make_ctx(task, strategy="static"))
    assert plan.strategy == "static" and plan.purpose is Purpose.GEN_SUSP and plan.note.startswith("decision tree")


def _with_unsolvable_suspension(task: PddlTaskType) -> PddlTaskType:
    # `connected` never holds from a place to itself and no action adds it
    spec = dataclasses.replace(task.spec, suspension=(Branch(goal=(("connected", "$at:robot", "$at:robot"),)),))
    return PddlTaskType(spec, task.domain, task.hooks)


def test_unsolvable_suspension_falls_back_to_static(task: PddlTaskType) -> None:
    broken = _with_unsolvable_suspension(task)
    plan = broken.generate_suspension(make_ctx(broken))
    assert plan.strategy == "static" and plan.note.startswith("fallback to static: suspension goal unsolvable")
    assert plan.stages == task.generate_suspension(make_ctx(task, strategy="static")).stages


def test_planner_timeout_falls_back_to_static(task: PddlTaskType) -> None:
    slow = PddlTaskType(task.spec, task.domain, task.hooks, planner=Planner(cache_size=0), timeout=1e-6)
    plan = slow.update_task(make_ctx(slow))
    assert plan.strategy == "static" and "timed out" in plan.note
    assert [s.action for s in plan.stages] == [t.action for t in task.spec.static_update]
    assert "timed out" in slow.generate_suspension(make_ctx(slow, world=_mid_world(task))).note


def _mid_world(task: PddlTaskType):  # noqa: ANN202 - a WorldState
    ctx = make_ctx(task)
    exe = task.update_task(ctx)
    return apply(ctx.world, exe.stages[: len(exe.stages) - 1])


def test_unsolvable_task_raises(task: PddlTaskType) -> None:
    ctx = make_ctx(task)
    blocked = StraightLineMotion(blocked=frozenset(ctx.world.poses.values()))
    with pytest.raises(PlanningFailed) as info:
        task.update_task(make_ctx(task, motion=blocked))
    assert info.value.status == "unsolvable"


def test_unsolvable_task_names_the_places_the_robot_cannot_reach(tasks: dict[str, PddlTaskType]) -> None:
    """Before: a guide to a walled-off place ended with only "no plan reaches the goal …", which
    did not say that the robot could not get there."""
    task = tasks["guide_human"]
    ctx = make_ctx(task)
    here = next(f[2] for f in ctx.world.facts if f[:2] == ("at", "robot"))
    there = ctx.args["destination"]
    blocked = StraightLineMotion(blocked=frozenset({ctx.world.poses[there]}))
    with pytest.raises(PlanningFailed) as info:
        task.update_task(make_ctx(task, motion=blocked))
    assert info.value.status == "unsolvable"
    assert str(info.value).endswith(f"; the robot cannot drive from {here!r} to {there!r} "
                                    "(walled off, or behind a closed door)")


def test_unsolvable_task_names_where_the_thing_it_moves_is(tasks: dict[str, PddlTaskType]) -> None:
    """The item to carry lies where the robot cannot go: its place is named, not only the goal's."""
    task = tasks["carry_object"]
    ctx = make_ctx(task)
    here = next(f[2] for f in ctx.world.facts if f[:2] == ("at", "robot"))
    there = place_of(ctx.world, ctx.args["item"])
    assert there is not None and there not in (here, ctx.args["destination"])
    blocked = StraightLineMotion(blocked=frozenset({ctx.world.poses[there]}))
    with pytest.raises(PlanningFailed) as info:
        task.update_task(make_ctx(task, motion=blocked))
    assert str(info.value).endswith(f"; the robot cannot drive from {here!r} to {there!r} "
                                    "(walled off, or behind a closed door)")


def test_no_world_is_an_error(task: PddlTaskType) -> None:
    ctx = make_ctx(task)
    ctx.world = None
    with pytest.raises(PlanningFailed) as info:
        task.update_task(ctx)
    assert info.value.status == "error"


# -- task-specific behaviour ---------------------------------------------------------------------


def test_guide_alg3_greets_and_apologises_after_suspension(tasks: dict[str, PddlTaskType]) -> None:
    t = tasks["guide_human"]
    for strategy in ("planned", "static"):
        actions = [s.action for s in t.update_task(make_ctx(t, strategy=strategy, suspended=True)).stages]
        assert "greet_and_apologise" in actions and "greet" not in actions
        actions = [s.action for s in t.update_task(make_ctx(t, strategy=strategy)).stages]
        assert "greet" in actions and "greet_and_apologise" not in actions


def test_guide_eq47_save_or_apologise(tasks: dict[str, PddlTaskType]) -> None:
    t = tasks["guide_human"]
    ctx = make_ctx(t, strategy="static")
    assert t.generate_suspension(ctx).stages == ()  # not greeted: save
    greeted = make_ctx(t, strategy="static", world=ctx.world.updated([("greeted", "john")]))
    assert [s.action for s in t.generate_suspension(greeted).stages] == ["ask_to_wait"]


def test_guide_r6_person_already_there(tasks: dict[str, PddlTaskType]) -> None:
    t = tasks["guide_human"]
    world = make_ctx(t).world.updated([("at", "john", "kitchen")], [("at", "john", "hall")])
    plan = t.update_task(make_ctx(t, world=world))
    assert plan.stages == () and plan.note == "goal already holds"


def test_human_fell_r6_person_got_up(tasks: dict[str, PddlTaskType]) -> None:
    t = tasks["human_fell"]
    world = make_ctx(t).world.updated(delete=[("fallen", "peter")])
    assert t.update_task(make_ctx(t, world=world)).stages == ()


def test_carry_r6_door_opened_by_someone_else(tasks: dict[str, PddlTaskType]) -> None:
    t = tasks["carry_object"]
    assert "open_door" in [s.action for s in t.update_task(make_ctx(t)).stages]
    world = make_ctx(t).world.updated([("open", "door1")])
    assert "open_door" not in [s.action for s in t.update_task(make_ctx(t, world=world)).stages]


def test_carry_suspension_places_safely_and_closes_door(tasks: dict[str, PddlTaskType]) -> None:
    t = tasks["carry_object"]
    ctx = make_ctx(t)
    exe = t.update_task(ctx)
    k = [s.action for s in exe.stages].index("pick") + 1  # holding the vase, the door is open
    susp = t.generate_suspension(make_ctx(t, world=apply(ctx.world, exe.stages[:k])))
    actions = [s.action for s in susp.stages]
    assert "place" in actions and actions[-1] == "close_door"  # hands free before the door
    place = susp.stages[actions.index("place")]
    assert ("surface", place.args[2]) in ctx.world.facts  # only ever put down on a surface


@pytest.mark.parametrize("strategy", ["planned", "static"])
def test_cook_suspension_policy_is_the_same_factor_for_both_strategies(tasks: dict[str, PddlTaskType],
                                                                        strategy: str) -> None:
    """strict: the cooker goes off whatever the interruption; conditional: a short
    interruption leaves it on — for the planned and the static strategy alike."""
    t = tasks["cook"]
    ctx = make_ctx(t)
    exe = t.update_task(ctx)
    k = [s.action for s in exe.stages].index("cook_food")  # cooker on, pan on it
    world = apply(ctx.world, exe.stages[:k])

    def susp(policy: str, expected: float | None, w: WorldState = world) -> list[str]:
        c = make_ctx(t, strategy=strategy, world=w)
        c.strategy = Strategy(strategy, strategy, policy)
        if expected is not None:
            c.memory[INTERRUPTION_KEY] = expected
        return [s.action for s in t.generate_suspension(c).stages]

    assert susp("strict", 10.0) == susp("strict", None) == ["turn_off"]
    assert susp("conditional", None) == ["turn_off"] and susp("conditional", 10.0) == []
    k = [s.action for s in exe.stages].index("put_down")  # hot pan held
    held = apply(ctx.world, exe.stages[:k])
    off = ["turn_off"] if ("cooker_on", "cooker") in held.facts else []
    assert susp("strict", 10.0, held) == ["put_down", *off]
    assert susp("conditional", 10.0, held) == ["put_down"]


def test_a_suspension_planned_ahead_takes_the_static_time(task: PddlTaskType) -> None:
    """While exeTsk runs under the planned strategy, compSP plans the suspension ahead — for
    the state now, or during a blocking stage for the state that stage leaves (a susp waits
    for its end).  A susp in that state finds the plan made (static_time_s, the stages a
    planning then would give); in a state nobody planned for, genSusp plans (planning_time_s)."""
    from planners.estimates import estimator_for

    ctx = make_ctx(task)
    exe = task.update_task(ctx)
    last = exe.stages[-1]
    ctx.plan, ctx.stage_index, ctx.stage_started = exe, len(exe.stages) - 1, 0.0  # running its last stage
    ctx.world = apply(ctx.world, exe.stages[:-1])
    estimator_for(task).clear()
    task.compute_params(ctx)
    if last.blocking:
        ctx.world = apply(ctx.world, [last])  # the susp is honoured when the blocking stage ends
    ahead = task.generate_suspension(ctx)
    estimator_for(task).clear()
    fresh = task.generate_suspension(make_ctx(task, world=ctx.world))  # nothing planned for it
    assert ahead.sim_time == task.spec.static_time_s and ahead.strategy == "planned"
    assert [s.action for s in ahead.stages] == [s.action for s in fresh.stages]
    if fresh.stages:
        assert "planned ahead" in (ahead.note or "")
        assert fresh.sim_time == task.spec.planning_time_s and "planned ahead" not in (fresh.note or "")


def test_a_suspension_another_agent_estimated_is_planned_already(task: PddlTaskType) -> None:
    """The handover: a waiting agent's estimate asks what this task's suspension leaves
    (``leaves``), which plans that suspension into the shared cache; a susp in the same
    state then finds it planned (static_time_s), although this agent never planned ahead."""
    from planners.estimates import estimator_for

    ctx = make_ctx(task, world=_mid_world(task))
    estimator_for(task).clear()
    task.leaves(ctx, "suspend")  # what another agent's estimate asks
    plan = task.generate_suspension(ctx)
    if plan.stages:
        assert plan.sim_time == task.spec.static_time_s and "planned ahead" in (plan.note or "")
    estimator_for(task).clear()
    assert "planned ahead" not in (task.generate_suspension(make_ctx(task, world=ctx.world)).note or "")
