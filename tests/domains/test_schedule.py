"""Schedule parameters: cost = cps * (age + cTime), in seconds; unreachable is inf, never zero."""

from __future__ import annotations

import math

import pytest

from planners.examples import StraightLineMotion
from planners.pddl_task import PddlTaskType
from tasker.messages import SP_COMPLETION, CompletionCost, CostParams, SPRequest
from tests.domains.conftest import make_ctx


def test_compute_params(task: PddlTaskType) -> None:
    ctx = make_ctx(task)
    ctx.now = 30.0
    p = task.compute_params(ctx)
    assert isinstance(p, CostParams) and p.task_type == task.name
    assert 0 < p.c_time < math.inf and p.cps == task.spec.cps
    assert p.cost == task.spec.cps * (30.0 + p.c_time) and p.end_pose is not None


def test_params_follow_the_plan_once_made(task: PddlTaskType) -> None:
    ctx = make_ctx(task)
    ctx.plan = task.update_task(ctx)
    ctx.stage_started = ctx.now  # executing: its plan is its plan from the state now
    full = task.compute_params(ctx).c_time
    ctx.stage_index = 1
    assert task.compute_params(ctx).c_time < full


def test_without_motion_model_declared_durations_are_used(task: PddlTaskType) -> None:
    p = task.compute_params(make_ctx(task, motion=None))
    assert 0 < p.c_time < math.inf


def test_unreachable_is_infinite(task: PddlTaskType) -> None:
    ctx = make_ctx(task)
    blocked = StraightLineMotion(blocked=frozenset(ctx.world.poses.values()))
    p = task.compute_params(make_ctx(task, motion=blocked))
    assert p.cost == math.inf and p.c_time == math.inf


@pytest.mark.slow
def test_request_sp_completion_cost(task: PddlTaskType) -> None:
    ctx = make_ctx(task)
    near = task.request_sp(ctx, SPRequest(SP_COMPLETION, {"pose": ctx.world.poses["robot"]}))
    far = task.request_sp(ctx, SPRequest(SP_COMPLETION, {"pose": (40.0, 40.0, 0.0)}))
    assert isinstance(near, CompletionCost) and near.ccps == task.spec.cps
    assert near.cc == task.compute_params(ctx).cost and far.cc > near.cc


def test_fallen_person_costs_more_per_second_than_a_guided_one(tasks: dict[str, PddlTaskType]) -> None:
    assert tasks["human_fell"].spec.cps > tasks["guide_human"].spec.cps


def test_without_world_declared_template_time(task: PddlTaskType) -> None:
    ctx = make_ctx(task)
    ctx.world = None
    p = task.compute_params(ctx)
    assert 0 < p.c_time < math.inf and p.end_pose is None
