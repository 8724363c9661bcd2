"""Fixtures for the task-domain tests: every bundled task type, contexts on its example world."""

from __future__ import annotations

from collections.abc import Iterable

import pytest
import unified_planning as up

import domains
from planners.bundled import task_types
from planners.checks import load_problem_text
from planners.examples import StraightLineMotion, example_context
from planners.pddl_task import PddlTaskType
from planners.planner import PddlText
from tasker.stage import Stage
from tasker.task import Strategy, TaskContext
from tasker.world import WorldState

BUNDLED = domains.bundled_names()
MOTION = StraightLineMotion()


@pytest.fixture(scope="session")
def tasks() -> dict[str, PddlTaskType]:
    out = {t.name: t for t in task_types()}
    assert all(isinstance(t, PddlTaskType) for t in out.values())
    return out  # type: ignore[return-value]


@pytest.fixture(params=BUNDLED)
def task(request: pytest.FixtureRequest, tasks: dict[str, PddlTaskType]) -> PddlTaskType:
    return tasks[request.param]


def make_ctx(task: PddlTaskType, *, strategy: str = "planned", world: WorldState | None = None,
             motion: object = MOTION, suspended: bool = False) -> TaskContext:
    ctx = example_context(task, strategy=Strategy(strategy, strategy), motion=motion, world=world)
    assert ctx is not None
    ctx.suspended = suspended
    return ctx


def apply(world: WorldState, stages: Iterable[Stage]) -> WorldState:
    """What the executor does when stages succeed: apply their grounded effects."""
    for s in stages:
        world = world.updated([tuple(f) for f in s.data["add"]], [tuple(f) for f in s.data["delete"]])
    return world


def up_problem(task: PddlTaskType, text: PddlText) -> up.model.Problem:
    return load_problem_text(task.domain.checked, text.problem)


def steps(stages: Iterable[Stage]) -> list[tuple[str, ...]]:
    return [(s.action, *s.args) for s in stages]
