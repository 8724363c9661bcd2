"""The drawn work of a day on the robot backend: stage durations from the request, and non-preemptive types.

A task folder declares how long each of its actions takes (``[actions.NAME] duration``);
TaBSA's day draws that per request (a fall's help U(60, 300) s, a pick and a place
U(60, 300) s each).  A protocol's ``[robot_backend.tasks.KIND] durations`` names, per action
of the folder, the drawn value it takes (``{ call_help = "$work" }``); the day's requests
carry them as arguments ``ACTION_s`` (:data:`SUFFIX`), and :class:`DrawnWork` wraps the
folder's task type so that every ``exeTsk`` plan gives those stages those durations.  A type
the protocol declares ``preemptive = false`` runs every stage of its ``exeTsk`` blocking:
once started it runs to its end, whatever the scheduler asks (TaBSA's falls and
pick-and-place), as on the synthetic backend (:mod:`experiments.days.daytask`).

The estimates follow: while the task executes its own plan (which carries the drawn
durations) they are the folder's; otherwise the folder's estimate (a plan or template with
the declared durations) gains, for every drawn action the task has not yet completed, the
drawn minus the declared duration, and the cost its cost rate times that.
:func:`wrapper_for` is what :meth:`experiments.days.pipeline.Day.run` hands the runner.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from typing import Any

from tasker.messages import CompletionCost, CostParams, ScheduleParams, SPRequest
from tasker.stage import Stage, StageKind, StagePlan
from tasker.task import ArgSpec, Effects, Leaving, TaskContext, TaskType, adjust_inner

SUFFIX = "_s"
"""A drawn duration's request argument: the action's name and this suffix (``call_help_s``)."""


class DrawnWork(TaskType):
    """``inner`` with drawn stage durations for ``actions`` and, unless ``preemptive``, every
    ``exeTsk`` stage blocking (see the module docstring)."""

    def __init__(self, inner: TaskType, actions: tuple[str, ...], preemptive: bool = True) -> None:
        self.inner = inner
        self.actions = actions
        self.preemptive = preemptive
        self.name = inner.name
        self.description = inner.description
        self.meaning = inner.meaning
        self._own = tuple(ArgSpec(a + SUFFIX, "float", required=False,
                                  help=f"seconds the {a!r} stage takes (drawn by the day)") for a in actions)
        self.arg_specs = (*inner.arg_specs, *self._own)
        self._names = frozenset(s.name for s in self._own)

    def __getattr__(self, name: str) -> Any:  # the wrapped type's attributes (spec, domain, ...)
        if name == "inner":
            raise AttributeError(name)
        return getattr(self.inner, name)

    # -- arguments --------------------------------------------------------------------------------------
    def check_args(self, args: dict[str, Any]) -> None:
        self.inner.check_args({k: v for k, v in args.items() if k not in self._names})

    def adjust_args(self, given: Mapping[str, Any], args: dict[str, Any]) -> None:
        adjust_inner(self.inner, self._names, given, args)

    # -- the durations ----------------------------------------------------------------------------------
    def _drawn(self, ctx: TaskContext) -> dict[str, float]:
        return {a: float(v) for a in self.actions if (v := ctx.args.get(a + SUFFIX)) is not None}

    def declared(self, action: str) -> float:
        """The folder's duration of ``action`` (its ``duration``, else the domain's constant cost, else 0)."""
        spec = getattr(getattr(self.inner, "spec", None), "actions", {}).get(action)
        if spec is not None and spec.duration is not None:
            return float(spec.duration)
        model = getattr(getattr(self.inner, "domain", None), "actions", {}).get(action)
        return float(getattr(model, "constant_cost", None) or 0.0)

    def extra(self, ctx: TaskContext) -> float:
        """Seconds the drawn durations add to an estimate built with the declared ones: every drawn
        action not yet completed in ``exeTsk``."""
        done = {s.action for s in ctx.done}
        return math.fsum(v - self.declared(a) for a, v in self._drawn(ctx).items() if a not in done)

    def _stages(self, ctx: TaskContext, stages: tuple[Stage, ...]) -> tuple[Stage, ...]:
        drawn = self._drawn(ctx)
        out = []
        for s in stages:
            changes: dict[str, Any] = {}
            if s.action in drawn:
                changes["duration"] = drawn[s.action]
            if not self.preemptive and s.kind is not StageKind.BLOCKING:
                changes["kind"] = StageKind.BLOCKING
            out.append(dataclasses.replace(s, **changes) if changes else s)
        return tuple(out)

    # -- hooks ------------------------------------------------------------------------------------------
    def initialise(self, ctx: TaskContext) -> None:
        self.inner.initialise(ctx)

    def update_task(self, ctx: TaskContext) -> StagePlan:
        plan = self.inner.update_task(ctx)
        return dataclasses.replace(plan, stages=self._stages(ctx, plan.stages))

    def generate_suspension(self, ctx: TaskContext) -> StagePlan:
        return self.inner.generate_suspension(ctx)

    def compute_params(self, ctx: TaskContext) -> ScheduleParams:
        params = self.inner.compute_params(ctx)
        if not isinstance(params, CostParams) or _executing(ctx):
            return params
        extra = self.extra(ctx)
        if not extra or not math.isfinite(params.c_time):
            return params
        return dataclasses.replace(params, c_time=params.c_time + extra, cost=params.cost + params.cps * extra)

    def request_sp(self, ctx: TaskContext, request: SPRequest) -> Any:
        answer = self.inner.request_sp(ctx, request)
        if not isinstance(answer, CompletionCost) or not math.isfinite(answer.cc):
            return answer
        # an answer for another start is built from a hypothetical plan (declared durations)
        asked_elsewhere = any(request.args.get(k) for k in ("pose", "start_pose", "end_pose", "after"))
        if _executing(ctx) and not asked_elsewhere:
            return answer
        return dataclasses.replace(answer, cc=answer.cc + answer.ccps * self.extra(ctx))

    def check_terminate(self, ctx: TaskContext) -> str | None:
        return self.inner.check_terminate(ctx)

    def on_stage_done(self, ctx: TaskContext, stage: Stage) -> None:
        self.inner.on_stage_done(ctx, stage)

    def leaves(self, ctx: TaskContext, how: Leaving) -> Effects | None:
        return self.inner.leaves(ctx, how)


def _executing(ctx: TaskContext) -> bool:
    """A stage of this task's own ``exeTsk`` plan runs (its estimate is that plan's remainder)."""
    from planners.estimates import executing

    return executing(ctx)


def wrapper_for(work: Mapping[str, tuple[tuple[str, ...], bool]]) -> Callable[[TaskType], TaskType]:
    """Wrap each task type named in ``work`` (task name -> (drawn actions, preemptive)); others unchanged."""
    def wrap(task: TaskType) -> TaskType:
        if task.name not in work:
            return task
        actions, preemptive = work[task.name]
        if not actions and preemptive:
            return task
        return DrawnWork(task, actions, preemptive)

    return wrap
