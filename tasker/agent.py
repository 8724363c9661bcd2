"""The dynamic agent (da): one requested task, run by the hierarchical FSM of Fig. 5.

The agent owns the loop of its task; the task type (:mod:`tasker.task`) supplies
hooks.  It is stepped by a clock (:mod:`tasker.loop`) at the times it asks for:

* in ``compSP`` and ``wait`` at ``repRate`` (eqs. 22, 27): compute the schedule
  parameters, check ``ic_term``, publish the report;
* in ``exeTsk`` and ``exeSusp`` at ``taskExeRate`` (eq. 24): advance the running
  stage; in ``exeTsk`` also at ``SPupRate``: recompute the parameters;
* in ``upTsk`` and ``genSusp`` once, when the planning hook's simulated time is up;
* at once, whenever the harmoniser delivers a command.

What a command does is read off the one FSM table of :mod:`tasker.fsm`: the agent
latches it (:mod:`tasker.conditions`, as :data:`tasker.fsm.LATCHES` says) and takes the
first command row whose guards hold (:func:`tasker.fsm.enabled`) whenever it steps --
so a ``susp`` ends a suspendable stage at once and waits out a blocking one (eqs.
25-26), a ``term`` in ``cmd`` is a safe suspension followed by ``end``, and a ``start``
with ``secure`` makes a waiting agent secure its hazard (hazard-aware waiting,
``docs/model.md``).  Hooks' outcomes are fired as events (:func:`tasker.fsm.resolve`).
The agent never names a target state; it evaluates the table's guards and does what
each transition means.  Every call into a task hook or the core agent is contained
(:meth:`DynamicAgent.step`): an exception ends this task only.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from typing import Any, final

from tasker import events as ev
from tasker import fsm, securing
from tasker.conditions import Latched
from tasker.errors import AgentEnded, ConfigError, FSMError, PlanningFailed
from tasker.inputs import Parking
from tasker.messages import Command, Flag, FsmState, Report, ScheduleParams, SPRequest
from tasker.parking import ParkedReports, parking
from tasker.protocols import CoreAgent, SkillState
from tasker.rates import Rates, next_tick_of
from tasker.stage import Purpose, Stage, StagePlan
from tasker.stagerun import UNCONTAINED, StageRunner, check_goal, describe, emit_plan
from tasker.task import TaskContext, TaskType
from tasker.trace import Trace

S = FsmState
_SUSPENDING = frozenset({S.GEN_SUSP, S.EXE_SUSP})

class DynamicAgent(ParkedReports):
    """A task's dynamic agent.  Created by the harmoniser's ``pf_initDA``.

    ``report`` is the agent's report buffer; the harmoniser reads it and sends
    commands with :meth:`deliver`; ``request_sp`` answers argument-dependent
    schedule-parameter requests synchronously (eqs. 20-21).
    """

    def __init__(
        self,
        agent_id: str,
        task: TaskType,
        ctx: TaskContext,
        *,
        trace: Trace,
        rates: Rates | None = None,
        core: CoreAgent | None = None,
        world: Callable[[], Any] | None = None,
        on_report: Callable[[DynamicAgent], None] | None = None,
        waker: Callable[[DynamicAgent], None] | None = None,
    ) -> None:
        self.id = agent_id
        self.task = task
        self.ctx = ctx
        self.rates = rates or Rates()
        self.core = core
        self._trace = trace
        self._world = world
        self._on_report = on_report
        self._waker = waker
        self.state = S.INIT_COMM
        self._report: Report | None = None
        self.offer: Parking | None = None  # set by a report the loop may let age (ParkedReports.park)
        self._parked = self._next = self._clock = self._aged = None
        self.end_reason: str | None = None
        self.next_wake = ctx.request_time
        self._inbox: list[Command] = []
        self._ack = 0
        self._latched = Latched()  # ic_start, ic_susp, ic_term as the FSM's guards read them
        self._runner: StageRunner | None = None
        self._ready_at = 0.0  # end of a planning hook's simulated time
        self._next_sp = 0.0
        self._params: ScheduleParams | None = None
        self._params_at: float | None = None  # when _params was computed (None: not since the last change)
        self._fresh: tuple[float, ScheduleParams | None] | None = None  # fresh_params' answer at one moment
        self.planner_calls: list[dict[str, Any]] = []
        self._recovered = False  # this suspension already planned around a stage of exeSusp (fallback)

    # -- the harmoniser's side ----------------------------------------------------------

    def deliver(self, command: Command) -> None:
        """Put a command in the agent's command buffer (eq. 13); it acts on its next step, now."""
        self._inbox.append(command)
        if self._waker is not None:
            self._waker(self)

    def update_args(self, args: dict[str, Any], requester: str, now: float) -> None:
        """A requester changed the task's arguments (R2); parameters are recomputed at once."""
        changed = {k: v for k, v in args.items() if self.ctx.args.get(k) != v}
        self.ctx.args = dict(args)
        self._params_at = self._fresh = None
        self._trace.emit(ev.ArgsChanged(now, self.id, changed, requester))
        if self._waker is not None:
            self._waker(self)

    def request_sp(self, request: SPRequest, now: float) -> Any:
        """Answer ``[spID, args]`` with ``[scheduleParam]`` (eqs. 20-21, 23).

        A hook that raises ends this agent (cause ``error``) and raises
        :class:`~tasker.errors.AgentEnded`, so the harmoniser drops it as a candidate.
        """
        if self.state is S.END:
            raise AgentEnded(self.id, self.end_reason or "ended")
        try:
            self.refresh(now)
            return self.task.request_sp(self.ctx, request)
        except UNCONTAINED:
            raise
        except Exception as exc:
            self.fail(now, exc)
            raise AgentEnded(self.id, self.end_reason or "error") from exc

    def fresh_params(self, now: float) -> ScheduleParams | None:
        """``compute_params`` at ``now``, without publishing: for a decision made from one moment.

        Parameters already computed at ``now`` (by the agent's own timer, or by an
        earlier call) are of this moment and are returned as they are: nothing the
        hook reads changes between them, since the agent is not stepped in between.
        Returns None when the task type reports no parameters; raises
        :class:`~tasker.errors.AgentEnded` (after ending the agent) if the hook raises.
        """
        if self.state is S.END:
            raise AgentEnded(self.id, self.end_reason or "ended")
        if self._params_at == now:
            return self._params
        if self._parked is not None and self._clock is not None and self._clock() == now:
            return self.report.params if self.report is not None else None  # reported now, aged
        if self._fresh is not None and self._fresh[0] == now:
            return self._fresh[1]
        try:
            self.refresh(now)
            params = self.task.compute_params(self.ctx)
            self._fresh = (now, params)
            return params
        except UNCONTAINED:
            raise
        except Exception as exc:
            self.fail(now, exc)
            raise AgentEnded(self.id, self.end_reason or "error") from exc

    @property
    def ready_at(self) -> float:
        """When the planning hook's simulated time of ``upTsk`` or ``genSusp`` is (or was) up."""
        return self._ready_at

    @property
    def stage_plan(self) -> StagePlan | None:
        """The ``exeTsk`` or ``exeSusp`` plan the agent runs or is about to, None before the first."""
        return self._runner.plan if self._runner is not None else None

    @property
    def progress(self) -> tuple[FsmState, int]:
        """Where the agent is: its state and the index of its current stage (estimates change with it)."""
        return self.state, self._runner.index if self._runner is not None else -1

    def secure_estimate(self, now: float) -> float:
        """Seconds until this waiting agent, asked to secure now, is safe (:func:`tasker.securing.secure_estimate`)."""
        return securing.secure_estimate(self, now)

    def suspend_estimate(self, now: float, expected_s: float | None = None) -> float:
        """Seconds until this agent, sent ``susp`` now, waits (:func:`tasker.securing.suspend_estimate`)."""
        return securing.suspend_estimate(self, now, expected_s)

    def abort(self, now: float, reason: str) -> None:
        """End at once with cause ``error`` (the run is aborted): stop the running stage, guarded."""
        if self.state is not S.END:
            self._stop_stage(now, "failed", reason=reason)
            self._end(now, reason, cause="error", event="error")

    @property
    def ended(self) -> bool:
        return self.state is S.END

    # -- stepping ---------------------------------------------------------------------------

    @final
    def step(self, now: float) -> None:
        """Run the transition functions due at ``now``; set :attr:`next_wake`.

        The framework's loop (``typing.final``): a task changes what the agent does
        through the hooks of :class:`~tasker.task.TaskType`, never by overriding this.

        This is the containment boundary: an exception from a task hook, the core
        agent or a planner ends this task (``end`` with cause ``error`` and the
        exception in the reason); it never reaches the harmoniser or the loop.
        """
        if self.state is S.END:
            self.next_wake = math.inf
            return
        if self._parked is not None:  # stepped directly, not by its loop: its reports stop aging here
            self.unpark(self._clock() if self._clock is not None else None)
        self.offer = None
        self._params_at = self._fresh = None  # stepping may change what the parameters depend on
        try:
            self.refresh(now)
            self._read_inbox()
            _HANDLERS[self.state](self, now)
        except UNCONTAINED:
            raise
        except Exception as exc:
            self.fail(now, exc)

    def refresh(self, now: float) -> None:
        """Bring ``ctx.now`` and ``ctx.world`` to ``now``: what a hook reads when it is called."""
        self.ctx.now = now
        if self._world is not None:
            self.ctx.world = self._world()

    def _read_inbox(self) -> None:
        if not self._inbox:
            return
        for cmd in self._inbox:
            self._ack = cmd.seq
            if cmd.flag is Flag.SUSP and "expected_s" in cmd.data:  # how long the interruption is expected to last
                self.ctx.memory.interruption_s = float(cmd.data["expected_s"])
            self._latched.receive(cmd.flag.value, cmd.data, self.state)
        self._inbox.clear()

    # -- state behaviours ---------------------------------------------------------------

    def _init_comm(self, now: float) -> None:
        self.task.initialise(self.ctx)
        self._fire("initialised", now)
        self._comp_sp(now)

    def _comp_sp(self, now: float) -> None:
        """``compSP`` and ``wait``: f^compSP (eq. 22), f^wait = f^compSP (eq. 27).

        A latched command is taken first (``term``, then ``secure``, then ``start``: the
        table's order); else the task's own ``ic_term`` (``check_terminate``), else the
        schedule parameters are computed and reported.
        """
        t = fsm.enabled(self.state, self._guard)
        if t is None:
            why = self.task.check_terminate(self.ctx)
            if why:
                self._latched.terminate(why, "self")
                t = fsm.enabled(self.state, self._guard)
        if t is not None:
            _COMMANDS[t.event](self, now)
            return
        self._params = self.task.compute_params(self.ctx)
        self._params_at = now
        self._publish()
        self.next_wake = next_tick_of(now, self.rates.rep_rate)
        self.offer = None if self._inbox else parking(self.task, self.ctx, self._params, now)

    def _terminate(self, now: float) -> None:
        """``term [ic_term]``: end with the latched reason and cause."""
        term = self._latched.term
        assert term is not None
        self._end(now, term.reason, cause=term.cause, event="term")

    def _start_up_tsk(self, now: float) -> None:
        self._fire("start", now)
        self.refresh(now)  # plan from the world as it is now, after any effect applied this step
        try:
            plan = self.task.update_task(self.ctx)
        except PlanningFailed as exc:
            self._end(now, f"upTsk {exc.status}: {exc}", cause="failed", event="plan_failed")
            return
        self._emit_plan(now, plan)
        self.ctx.plan = plan
        self.ctx.stage_index = 0
        self._ready_at = now + plan.sim_time
        if plan.sim_time > 0:
            self.next_wake = self._ready_at
        else:
            self._up_tsk(now)

    def _up_tsk(self, now: float) -> None:
        if now < self._ready_at:
            self.next_wake = self._ready_at
            return
        plan = self.ctx.plan
        assert plan is not None
        if not plan.stages:  # nothing left to do (R6: done by someone else)
            self._end(now, "finished", cause="finished", event="planned")
            return
        self._runner = StageRunner(plan, self.id, self._trace)
        self._fire("planned", now)
        self._next_sp = next_tick_of(now, self.rates.sp_up_rate)
        self._enter_stage(now)

    def _enter_stage(self, now: float) -> None:
        """Start the runner's current stage, or suspend first if a susp or term is pending (eq. 26)."""
        runner = self._runner
        assert runner is not None
        stage = runner.stage
        if stage is None:
            if self.state is S.EXE_TSK:
                self._end(now, "finished", cause="finished", event="finished")
            else:
                self._finish_susp(now)
            return
        in_task = self.state is S.EXE_TSK
        if (t := fsm.enabled(self.state, self._guard)) is not None:  # exeTsk: suspend at a suspendable stage
            self.ctx.interrupted = stage
            self._start_gen_susp(now, t.event)
            return
        if self.core is None:
            raise ConfigError(f"agent {self.id}: a stage must run but no core agent was given")
        self.refresh(now)  # the stage before may just have changed the world
        why = self.task.inapplicable(self.ctx, stage)
        if why is not None:
            runner.event(now, self.state, "begin")
            done = self.task.already_done(self.ctx, stage)
            if done is not None:  # its effects hold already (someone else did it): skipped, no failure
                runner.close(now, self.state, "already_done", reason=done)
                self._advance(now, stage)
                return
            self._stage_failed(now, stage, why)  # as on a robot: an action that cannot run fails, changes nothing
            return
        if in_task:
            self.ctx.stage_started = now
        runner.begin(self.core, self.state, now)
        self.next_wake = next_tick_of(now, self.rates.task_exe_rate)

    def _exe(self, now: float) -> None:
        """``exeTsk`` / ``exeSusp``: f^stage,k at taskExeRate, f^compSP at SPupRate (eq. 24)."""
        runner = self._runner
        assert runner is not None and runner.stage is not None and self.core is not None
        stage = runner.stage
        in_task = self.state is S.EXE_TSK
        if (t := fsm.enabled(self.state, self._guard)) is not None:  # exeTsk: suspend at a suspendable stage
            self._suspend_now(now, stage, t.event)
            return
        status = self.core.poll(self.id, stage, now)
        if status.state is SkillState.FAILED:
            self._stage_failed(now, stage, status.reason or "no reason given")
            return
        if status.state is SkillState.SUCCEEDED:
            runner.close(now, self.state, "done")
            self._advance(now, stage)
            if self.state is not S.EXE_TSK:
                return
        elif in_task and self._latched.term is None:
            why = self.task.check_terminate(self.ctx)
            if why:  # ic_term: finish a blocking stage, then suspend safely, then end (eqs. 25-26)
                self._latched.terminate(why, "self")
                if (t := fsm.enabled(self.state, self._guard)) is not None:
                    self._suspend_now(now, stage, t.event)
                    return
        if in_task and now >= self._next_sp:
            self._params = self.task.compute_params(self.ctx)
            self._params_at = now
            self._publish()
            self._next_sp = next_tick_of(now, self.rates.sp_up_rate)
        if runner.running:
            self.next_wake = next_tick_of(now, self.rates.task_exe_rate)

    def _advance(self, now: float, stage: Stage) -> None:
        """``stage`` is over and done (it ran, or its effects held already): on to the next one."""
        runner = self._runner
        assert runner is not None
        if self.state is S.EXE_TSK:
            self.ctx.stage_started = None
            self.ctx.done.append(stage)
            self.ctx.stage_index = runner.index + 1
        self.task.on_stage_done(self.ctx, stage)
        runner.index += 1
        self._enter_stage(now)

    def _stage_failed(self, now: float, stage: Stage, reason: str) -> None:
        """The running stage failed (its skill said so, or it could not run): close it ``failed``; in
        ``exeSusp`` the task ends (or, under ``fallback``, plans around it once), in ``exeTsk`` it is
        first made safe (genSusp, exeSusp), then ends."""
        runner = self._runner
        assert runner is not None
        runner.close(now, self.state, "failed", reason=reason)
        failure = f"stage {stage.label} failed: {reason}"
        target = fsm.resolve(self.state, "stage_failed", self._guard).target
        if self.state is S.EXE_SUSP and target is S.GEN_SUSP:  # fallback: from the world as it is, once
            self.ctx.recovering = failure
            try:
                self._start_gen_susp(now, "stage_failed")
            finally:
                self.ctx.recovering = None
            return
        if target is S.END:
            # a suspension's own stage: nothing safer to fall back on
            self._end(now, self._after_failure(failure), cause="failed", event="stage_failed")
            return
        # the task cannot go on, but what it leaves must be safe: genSusp, exeSusp, then end
        self._latched.terminate(failure, "failed")
        self._suspend_now(now, stage, event="stage_failed")  # the stage is closed: nothing to stop

    def _suspend_now(self, now: float, stage: Stage, event: str = "suspend") -> None:
        """A suspendable stage of exeTsk ends at once for a pending susp or term (eq. 26), or a
        failed one (``event`` ``stage_failed``) before its task ends."""
        self._stop_stage(now, "stopped")
        self.ctx.interrupted = stage
        self.ctx.stage_started = None
        self._start_gen_susp(now, event)

    def _after_failure(self, why: str) -> str:
        """``why``, after the failure whose safe suspension it interrupted, if it did."""
        term = self._latched.term
        if term is not None and term.cause == "failed":
            return f"{term.reason}; then {why}"
        return why

    def _start_gen_susp(self, now: float, event: str = "suspend") -> None:
        """Enter ``genSusp`` by ``event`` and ask ``generate_suspension``: after a ``susp``, a ``term`` or a
        failed stage; again after a stage of ``exeSusp`` that cannot run (``fallback``); or, by
        ``secure``, from ``wait`` (hazard-aware waiting): then under the ``strict`` policy, so that
        whatever a ``conditional`` branch left unsafe for a short interruption is made safe now that
        the interruption has lasted."""
        secure, again = event == "secure", self.state is S.EXE_SUSP  # again: planning around its own failed stage
        self.ctx.suspended = True
        self.ctx.terminating = not secure and self._latched.term is not None
        self._fire(event, now)
        self._recovered = again
        self.refresh(now)  # the stage that just ended may have changed the world
        strategy = self.ctx.strategy
        if secure:
            self.ctx.strategy = replace(strategy, policy="strict")
        try:
            plan = self.task.generate_suspension(self.ctx)
        except PlanningFailed as exc:
            what = "genSusp (secure)" if secure else "genSusp"
            self._end(now, self._after_failure(f"{what} {exc.status}: {exc}"), cause="failed", event="plan_failed")
            return
        finally:
            self.ctx.strategy = strategy
        self._run_suspension(now, plan)

    def _run_suspension(self, now: float, plan: StagePlan) -> None:
        self._emit_plan(now, plan)
        self._runner = StageRunner(plan, self.id, self._trace)
        self._ready_at = now + plan.sim_time
        if plan.sim_time > 0:
            self.next_wake = self._ready_at
        else:
            self._gen_susp(now)

    def _gen_susp(self, now: float) -> None:
        if now < self._ready_at:
            self.next_wake = self._ready_at
            return
        self._fire("planned", now)
        self._enter_stage(now)

    def _finish_susp(self, now: float) -> None:
        term = self._latched.term
        if fsm.resolve(self.state, "finished", self._guard).target is S.END:  # [ic_term]
            assert term is not None
            self._end(now, term.reason, cause=term.cause, event="finished")
            return
        self._fire("finished", now)
        self._comp_sp(now)

    # -- helpers ------------------------------------------------------------------------------

    def _guard(self, name: str) -> bool:
        """Evaluate a guard named in :data:`tasker.fsm.TRANSITIONS` (meanings: :data:`tasker.fsm.GUARD_MEANING`)."""
        evaluate = _GUARDS.get(name)
        if evaluate is None:
            raise ConfigError(f"agent {self.id}: the FSM names a guard {name!r} the agent does not know")
        return evaluate(self)

    def _fire(self, event: str, now: float) -> None:
        """Fire ``event`` through the FSM table: the table picks the target; traced and reported."""
        t = fsm.resolve(self.state, event, self._guard)
        if self.state in _SUSPENDING and t.target not in _SUSPENDING:
            self._check_goal(now)
        self._trace.emit(ev.Transition(now, self.id, event, self.state.value, t.target.value))
        self.state = t.target
        self._latched.enter(t.target)
        if t.target is S.END:
            self.next_wake = math.inf
        else:
            self._publish()

    def _check_goal(self, now: float) -> None:
        """The suspension ends: which literals of the goal its ``exeSusp`` aimed for do not hold now."""
        plan = self._runner.plan if self._runner is not None else None
        if plan is not None and plan.purpose is Purpose.GEN_SUSP and plan.goal is not None:
            self.refresh(now)
            check_goal(self._trace, now, self.id, plan, self.ctx.world)

    def _end(self, now: float, reason: str, *, cause: str, event: str) -> None:
        """Every end goes through here: the running stage is stopped (once), then ``event`` leads to ``end``."""
        self._stop_stage(now, "stopped")
        self._fire(event, now)
        if self.state is not S.END:
            raise FSMError(f"agent {self.id}: event {event!r} did not end the task")
        self.end_reason = reason
        self._trace.emit(ev.TaskEnded(now, self.id, self.ctx.task_type, reason, cause))
        self._publish()

    def fail(self, now: float, exc: BaseException) -> None:
        """A hook, the core agent or a planner raised ``exc``: end this task with cause ``error``.

        Called by the agent's own containment and by whoever asks a hook on its behalf
        (:mod:`tasker.securing`'s estimates)."""
        if self.state is S.END:
            return
        reason = describe(exc, self.state)
        self._stop_stage(now, "failed", reason=reason)
        self._end(now, reason, cause="error", event="error")

    def _stop_stage(self, now: float, status: str, **extra: Any) -> None:
        """Stop the running stage, if any (:meth:`tasker.stagerun.StageRunner.stop`)."""
        if self._runner is not None:
            self._runner.stop(self.core, self.state, now, status, **extra)

    def _publish(self) -> None:
        """pf^report: write the report buffer; tell the harmoniser only if it changed (newData)."""
        report = Report(self.state, self._params, self._ack, self.end_reason if self.state is S.END else None)
        if report != self._report:
            self._report = report
            if self._on_report is not None:
                self._on_report(self)

    def _emit_plan(self, now: float, plan: StagePlan) -> None:
        expected = Purpose.UP_TSK if self.state is S.UP_TSK else Purpose.GEN_SUSP
        call = emit_plan(self._trace, now, self.id, self.ctx.task_type, self.state, expected, plan)
        if call is not None:
            self.planner_calls.append(call)


def _suspendable(agent: DynamicAgent) -> bool:
    stage = agent._runner.stage if agent._runner is not None else None
    return stage is not None and not stage.blocking


_GUARDS: dict[str, Callable[[DynamicAgent], bool]] = {
    "has_stages": lambda a: a.ctx.plan is not None and bool(a.ctx.plan.stages),
    "no_stages": lambda a: a.ctx.plan is None or not a.ctx.plan.stages,
    "ic_start": lambda a: a._latched.holds("ic_start"),
    "ic_susp": lambda a: a._latched.holds("ic_susp"),
    "ic_term": lambda a: a._latched.holds("ic_term"),
    "not_ic_term": lambda a: not a._latched.holds("ic_term"),
    "secure": lambda a: a._latched.holds("secure"),
    "suspendable": _suspendable,
    "recovers": lambda a: not a._recovered and a.task.recovers_suspension(a.ctx),
}
"""How the agent evaluates each guard of :data:`tasker.fsm.GUARDS`."""

_COMMANDS: dict[str, Callable[[DynamicAgent, float], None]] = {
    "term": DynamicAgent._terminate,
    "start": DynamicAgent._start_up_tsk,
    "secure": lambda a, now: a._start_gen_susp(now, "secure"),
}
"""What the command rows that leave ``compSP`` and ``wait`` do (``suspend`` leaves ``exeTsk``)."""

_TAKEN_BY_COMP_SP = {t.event for t in fsm.TRANSITIONS if t.auto and t.source in (S.COMP_SP, S.WAIT)}
if set(_GUARDS) != set(fsm.GUARDS) or not _TAKEN_BY_COMP_SP <= set(_COMMANDS):  # the table and its runner agree
    raise FSMError(f"the agent evaluates the guards {sorted(_GUARDS)} and takes the commands {sorted(_COMMANDS)} "
                   f"in compSP and wait; the FSM table names the guards {list(fsm.GUARDS)} and the commands "
                   f"{sorted(_TAKEN_BY_COMP_SP)}")

_HANDLERS: dict[FsmState, Callable[[DynamicAgent, float], None]] = {
    S.INIT_COMM: DynamicAgent._init_comm,
    S.COMP_SP: DynamicAgent._comp_sp,
    S.UP_TSK: DynamicAgent._up_tsk,
    S.EXE_TSK: DynamicAgent._exe,
    S.GEN_SUSP: DynamicAgent._gen_susp,
    S.EXE_SUSP: DynamicAgent._exe,
    S.WAIT: DynamicAgent._comp_sp,
}
