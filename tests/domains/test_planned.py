"""Planned upTsk and genSusp for every bundled task type, checked by UP's validator and simulator."""

from __future__ import annotations

import math

import pytest

from planners.pddl_task import PddlTaskType
from planners.validate import state_after, validate_plan
from tasker.stage import Purpose, StageKind
from tests.domains.conftest import apply, make_ctx, steps, up_problem


def test_update_plan_is_valid_and_costed(task: PddlTaskType) -> None:
    ctx = make_ctx(task)
    plan = task.update_task(ctx)
    assert plan.purpose is Purpose.UP_TSK and plan.strategy == "planned" and plan.stages
    assert plan.sim_time == task.spec.planning_time_s
    check = validate_plan(up_problem(task, task.planning_problem(ctx, Purpose.UP_TSK)), steps(plan.stages))
    assert check.valid, check.reason
    assert check.cost == plan.info["cost"]


def test_stages_follow_the_skill_contract(task: PddlTaskType) -> None:
    for s in task.update_task(make_ctx(task)).stages:
        spec = task.spec.actions[s.action]
        assert s.skill == spec.skill and s.kind is spec.kind
        assert s.duration > 0 and math.isfinite(s.duration)
        assert isinstance(s.data["add"], list) and isinstance(s.data["delete"], list)
        if s.skill == "navigate":
            assert isinstance(s.data["to"], str) and s.data["to"] in s.args
        if s.skill == "say":
            assert s.data["text"] and "{" not in s.data["text"]


@pytest.mark.slow
def test_effects_match_ups_simulator(task: PddlTaskType) -> None:
    """data["add"]/["delete"] applied to the world give the state UP's SequentialSimulator gives."""
    ctx = make_ctx(task)
    plan = task.update_task(ctx)
    problem = up_problem(task, task.planning_problem(ctx, Purpose.UP_TSK))
    for k in range(1, len(plan.stages) + 1):
        ctx_k = make_ctx(task, world=apply(ctx.world, plan.stages[:k]))
        _, init, _ = task.problem_text(ctx_k, *task.update_inputs(ctx_k))
        assert init == state_after(problem, steps(plan.stages), k), f"after {k} stage(s)"


@pytest.mark.slow
def test_partial_execution_plans_only_the_remaining_work(task: PddlTaskType) -> None:
    ctx = make_ctx(task)
    plan = task.update_task(ctx)
    full = steps(plan.stages)
    for k in range(1, len(full)):
        ctx_k = make_ctx(task, world=apply(ctx.world, plan.stages[:k]))
        ctx_k.memory = ctx.memory  # the same agent: it remembers what it found ([problem] restore)
        again = task.update_task(ctx_k)
        problem = up_problem(task, task.planning_problem(ctx_k, Purpose.UP_TSK))
        check = validate_plan(problem, steps(again.stages))
        assert check.valid, check.reason
        suffix = validate_plan(problem, full[k:])
        assert suffix.valid and check.cost == suffix.cost, f"after {k}: replanned work differs from what remained"
        assert not set(steps(again.stages)) & set(full[:k]), "work already done is planned again"


@pytest.mark.slow
def test_suspension_depends_on_the_interruption_point(task: PddlTaskType) -> None:
    ctx = make_ctx(task)
    exe = task.update_task(ctx)
    found: dict[tuple[tuple[str, ...], ...], int] = {}
    for k in range(len(exe.stages)):
        ctx_k = make_ctx(task, world=apply(ctx.world, exe.stages[:k]))
        ctx_k.plan, ctx_k.stage_index, ctx_k.interrupted = exe, k, exe.stages[k]
        susp = task.generate_suspension(ctx_k)
        assert susp.purpose is Purpose.GEN_SUSP and susp.strategy == "planned", susp.note
        problem = up_problem(task, task.planning_problem(ctx_k, Purpose.GEN_SUSP))
        check = validate_plan(problem, steps(susp.stages))  # valid and reaches the suspension goal
        assert check.valid, f"interrupted before stage {k}: {check.reason}"
        found.setdefault(tuple(steps(susp.stages)), k)
    assert len(found) >= 3, f"{task.name}: suspension plans by interruption point: {found}"


def test_blocking_stages_are_declared_ones(task: PddlTaskType) -> None:
    blocking = {n for n, a in task.spec.actions.items() if a.kind is StageKind.BLOCKING}
    plan = task.update_task(make_ctx(task))
    assert {s.action for s in plan.stages if s.blocking} == {s.action for s in plan.stages} & blocking


def test_deterministic(task: PddlTaskType) -> None:
    from planners.loader import load_task
    from planners.planner import Planner

    a = load_task(task.spec.folder)
    b = load_task(task.spec.folder)
    a._planner, b._planner = Planner(cache_size=0), Planner(cache_size=0)
    for hook in ("update_task", "generate_suspension"):
        pa, pb = getattr(a, hook)(make_ctx(a)), getattr(b, hook)(make_ctx(b))
        assert (pa.stages, pa.strategy, pa.sim_time, pa.note) == (pb.stages, pb.strategy, pb.sim_time, pb.note)
        assert {k: v for k, v in pa.info.items() if k != "planner_time_s"} == \
            {k: v for k, v in pb.info.items() if k != "planner_time_s"}  # wall time is a metric, not the model
