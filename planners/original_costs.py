"""The original TaskER cost model (2019), offered by a folder with ``[schedule.taskER-2019]``.

A request with ``cost_model = "taskER-2019"`` is costed as the 2019 code costed a guidance:
path metres to the person and on to the destination, weighted per person (``docs/model.md``).
:class:`planners.pddl_task.PddlTaskType` calls these for such a request."""

from __future__ import annotations

import math
from typing import Protocol

from planners.problem import holds
from planners.stages import Bindings, robot_name
from planners.taskspec import ORIGINAL, TaskSpec
from tasker.errors import PlanningFailed
from tasker.messages import CompletionCost, CostParams
from tasker.task import TaskContext
from tasker.world import Pose, WorldState


class CostedTask(Protocol):
    """What the original cost model needs of a task type (:class:`planners.pddl_task.PddlTaskType`)."""

    name: str
    spec: TaskSpec

    def world_of(self, ctx: TaskContext) -> WorldState: ...


def _state(task: CostedTask, ctx: TaskContext) -> tuple[WorldState, Pose, tuple[float, float, float], float, bool]:
    """The world, the person's pose, the factors (walk, stand, sit), the rate of the person's
    cost while they wait (``f_stand`` until greeted, then ``f_sit``: what the 2019 code answered
    for a waiting or suspended guideHuman) and whether they walk with the robot now."""
    model = task.spec.original_costs
    assert model is not None
    world = task.world_of(ctx)
    b = Bindings(ctx.args, world)
    person = b.token(model.person)
    if person not in world.poses:
        raise PlanningFailed("error", f"{task.name}: no pose for {person!r}")
    f = tuple(float(ctx.args[t[1:]]) for t in model.factors) if model.factors else (1.0, 1.0, 1.0)
    walking = bool(model.walk) and holds(world.facts, b.literals(model.walk))
    greeted = walking or bool(model.sit) and holds(world.facts, b.literals(model.sit))
    return world, world.poses[person], (f[0], f[1], f[2]), f[2] if greeted else f[1], walking


def _metres(task: CostedTask, ctx: TaskContext, start: Pose, goal: Pose) -> float:
    if ctx.motion is None:
        raise PlanningFailed("error", f"{task.name}: the {ORIGINAL} cost model needs a motion model")
    est = ctx.motion.estimate(start, goal)
    return float(est.distance_m) if est.reachable else math.inf


def params(task: CostedTask, ctx: TaskContext) -> CostParams:
    """The 2019 code's ``getSP()``: with *a* the robot's path to the person and *g* the
    person's path to the destination (metres), ``cost = g·f_walk`` while the person walks
    with the robot, else ``a·rate + g·f_walk``; ``cps = rate``; ``cTime = a + g`` (metres,
    as the original); ``endPose`` the destination, or the person without one."""
    model = task.spec.original_costs
    assert model is not None
    world, person, (f_walk, _, _), rate, walking = _state(task, ctx)
    a = 0.0 if walking else _metres(task, ctx, world.poses[robot_name(world)], person)
    end = person
    g = 0.0
    if model.destination is not None:
        place = Bindings(ctx.args, world).token(model.destination)
        if place not in world.poses:
            raise PlanningFailed("error", f"{task.name}: no pose for {place!r}")
        end = world.poses[place]
        g = _metres(task, ctx, person, end)
    if not (math.isfinite(a) and math.isfinite(g)):
        return CostParams(task.name, cost=math.inf, cps=rate, c_time=math.inf, end_pose=end)
    return CostParams(task.name, cost=g * f_walk + (0.0 if walking else a * rate), cps=rate, c_time=a + g,
                      end_pose=end)


def completion(task: CostedTask, ctx: TaskContext, start: Pose | None) -> CompletionCost:
    """The 2019 code's cost and suspend conditions: ``cc`` is the path from ``start`` to the
    person times the waiting rate (the approach leg only), ``ccps`` that rate."""
    world, person, _, rate, _ = _state(task, ctx)
    a = _metres(task, ctx, start if start is not None else world.poses[robot_name(world)], person)
    return CompletionCost(cc=a * rate if math.isfinite(a) else math.inf, ccps=rate)
