"""Example contexts built from a task folder's ``[example]`` world, and a stand-in motion model.

Used by ``tasker fsm``, the tests and the benchmark.  :class:`StraightLineMotion` is a
deterministic stand-in for the OMPL model of ``robot/``: straight-line distance at a
fixed speed plus a rotation term; places listed as ``blocked`` are unreachable.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from tasker.task import Strategy, TaskContext
from tasker.world import UNREACHABLE, MotionEstimate, MotionModel, Pose, WorldState

if TYPE_CHECKING:
    from planners.pddl_task import PddlTaskType


@dataclass(frozen=True, slots=True)
class StraightLineMotion:
    """Travel time = distance / ``speed`` + |heading change| / ``turn_rate``; deterministic."""

    speed: float = 0.5
    turn_rate: float = 1.0
    blocked: frozenset[Pose] = field(default_factory=frozenset)

    def estimate(self, start: Pose, goal: Pose) -> MotionEstimate:
        if tuple(goal) in self.blocked:
            return UNREACHABLE
        dx, dy = goal[0] - start[0], goal[1] - start[1]
        dist = math.hypot(dx, dy)
        heading = math.atan2(dy, dx) if dist > 1e-9 else start[2]
        turn = abs((heading - start[2] + math.pi) % (2 * math.pi) - math.pi)
        return MotionEstimate(True, dist / self.speed + turn / self.turn_rate, dist, (goal[0], goal[1], heading))


def example_world(task: PddlTaskType) -> WorldState | None:
    """The ``[example]`` world of a task folder, as a :class:`WorldState`."""
    ex = task.spec.example
    if ex is None:
        return None
    return WorldState(frozenset(tuple(f) for f in ex.facts), dict(ex.poses), dict(ex.objects))


def example_context(task: PddlTaskType, *, strategy: Strategy | None = None, motion: MotionModel | None = None,
                    world: WorldState | None = None) -> TaskContext | None:
    """A :class:`TaskContext` for the task's example request in its example world."""
    ex = task.spec.example
    if ex is None:
        return None
    return TaskContext(
        agent=f"{task.name}-example", task_type=task.name, args=task.validate_args(dict(ex.args)),
        request_time=0.0, rng=random.Random(0), strategy=strategy or Strategy(),
        world=world if world is not None else example_world(task), motion=motion,
    )
