"""Running one stage FSM (``exeTsk`` or ``exeSusp``) on the core agent: ``pf^stage,k`` of eq. 24.

A :class:`StageRunner` knows which stage of a :class:`~tasker.stage.StagePlan` its agent is
at and whether that stage runs; it begins the stage on the core agent, and stops and
closes it -- ``core.stop`` at most once a stage, guarded -- writing the ``stage`` events
of the trace.  The dynamic agent (:mod:`tasker.agent`) decides when, from its FSM; this
module only does it.  Also here, since both modules call hooks: what a hook's exception is
called in the trace (:func:`describe`) and which exceptions are no one task's fault
(:data:`UNCONTAINED`); and what a plan is and what it left, in the trace (:func:`emit_plan`,
:func:`check_goal`).  Stdlib only.
"""

from __future__ import annotations

import traceback
from pathlib import Path
from typing import Any

from tasker import events as ev
from tasker.errors import ConfigError, InvariantViolation, WorldError
from tasker.fsm import FsmState
from tasker.meaning import holds
from tasker.protocols import CoreAgent
from tasker.stage import Purpose, Stage, StagePlan
from tasker.trace import Trace

VOLATILE_INFO = frozenset({"planner_time_s", "cached", "wall_time_s"})
"""Keys of ``StagePlan.info`` that vary from run to run: kept out of the trace (it must be
reproducible byte for byte) and collected in :attr:`tasker.agent.DynamicAgent.planner_calls` instead."""

UNCONTAINED = (InvariantViolation, WorldError)
"""Exceptions that are not one task's fault: a broken model invariant or a broken world."""

_RUNNER_FILES = frozenset({__file__, str(Path(__file__).with_name("agent.py"))})
"""The framework's own frames, skipped when naming the hook that raised."""


def describe(exc: BaseException, state: FsmState) -> str:
    """``"<hook>() raised <Type>: <message> (in <state>)"``: where it came from, without file paths.

    The hook is the first frame outside the agent and this module, so the reason names
    the task hook or core-agent method the agent called (``update_task``, ``poll``, ...).
    """
    where = None
    for frame in traceback.extract_tb(exc.__traceback__):
        if frame.filename not in _RUNNER_FILES:
            where = frame.name
            break
    origin = f"{where}() raised " if where else ""
    return f"{origin}{type(exc).__name__}: {exc} (in {state.value})"


class StageRunner:
    """Runs the stages of one ``exeTsk`` or ``exeSusp`` plan for agent ``agent``, in order."""

    __slots__ = ("plan", "index", "running", "_agent", "_trace")

    def __init__(self, plan: StagePlan, agent: str, trace: Trace) -> None:
        self.plan = plan
        self.index = 0
        self.running = False
        self._agent = agent
        self._trace = trace

    @property
    def stage(self) -> Stage | None:
        """The stage the runner is at (running or about to), None once every stage is done."""
        return self.plan.stages[self.index] if self.index < len(self.plan.stages) else None

    def begin(self, core: CoreAgent, state: FsmState, now: float) -> None:
        """Begin the current stage on the core agent."""
        stage = self.stage
        assert stage is not None
        self.running = True  # before begin: a begin that raises still gets a guarded stop and its closing event
        self.event(now, state, "begin")
        core.begin(self._agent, stage, now)

    def stop(self, core: CoreAgent | None, state: FsmState, now: float, status: str, **extra: Any) -> None:
        """Stop the running stage, if any: ``core.stop`` at most once a stage, guarded, then its closing event.

        A stop that raises while the stage is being closed as ``failed`` adds to its reason; otherwise
        (a suspension or an end stopping it) the stage closes ``failed`` and the exception is raised:
        it is the task's error.
        """
        stage = self.stage
        if not self.running or stage is None:
            return
        self.running = False  # first: a stop that raises is never attempted twice
        if core is not None:
            try:
                core.stop(self._agent, stage, now)
            except UNCONTAINED:
                raise
            except Exception as exc:
                if status == "failed":
                    extra["reason"] = f"{extra.get('reason', '')}; then {describe(exc, state)}".lstrip("; ")
                else:
                    self.close(now, state, "failed", reason=describe(exc, state))
                    raise
        self.close(now, state, status, **extra)

    def close(self, now: float, state: FsmState, status: str, **extra: Any) -> None:
        """The current stage is over (``done``, ``failed``, ``stopped``): write its closing event."""
        self.running = False
        self.event(now, state, status, **extra)

    def event(self, now: float, state: FsmState, status: str, **extra: Any) -> None:
        """Write the ``stage`` event of the current stage."""
        stage = self.stage
        assert stage is not None
        self._trace.emit(ev.StageChanged(now, self._agent, state.value, self.index, stage.action, list(stage.args),
                                         stage.kind.value, status, **extra))


def emit_plan(trace: Trace, now: float, agent: str, task_type: str, state: FsmState, expected: Purpose,
              plan: StagePlan) -> dict[str, Any] | None:
    """Trace the ``plan`` event of what ``upTsk``/``genSusp`` (``state``) built; return the planner
    call to remember (with its wall-clock values, which stay out of the trace), or None.  A hook
    that returned something else than a :class:`StagePlan` of the ``expected`` purpose is the task
    type's error (:class:`~tasker.errors.ConfigError`)."""
    if not isinstance(plan, StagePlan):
        raise ConfigError(f"task type {task_type!r} returned a {type(plan).__name__} in {state.value}, "
                          "expected a StagePlan")
    info, call = None, None
    if plan.info:
        info = {k: v for k, v in plan.info.items() if k not in VOLATILE_INFO} or None
        call = {"t": now, "agent": agent, "purpose": plan.purpose.value, "strategy": plan.strategy,
                **dict(plan.info)}
    if plan.purpose is not expected:
        raise ConfigError(f"task type {task_type!r} returned a {plan.purpose.value} plan in {state.value}")
    goal = None if plan.goal is None else [list(lit) for lit in plan.goal]
    trace.emit(ev.PlanMade(now, agent, plan.purpose.value, plan.strategy, [s.to_json() for s in plan.stages],
                           plan.note or None, info, goal))
    return call


def check_goal(trace: Trace, now: float, agent: str, plan: StagePlan, world: Any) -> None:
    """A suspension ends: trace (:class:`~tasker.events.GoalChecked`) which literals of the goal its
    ``exeSusp`` ``plan`` aimed for do not hold in ``world`` now — nothing when the plan says no goal or
    the world has no facts (a synthetic run)."""
    facts = getattr(world, "facts", None)
    if plan.goal is None or facts is None:
        return
    unmet = [list(lit) for lit in plan.goal if not holds(lit, facts)]
    trace.emit(ev.GoalChecked(now, agent, [list(lit) for lit in plan.goal], unmet))
