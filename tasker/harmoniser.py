"""The task harmoniser (tha): Fig. 7, ``f^harm`` of eq. 36, and Alg. 1.

One :meth:`TaskHarmoniser.step` computes the composite transition function:

* ``pf_initDA`` for every new request in the task buffers: a new agent joins
  ``idleDA`` (``D_r``);
* ``term_event`` (eq. 38): agents that reported ``end`` leave ``A_da`` (Alg. 1,
  lines 15-16; done first, so a freed ``exeDA`` is refilled in the same step);
* ``pf_schedule`` when ``timer(sFreq)`` fires or on ``shdl_event`` (eq. 37), only
  while ``irrDA`` is empty; in constant-task (CT) harmonisation, or with a
  non-preemptive algorithm, only while no agent executes;
* ``pf_switchDA`` (Alg. 1) when ``irrDA`` is set or on ``term_event``: ``susp`` to
  the executing agent, and once it reports ``wait`` (acknowledging that ``susp``),
  ``start`` to ``irrDA``.

The harmoniser never waits on an agent, and it enforces the invariant that at most
one agent is in ``cmd``: every report updates the set of agents in ``cmd``, and a
second member is an :class:`~tasker.errors.InvariantViolation`.

Departures from the letter of Alg. 1, all to keep its intent: ``susp`` is sent only
when a replacement (``irrDA``) exists — on a bare ``term_event`` line 3 would suspend
the executing task for nothing —, and once per switch rather than on every
iteration; and ``pf_switchDA`` also runs while the executing agent is suspending,
so that if ``irrDA`` ends meanwhile the suspended agent still leaves ``exeDA``
(eq. 36 would never trigger it again: found by the property test).

**Hazard-aware waiting** (``hazard_waiting=True`` and a ``hazards`` source, e.g.
:meth:`tasker.meaning.Monitor.active`), not in the paper: at each ``timer(sFreq)``
the harmoniser checks every waiting agent whose hazard holds and is unattended; when
the budget left is no more than the time to secure it (:class:`tasker.securing.HazardWatch`),
it makes that agent ``irrDA`` whatever the scheduler says — the executing agent is
suspended safely the normal way — and starts it with ``secure``: the agent reaches
its ``strict`` safe state and waits again (``docs/model.md``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from enum import StrEnum
from typing import Any, final

from tasker import events as ev
from tasker.agent import DynamicAgent
from tasker.errors import AgentEnded, ConfigError, InvariantViolation, TaskerError, WorldError
from tasker.messages import Command, Flag, FsmState, ScheduleParams, SPRequest
from tasker.oscillation import OscillationGuard
from tasker.schedulers.base import Candidate, Scheduler, ScheduleView, UnattendedHazard
from tasker.schedulers.index import (
    CandidateIndex,
    IdleAgents,
    IdleCandidates,
    QueueAhead,
    ReportedCandidates,
    reported_c_time,
)
from tasker.securing import HazardSource, HazardWatch, suspend_estimate
from tasker.task import Effects
from tasker.trace import Trace

_TRACED = frozenset({"by", "expected_s", "predicted_s", "secure"})
"""Command data copied into the ``command`` trace event."""


class Mode(StrEnum):
    """Task harmonisation: interruptible-task (IT) or constant-task (CT)."""

    IT = "IT"
    CT = "CT"


@dataclass(frozen=True, slots=True)
class Request:
    """A task request from a requester (tra): a task type and its (validated) arguments.

    ``renews``: the agent whose task this request asks for again, after that task ended
    without doing its work (e.g. a fall detector still sees the person down); traced, so
    a reader can count needs rather than attempts."""

    task_type: str
    args: Mapping[str, Any] = field(default_factory=dict)
    requester: str = "user"
    renews: str | None = None


AgentFactory = Callable[[str, Request, float, Callable[[DynamicAgent], None]], DynamicAgent]


@dataclass(slots=True)
class _Securing:
    """The agent chosen to secure its hazard, its estimated time to secure, and the ``start`` it was sent."""

    agent: str
    secure_s: float
    seq: int | None = None


class TaskHarmoniser:
    """The robot's task harmoniser.  ``exe_da``, ``irr_da`` and ``idle_da`` are its roles.

    ``hazard_waiting`` (default off) selects hazard-aware waiting, one factor of the
    static-versus-planned sweep (``docs/model.md``): with a ``hazards`` source (set
    here or later as :attr:`hazards`), a waiting agent secures its hazard before the
    hazard's budget runs out (module docstring).  ``secure_margin_s`` is the slack
    added to the estimated time to secure.
    """

    incremental: bool = True
    """Keep the candidates of an :attr:`~tasker.schedulers.base.Scheduler.indexed` scheduler in a heap
    updated on each report (:mod:`tasker.schedulers.index`), so a decision does not scan every waiting
    agent.  False (on an instance or the class) scans, as every unindexed scheduler does: the reference
    computation, kept callable; decisions and traces are the same either way."""

    scan_below: int = 32
    """With no more waiting agents than this, and none parked (:mod:`tasker.parking`), a decision scans
    them: a short scan is cheaper than the heap, which reports keep exact for when it is used."""

    def __init__(
        self,
        scheduler: Scheduler,
        agent_factory: AgentFactory,
        *,
        trace: Trace,
        mode: Mode = Mode.IT,
        s_freq: float = 1.0,
        guard: OscillationGuard | None = OscillationGuard(),
        hazard_waiting: bool = False,
        hazards: HazardSource | None = None,
        secure_margin_s: float = 5.0,
        secure_over_higher: bool = False,
    ) -> None:
        if not isinstance(s_freq, int | float) or s_freq <= 0:
            raise ConfigError(f"sFreq must be a positive number of Hz, got {s_freq!r}")
        self.scheduler = scheduler
        self.mode = Mode(mode)
        self.s_freq = float(s_freq)
        self.guard = guard  # None: no oscillation guard
        self.hazard_waiting = bool(hazard_waiting)  # hazard-aware waiting, a sweep factor
        self.hazards = hazards  # where hazard-aware waiting learns of hazards (None: it has nothing to watch)
        self.watch = HazardWatch(secure_margin_s, 1.0 / self.s_freq)  # hazard-aware waiting's memory
        self.secure_over_higher = bool(secure_over_higher)  # may securing preempt a task of a higher class?
        self._held_secures: set[tuple[str, str]] = set()  # (waiting agent, exeDA) whose securing was held
        self._securing: _Securing | None = None
        self._became: dict[str, list[float]] = {}  # when each agent became exeDA since the last new request
        self._factory = agent_factory
        self._trace = trace
        self.agents: dict[str, DynamicAgent] = {}  # A_da
        self._handovers: dict[tuple[str, str, float], Effects | None] = {}  # handover's answers
        self._suspensions: dict[tuple[float, str, str | None], float] = {}  # _suspension_of's answers
        self.exe_da: str | None = None
        self.irr_da: str | None = None
        self._idle = IdleAgents()  # D_r, in request order (its version counts changes: ScheduleView.generation)
        self._requests: list[tuple[str, Request]] = []
        self._terms: list[tuple[str, str]] = []
        self._ended: list[str] = []
        self._new_data = False
        self._in_cmd: set[str] = set()
        self._cands = ReportedCandidates(self.agents, self._idle)  # by agent; a parked agent's aged when read
        self._queue_ahead = QueueAhead(self._cands, self._idle)  # a susp's expected_s, one sum per moment
        self._index: CandidateIndex | None = None  # built at the first indexed decision
        self._order: dict[str, int] = {}
        self._seq = 0
        self._susp_seq: dict[str, int] = {}
        self._count = 0
        self._roles_dirty = False
        self._last_roles: tuple[Any, ...] | None = None
        self.now = 0.0

    # -- the requesters' side (taskIF) -----------------------------------------------------

    def submit(self, request: Request) -> str:
        """Queue a request; ``pf_initDA`` creates its agent at the next step.  Returns its id."""
        self._count += 1
        agent_id = f"d{self._count}"
        self._requests.append((agent_id, request))
        return agent_id

    def terminate(self, agent_id: str, reason: str = "terminated by the requester") -> None:
        """Ask for a task to end (``term``).  An executing task first suspends safely."""
        issued = agent_id[:1] == "d" and agent_id[1:].isdigit() and 1 <= int(agent_id[1:]) <= self._count
        if not issued:
            raise TaskerError(f"no task {agent_id!r}; active: {sorted(self.agents) or 'none'}")
        self._terms.append((agent_id, reason))  # a task that has already ended is left alone

    def set_mode(self, mode: Mode | str) -> None:
        """Switch between IT and CT harmonisation while running (paper feature 8)."""
        new = Mode(mode)
        if new is not self.mode:
            self.mode = new
            self._trace.emit(ev.ModeChanged(self.now, new.value))

    @property
    def idle_da(self) -> list[str]:
        return list(self._idle)

    @property
    def in_cmd(self) -> frozenset[str]:
        """Agents whose last report puts them in ``cmd`` (never more than one)."""
        return frozenset(self._in_cmd)

    @property
    def busy(self) -> bool:
        """True while any request is pending or any agent lives."""
        return bool(self._requests or self.agents or self._terms)

    # -- f^harm ------------------------------------------------------------------------------

    @final
    def step(self, now: float, timer: bool = False) -> None:
        """One iteration of ``f^harm`` (eq. 36) at simulated time ``now``.

        The framework's loop: a subclass must not override it (``typing.final``); a
        scheduling algorithm plugs in as a :class:`~tasker.schedulers.Scheduler`.
        """
        self.now = now
        if self._requests:
            self._pf_init_da(now)
        if self._terms:
            self._deliver_terms()
        term_event = bool(self._ended)
        if term_event:
            self._remove_ended()
        if timer and self.hazard_waiting and self.hazards is not None and self._securing is None:
            self._watch_hazards(now)
        shdl_event = (self.exe_da is None and self.irr_da is None and bool(self._idle)) or self._new_data
        self._new_data = False
        if (timer or shdl_event) and self.irr_da is None and self._securing is None:
            if self.exe_da is None or (self.mode is Mode.IT and self.scheduler.preemptive):
                self._pf_schedule(now)
        suspending = self.exe_da is not None and self.exe_da in self._susp_seq
        if self.irr_da is not None or term_event or suspending or self._securing is not None:
            self._pf_switch_da(now)
            if self.exe_da is None and self.irr_da is None and self._idle:  # freed: shdl_event at once
                self._pf_schedule(now)
                if self.irr_da is not None:
                    self._pf_switch_da(now)
        if self._roles_dirty:
            self._emit_roles(now)

    def _pf_init_da(self, now: float) -> None:
        for agent_id, request in self._requests:
            agent = self._factory(agent_id, request, now, self._on_report)
            self.agents[agent_id] = agent
            self._order[agent_id] = len(self._order)
            self._idle[agent_id] = None
            self._trace.emit(ev.TaskRequested(now, agent_id, request.task_type, dict(request.args),
                                              request.requester, request.renews))
        self._requests.clear()
        self._became.clear()  # a new request may legitimately preempt again
        self._roles_dirty = True

    def _deliver_terms(self) -> None:
        for agent_id, reason in self._terms:
            if agent_id in self.agents and not self.agents[agent_id].ended:
                self._send(agent_id, Flag.TERM, {"reason": reason})
        self._terms.clear()

    def _remove_ended(self) -> None:
        for agent_id in self._ended:
            self.agents.pop(agent_id, None)
            self._idle.pop(agent_id, None)
            self._cands.pop(agent_id, None)
            if self._index is not None:
                self._index.discard(agent_id)
            self._susp_seq.pop(agent_id, None)
            self._became.pop(agent_id, None)
            if self.exe_da == agent_id:
                self.exe_da = None
            if self.irr_da == agent_id:
                self.irr_da = None
            if self._securing is not None and self._securing.agent == agent_id:
                self._trace.emit(ev.SecureChanged(self.now, agent_id, "ended"))
                self._securing = None
        self._ended.clear()
        self._roles_dirty = True

    def _pf_schedule(self, now: float) -> None:
        """``pf_schedule`` (eq. 35), contained: a scheduler that raises is recorded and changes nothing."""
        name = self.scheduler.name
        for _ in range(len(self._idle) + 2):  # each retry follows an agent that ended while asked
            exe = self._cands.get(self.exe_da) if self.exe_da is not None else None
            index = self._candidate_index() if len(self._idle) > self.scan_below or self._cands.parked else None
            if index is not None and index.ready(self._cands) and not index.needs_scan(self._idle):
                lowest = index.lowest(self._idle)
                if lowest is None:
                    return
                view = ScheduleView(now=now, exe=exe, candidates=IdleCandidates(self._idle, self._cands),
                                    req_sp=self._req_sp, fresh=self._fresh, lowest=self._cands[lowest])
            else:  # the idle agents' candidates (aged, unless the scheduler reads no waiting cost)
                candidates = self._cands.of(self._idle, aged=self.scheduler.reads_cost)
                if candidates is None:
                    return
                view = ScheduleView(now=now, exe=exe, candidates=candidates, req_sp=self._req_sp, fresh=self._fresh,
                                    generation=self._idle.version)
            if self.scheduler.reads_harmoniser:  # what a whole-queue scheduler weighs beyond the reports
                view = replace(view, suspension=self._suspension_of if exe is not None else None,
                               hazards=self._unattended())
            try:
                decision = self.scheduler.schedule(view)
            except AgentEnded:
                self._remove_ended()  # no longer a candidate (or no longer executing): decide again
                continue
            except (InvariantViolation, WorldError):
                raise
            except Exception as exc:
                self._trace.emit(ev.Decision(now, {"algorithm": name, "rule": "error", "switch": False,
                                                   "error": f"{type(exc).__name__}: {exc}"}))
                return
            break
        else:
            return
        choice = decision.irr_da
        if choice is not None and choice not in self._idle:
            self._trace.emit(ev.Decision(now, {
                "algorithm": name, "rule": "error", "switch": False,
                "error": f"the scheduler chose {choice!r}, which is not idle; idle: {list(self._idle)}"}))
            return
        record = decision.record
        if choice is not None and record is None:  # every choice leaves a decision, whatever the scheduler
            record = {"algorithm": name, "dac": choice, "exeDA": exe.id if exe is not None else None,
                      "rule": "no exeDA" if exe is None else "choice", "switch": True}
        if choice is not None and exe is not None and record is not None:
            held = self._held(choice, exe.id, now)
            if held is not None:
                record = {**record, "switch": False, "held": held}
                choice = None
        if record is not None:
            self._trace.emit(ev.Decision(now, record))
        if choice is not None:
            del self._idle[choice]
            self.irr_da = choice
            self._roles_dirty = True

    def _suspension_of(self, by: str) -> float:
        """Seconds the executing agent needs to report ``wait`` if sent ``susp`` now with ``by`` as its
        replacement (:func:`tasker.securing.suspend_estimate`, for the interruption that ``susp`` would
        announce); one estimate per moment, or per replacement and moment if it read the interruption's length."""
        if self.exe_da is None:
            return 0.0
        memo, key, any_by = self._suspensions, (self.now, self.exe_da, by), (self.now, self.exe_da, None)
        if key not in memo:
            if any_by in memo:  # this moment's suspension did not read how long the interruption lasts
                return memo[any_by]
            if len(memo) > 256:
                memo.clear()
            expected, reads = self._susp_data(by).get("expected_s"), set[str]()
            memo[key] = suspend_estimate(self.agents[self.exe_da], self.now, expected, reads)
            if "interruption_s" not in reads:
                memo[any_by] = memo[key]
        return memo[key]

    def _unattended(self) -> tuple[UnattendedHazard, ...]:
        """The hazards that hold now while their agent is out of ``cmd``, with when that stretch began
        (as hazard-aware waiting counts it, :class:`tasker.securing.HazardWatch`)."""
        if self.hazards is None:
            return ()
        out = []
        for hz in self.hazards():
            agent = hz.agent
            if agent is None or agent not in self.agents or agent in self._in_cmd:
                continue
            since = max(float(hz.since), self.watch.left_cmd.get(agent, float(hz.since)))
            out.append(UnattendedHazard(agent, str(hz.name), float(hz.budget_s), since))
        return tuple(out)

    def _candidate_index(self) -> CandidateIndex | None:
        """The heap of candidates' keys for the current scheduler, or None to scan (built on first use)."""
        if not (self.incremental and self.scheduler.indexed):
            return None
        if self._index is None or self._index.scheduler is not self.scheduler:  # first use, or a new scheduler
            self._index = CandidateIndex(self.scheduler, self.agents)
            for agent in self._cands:
                self._index.touch(agent)
        return self._index

    def _held(self, dac: str, exe: str, now: float) -> dict[str, Any] | None:
        """The oscillation guard: why a preemption of ``exe`` by ``dac`` is held back, or None."""
        guard = self.guard
        if guard is None:
            return None
        for agent in (dac, exe):
            recent = [t for t in self._became.get(agent, ()) if now - t < guard.window_s]
            if len(recent) >= guard.count:
                return {"guard": "oscillation", "agent": agent, "became_exeDA": recent,
                        "window_s": guard.window_s, "count": guard.count}
        return None

    def _pf_switch_da(self, now: float) -> None:
        """Alg. 1."""
        exe = self.exe_da
        securing = self._securing
        if exe is not None and securing is not None and securing.agent == exe:
            report = self.agents[exe].report
            assert report is not None
            if report.fsm_state is FsmState.WAIT and securing.seq is not None and report.ack >= securing.seq:
                self._secure_done(now, exe)  # secured and waiting again: back to idleDA
        elif exe is not None:
            report = self.agents[exe].report
            assert report is not None
            state = report.fsm_state
            if state.in_cmd:  # line 2
                if self.irr_da is not None and exe not in self._susp_seq:
                    self._susp_seq[exe] = self._send(exe, Flag.SUSP, self._susp_data(self.irr_da))  # line 3
            elif state is FsmState.WAIT and exe in self._susp_seq and report.ack >= self._susp_seq[exe]:  # line 5
                # a ``wait`` that does not acknowledge our ``susp`` predates the last ``start``: not a suspension
                self._idle[exe] = None  # line 6
                self._susp_seq.pop(exe, None)
                self.exe_da = None  # line 7
                self._roles_dirty = True
        if self.exe_da is None and self.irr_da is not None:  # line 9
            if self._in_cmd:
                raise InvariantViolation(f"about to start {self.irr_da} while {sorted(self._in_cmd)} is in cmd")
            self.exe_da, self.irr_da = self.irr_da, None  # lines 10-11
            if securing is not None and securing.agent == self.exe_da:  # not a resumption: not in the guard's count
                securing.seq = self._send(self.exe_da, Flag.START, {"secure": True})
            else:
                self._became.setdefault(self.exe_da, []).append(now)
                self._send(self.exe_da, Flag.START, self._start_data(self.exe_da))  # line 12
            self._roles_dirty = True

    # -- hazard-aware waiting ----------------------------------------------------------------

    def _watch_hazards(self, now: float) -> None:
        """Hazard-aware waiting: if a waiting agent must secure its hazard now, make it ``irrDA``."""
        assert self.hazards is not None
        waiting = {a: da for a in self._idle if (da := self.agents.get(a)) is not None and not da.ended
                   and da.report is not None and da.report.fsm_state is FsmState.WAIT}
        if not waiting:
            return
        exe = self.agents.get(self.exe_da) if self.exe_da is not None else None
        try:
            waiting = self._held_by_class(now, waiting, exe)
            due = self.watch.due(now, self.hazards(), waiting, exe, self._order) if waiting else None
        except AgentEnded:
            self._remove_ended()
            return
        if due is None:
            return
        agent, hz = due.agent, due.hazard
        self._securing = _Securing(agent, due.secure_s)
        self._trace.emit(ev.Decision(now, {
            "algorithm": self.scheduler.name, "rule": "secure", "dac": agent, "exeDA": self.exe_da, "switch": True,
            "hazard": str(hz.name), "args": list(hz.fact[1:]), "remaining_s": due.remaining_s,
            "secure_s": due.secure_s, "suspend_s": due.suspend_s,
            "margin_s": self.watch.margin_s + self.watch.period_s}))
        self._trace.emit(ev.SecureChanged(now, agent, "start",
                                          [{"hazard": e[1], "args": list(e[2][1:])} for e in due.episodes]))
        if self.irr_da is not None:  # a switch already under way: the hazard goes first
            self._idle[self.irr_da] = None
        del self._idle[agent]
        self._idle.sort(key=lambda a: self._order.get(a, 0))
        self.irr_da = agent
        self._roles_dirty = True

    def _held_by_class(self, now: float, waiting: dict[str, DynamicAgent],
                       exe: DynamicAgent | None) -> dict[str, DynamicAgent]:
        """The safety rule: securing a hazard never preempts a task whose priority class outranks the
        securing one (:meth:`Scheduler.outranks`) unless ``secure_over_higher`` allows it.  A waiting
        agent held back this way, whose hazard is due, leaves one ``decision`` with ``rule: "secure
        held"`` per executing task, saying which rule decided; it may secure once that task is done."""
        top = self._cands.get(exe.id) if exe is not None else None
        if top is None or self.secure_over_higher:
            return waiting
        held = {a: da for a, da in waiting.items()
                if (c := self._cands.get(a)) is not None and self.scheduler.outranks(top, c)}
        if held and self.hazards is not None:
            due = self.watch.due(now, self.hazards(), held, exe, self._order, mark=False)
            if due is not None and (due.agent, top.id) not in self._held_secures:
                self._held_secures.add((due.agent, top.id))
                self._trace.emit(ev.Decision(now, {
                    "algorithm": self.scheduler.name, "rule": "secure held", "dac": due.agent, "exeDA": top.id,
                    "switch": False, "hazard": str(due.hazard.name), "args": list(due.hazard.fact[1:]),
                    "remaining_s": due.remaining_s,
                    "why": "the executing task's priority class outranks the one that would secure its hazard "
                           "(secure_over_higher is off)"}))
        return {a: da for a, da in waiting.items() if a not in held}

    def _secure_done(self, now: float, agent: str) -> None:
        self._trace.emit(ev.SecureChanged(now, agent, "done"))
        self._securing = None
        self._idle[agent] = None
        self._idle.sort(key=lambda a: self._order.get(a, 0))
        self.exe_da = None
        self._roles_dirty = True

    # -- agents' side -----------------------------------------------------------------------

    def _send(self, agent_id: str, flag: Flag, data: Mapping[str, Any] | None = None) -> int:
        self._seq += 1
        fields = {k: v for k, v in (data or {}).items() if k in _TRACED}
        self._trace.emit(ev.CommandSent(self.now, agent_id, flag.value, **fields))
        self.agents[agent_id].deliver(Command(flag, self._seq, dict(data or {})))
        return self._seq

    def _start_data(self, agent_id: str) -> dict[str, Any]:
        """``data`` of a ``start``: the agent's cTime from the world as it is at the start, as
        ``predicted_s`` (its parameters computed now: the task it replaces has suspended since
        its last report, e.g. put down what it held); the last reported one if that fails."""
        c_time = None
        try:
            fresh = self._fresh(agent_id)
            value = getattr(fresh, "c_time", None)
            c_time = float(value) if isinstance(value, int | float) else None
        except Exception:  # the hook failed (the agent ends with its reason): the last report
            c_time = None
        if c_time is None:
            c_time = self._c_time(agent_id)
        return {} if c_time is None else {"predicted_s": c_time}

    def _c_time(self, agent_id: str) -> float | None:
        return reported_c_time(self._cands, agent_id)

    def _susp_data(self, replacement: str) -> dict[str, Any]:
        """``data`` of a ``susp``: who takes over (``by``) and how long the interruption is expected to last.

        ``expected_s`` is estimated from the queue: the replacement's cTime, plus the
        cTime of every waiting agent the scheduler ranks ahead of the suspended one
        (:meth:`Scheduler.queue_key`): they run before it resumes.  Still a lower
        bound (later requests, suspensions and re-planning are not foreseen).  A
        task's suspension may depend on it (a cooker left on for a short interruption).
        """
        data: dict[str, Any] = {"by": replacement}
        if self._securing is not None and self._securing.agent == replacement:
            data["expected_s"] = self._securing.secure_s  # it secures its hazard, then waits again
            return data
        c_time = self._c_time(replacement)
        if c_time is None:
            return data
        data["expected_s"] = c_time + self._queue_ahead.of(self.scheduler, self.exe_da, self.now)
        return data

    def _req_sp(self, agent_id: str, request: SPRequest) -> Any:
        return self.agents[agent_id].request_sp(request, self.now)

    def handover(self, asker: str, after: str | None = None) -> Effects | None:
        """What another task would leave changed before ``asker`` could start (an estimate's
        :attr:`TaskContext.handover <tasker.task.TaskContext.handover>`).

        ``after=None``: the executing agent's suspension, if ``asker`` replaced it now
        (None unless another agent runs a stage of ``exeTsk``); ``after`` an agent's id: what
        that agent leaves changed when it completes.  From the agent's ``leaves`` hook on its
        own context; one answer per agent, way and moment.  A hook that raises assumes nothing:
        the agent's own hooks report its failure."""
        other, how = (self.exe_da, "suspend") if after is None else (after, "complete")
        if other is None or other == asker or other not in self.agents:
            return None
        agent = self.agents[other]
        if how == "suspend" and agent.state is not FsmState.EXE_TSK:
            return None  # already suspending, planning or securing: the world says what it is
        key = (other, how, self.now)
        if key not in self._handovers:
            if len(self._handovers) > 64:
                self._handovers.clear()
            try:
                effects = agent.task.leaves(agent.ctx, how)  # type: ignore[arg-type]
            except Exception:
                effects = None
            self._handovers[key] = effects if isinstance(effects, Effects) and effects else None
        return self._handovers[key]

    def _fresh(self, agent_id: str) -> ScheduleParams | None:
        return self.agents[agent_id].fresh_params(self.now)

    def park(self, agent_id: str, parked: bool) -> None:
        """The loop parked or woke ``agent_id`` (:mod:`tasker.parking`): its candidate is keyed anew."""
        self._cands.park(agent_id, parked, self._index)

    def _on_report(self, agent: DynamicAgent) -> None:
        """A report buffer changed (newData, eq. 37)."""
        report = agent.report
        assert report is not None
        self._new_data = True
        if report.fsm_state.in_cmd:
            self._in_cmd.add(agent.id)
            if len(self._in_cmd) > 1:
                raise InvariantViolation(f"agents {sorted(self._in_cmd)} are in cmd at once")
        else:
            if agent.id in self._in_cmd:
                self.watch.left_cmd[agent.id] = self.now  # its hazards are unattended from now on
            self._in_cmd.discard(agent.id)
        if report.fsm_state is FsmState.END:
            self._ended.append(agent.id)
        elif report.params is not None:
            cand = Candidate(agent.id, agent.ctx.task_type, report.params,
                             agent.ctx.request_time, self._order.get(agent.id, 0))
            self._cands[agent.id] = cand
            if self._index is not None:
                self._index.touch(agent.id)

    def _emit_roles(self, now: float) -> None:
        self._roles_dirty = False
        roles = (self.exe_da, self.irr_da, tuple(self._idle))
        if roles != self._last_roles:
            self._last_roles = roles
            self._trace.emit(ev.RolesChanged(now, self.exe_da, self.irr_da, list(self._idle)))
