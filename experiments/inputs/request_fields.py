"""Request fields every scheduler sees: ``deadline`` and ``priority`` on any task type.

A day protocol gives every request a deadline (and a priority, and for a fall the time
the person is dead).  Synthetic day tasks declare these arguments themselves; a task type
built from a task folder (``planners.pddl_task.PddlTaskType``) does not, and its
``compute_params`` leaves :attr:`tasker.messages.CostParams.deadline` and ``priority``
empty.  :func:`with_request_fields` wraps such a type: the wrapper accepts the
:data:`FIELDS` as optional request arguments, hands every hook to the wrapped type
unchanged, and copies the request's ``deadline`` and ``priority`` into every
``CostParams`` the type reports, so EDF, the look-ahead and every other scheduler read
them from the schedule parameters, as with synthetic tasks.  What the task means
(:attr:`tasker.task.TaskType.meaning`), its plans and its estimates stay the folder's.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Mapping
from typing import Any

from tasker.messages import CostParams, ScheduleParams, SPRequest
from tasker.stage import Stage, StagePlan
from tasker.task import ArgSpec, TaskContext, TaskType, adjust_inner

FIELDS = (
    ArgSpec("deadline", "float", required=False, help="absolute simulated time the task should be done by"),
    ArgSpec("priority", "int", required=False, help="static priority, higher is more urgent"),
    ArgSpec("death_at", "float", required=False,
            help="time the person is dead if not helped (falls; read by the day metrics, not by the task)"),
)
FIELD_NAMES = tuple(f.name for f in FIELDS)
_NAMES = frozenset(FIELD_NAMES)


class WithRequestFields(TaskType):
    """``inner`` plus the optional request fields :data:`FIELDS` (see the module docstring)."""

    def __init__(self, inner: TaskType) -> None:
        self.inner = inner
        self.name = inner.name
        self.description = inner.description
        self.meaning = inner.meaning
        self.arg_specs = (*inner.arg_specs, *FIELDS)

    def __getattr__(self, name: str) -> Any:  # attributes of the wrapped type (spec, domain, ...)
        if name == "inner":
            raise AttributeError(name)
        return getattr(self.inner, name)

    def check_args(self, args: dict[str, Any]) -> None:
        """The wrapped type checks its own arguments (the types of :data:`FIELDS` are checked already)."""
        self.inner.check_args({k: v for k, v in args.items() if k not in _NAMES})

    def adjust_args(self, given: Mapping[str, Any], args: dict[str, Any]) -> None:
        """The wrapped type adjusts its own arguments; :data:`FIELDS` follow them, as given."""
        adjust_inner(self.inner, _NAMES, given, args)

    def initialise(self, ctx: TaskContext) -> None:
        self.inner.initialise(ctx)

    def compute_params(self, ctx: TaskContext) -> ScheduleParams:
        params = self.inner.compute_params(ctx)
        if isinstance(params, CostParams):
            return dataclasses.replace(params, deadline=ctx.args.get("deadline"), priority=ctx.args.get("priority"))
        return params

    def request_sp(self, ctx: TaskContext, request: SPRequest) -> Any:
        return self.inner.request_sp(ctx, request)

    def update_task(self, ctx: TaskContext) -> StagePlan:
        return self.inner.update_task(ctx)

    def generate_suspension(self, ctx: TaskContext) -> StagePlan:
        return self.inner.generate_suspension(ctx)

    def check_terminate(self, ctx: TaskContext) -> str | None:
        return self.inner.check_terminate(ctx)

    def on_stage_done(self, ctx: TaskContext, stage: Stage) -> None:
        self.inner.on_stage_done(ctx, stage)


def asked_for(actions: Iterable[Any]) -> bool:
    """Whether a scenario's requests (or changes) give any of :data:`FIELDS`.

    A robot scenario file that writes ``deadline = 200.0`` in a request's ``args`` gets its
    task types wrapped (:func:`with_request_fields`) both when it is checked and when it is
    run; a file that writes none runs its task types as they are.
    """
    return any(a.kind in ("request", "change") and not _NAMES.isdisjoint(a.fields.get("args") or {})
               for a in actions)


def with_request_fields(task: TaskType) -> TaskType:
    """``task`` itself when it already declares every field of :data:`FIELDS`, else wrapped."""
    if _NAMES <= {a.name for a in task.arg_specs}:
        return task
    return WithRequestFields(task)
