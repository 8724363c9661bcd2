"""The one reading of a trace: typed events become a timeline of intervals and episodes.

Everything that measures a run — run, day and path metrics, calibration, plots, the HTML
pages, the Appendix B check, ``tasker explain`` — reads a :class:`Timeline`, never raw
trace dicts.  So what a state, a suspension or a hazard episode *is* is decided here, once:

* **state spans** per agent: each FSM leaf state from the moment the agent entered it to
  the moment it left (``initComm`` from the request), with the triggers in and out;
* **harmoniser role spans** per agent (``exeDA``, ``irrDA``, ``idleDA``, from the ``roles``
  events) and **person role spans** (the task folders' declared roles, ``role`` events);
* **stage runs**: each stage from ``begin`` to its closing event;
* **suspension episodes**: from entering ``genSusp`` (by ``suspend``, ``stage_failed`` or
  ``secure``) to entering ``wait`` or ``end``, with the ``exeSusp`` plan (and any made again
  when the ``fallback`` strategy planned around a stage of it), the stages run, and the check
  of its goal as it ended (the ``goal`` event);
* **interruptions**: from a ``susp`` command to the agent's next ``start`` (a ``start`` with
  ``secure`` does not end one), with the expected and realised lengths;
* **hazard episodes** with their owner (``null``: nobody's), from ``on`` to ``off``, and whether
  the robot carries the thing (``carried``).

A span still open when the trace ends is closed at the trace's last time with
``closed=False``.  Times are the trace's simulated seconds.  The names of states and
triggers come from :mod:`tasker.fsm` (a renamed state breaks here, loudly, not silently in a
metric).
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tasker import events as ev
from tasker.fsm import FsmState
from tasker.trace import read_events, typed

S = FsmState
CMD = frozenset(s.value for s in FsmState if s.in_cmd)
"""Leaves of ``cmd`` (Fig. 5): an agent in one of them owns the robot."""
SUSPENDING = frozenset({S.GEN_SUSP.value, S.EXE_SUSP.value})


@dataclass(frozen=True, slots=True)
class Span:
    """``[start, end]``; ``closed`` is False when the trace ended first (``end`` is then its last time)."""

    start: float
    end: float
    closed: bool = True

    @property
    def duration(self) -> float:
        return self.end - self.start

    def overlap(self, start: float, end: float) -> float:
        """Seconds of this span within ``[start, end]``."""
        return max(0.0, min(self.end, end) - max(self.start, start))


@dataclass(frozen=True, slots=True)
class StateSpan(Span):
    """An agent in one FSM leaf state; ``entered_by`` / ``left_by`` are the FSM events (triggers)."""

    state: str = ""
    entered_by: str = ""
    left_by: str | None = None


@dataclass(frozen=True, slots=True)
class RoleSpan(Span):
    """A harmoniser role (``exeDA``, ``irrDA``, ``idleDA``) held by one agent."""

    agent: str = ""
    role: str = ""


@dataclass(frozen=True, slots=True)
class PersonRoleSpan(Span):
    """A person's declared role (``waiting``, ``following``, ...) while an agent's task holds it."""

    agent: str = ""
    role: str = ""
    person: str = ""


@dataclass(frozen=True, slots=True)
class StageRun:
    """One stage from ``begin`` to its closing event (``status`` ``running`` if the trace ended first)."""

    agent: str
    fsm: str
    index: int
    action: str
    args: tuple[Any, ...]
    kind: str
    begin: float
    end: float | None
    status: str
    reason: str | None = None


@dataclass(frozen=True, slots=True)
class Suspension:
    """One episode of making a task safe: ``genSusp`` (and ``exeSusp``) until ``wait`` or ``end``.

    ``trigger``: ``suspend`` (a ``susp`` or ``term`` command, or the task's own ``ic_term``),
    ``stage_failed`` (a failed stage, before the task ends) or ``secure`` (hazard-aware
    waiting, from ``wait``).  ``outcome``: ``wait``, ``end`` or ``open`` (the trace ended).
    ``ready`` is when ``exeSusp`` began (its plan was ready), if it did.  ``replans`` are the plans
    made again within the episode (``fallback`` planning around a stage that could not run);
    ``goal`` is the check of the goal its ``exeSusp`` aimed for as it ended, if the task type said one."""

    agent: str
    start: float
    trigger: str
    plan: ev.PlanMade | None
    stages: tuple[StageRun, ...]
    ready: float | None
    end: float
    outcome: str
    replans: tuple[ev.PlanMade, ...] = ()
    goal: ev.GoalChecked | None = None

    @property
    def last_plan(self) -> ev.PlanMade | None:
        """The plan ``exeSusp`` last ran (the first, unless it was planned again)."""
        return self.replans[-1] if self.replans else self.plan

    @property
    def duration(self) -> float:
        return self.end - self.start


@dataclass(frozen=True, slots=True)
class Interruption:
    """A ``susp`` command and what became of it (``docs/metrics.md``, calibration)."""

    agent: str
    task_type: str
    by: str | None
    susp_t: float
    expected_s: float | None
    wait_t: float | None
    resume_t: float | None
    outcome: str  # resumed, not suspended, ended, open at the end of the run


@dataclass(frozen=True, slots=True)
class HazardEpisode:
    """A declared hazard from ``on`` to ``off`` (``end`` None: still on when the trace ended)."""

    owner: str | None
    hazard: str
    args: tuple[str, ...]
    fact: tuple[str, ...]
    budget_s: float
    severity: float
    start: float
    end: float | None
    carried: bool = False

    @property
    def label(self) -> str:
        return " ".join([self.hazard, *self.args])


@dataclass
class AgentTimeline:
    """Everything the trace says about one agent."""

    id: str
    task_type: str
    args: Mapping[str, Any]
    requester: str
    renews: str | None
    request_t: float
    states: list[StateSpan] = field(default_factory=list)
    roles: list[RoleSpan] = field(default_factory=list)
    person_roles: list[PersonRoleSpan] = field(default_factory=list)
    plans: list[ev.PlanMade] = field(default_factory=list)
    stages: list[StageRun] = field(default_factory=list)
    commands: list[ev.CommandSent] = field(default_factory=list)
    transitions: list[ev.Transition] = field(default_factory=list)
    suspensions: list[Suspension] = field(default_factory=list)
    interruptions: list[Interruption] = field(default_factory=list)
    resumptions: list[Span] = field(default_factory=list)
    """From each ``wait --start--> upTsk`` to the first stage that then began (none if none did)."""
    end: ev.TaskEnded | None = None

    @property
    def ended(self) -> bool:
        return self.end is not None

    @property
    def cause(self) -> str | None:
        return self.end.cause if self.end is not None else None

    @property
    def first_start(self) -> ev.CommandSent | None:
        """The first ``start`` that gave it the robot to run its task (not one to secure a hazard)."""
        return next((c for c in self.commands if c.flag == "start" and not c.secure), None)

    def state_at(self, t: float) -> str | None:
        """Its state at ``t`` (after every event of that instant); None before its request."""
        state = None
        for s in self.states:
            if s.start <= t:
                state = s.state
            else:
                break
        if self.end is not None and t >= self.end.t:
            return S.END.value
        return state

    def in_cmd(self) -> list[StateSpan]:
        return [s for s in self.states if s.state in CMD]

    def person_role_at(self, role: str, t: float) -> bool:
        """Whether its person held ``role`` at ``t`` (the last edge at or before ``t``)."""
        on = False
        for s in self.person_roles:
            if s.role != role:
                continue
            if s.start <= t:
                on = not (s.closed and s.end <= t)
        return on


class Timeline:
    """A run's trace read once (see the module docstring).  Build it with :meth:`of` (typed
    events or records), :meth:`read` (a ``trace.jsonl``) or :meth:`from_events`."""

    def __init__(self, events: Sequence[ev.Event]) -> None:
        self.events: list[ev.Event] = list(events)
        self.t_end = max((e.t for e in self.events), default=0.0)
        self.started: ev.RunStarted | None = None
        self.stopped: ev.RunStopped | None = None
        self.agents: dict[str, AgentTimeline] = {}
        self.decisions: list[ev.Decision] = []
        self.roles: list[ev.RolesChanged] = []
        self.world: list[ev.WorldChanged] = []
        self.modes: list[ev.ModeChanged] = []
        self.changes: list[ev.ArgsChanged] = []
        self.secures: list[ev.SecureChanged] = []
        self.commands: list[ev.CommandSent] = []
        self.hazards: list[HazardEpisode] = []
        self.needs: dict[str, str] = {}
        self.goals: list[ev.GoalChecked] = []
        self._role_times: list[float] | None = None
        self.people_order: list[str] = []
        """Agents in the order their first person-role edge came (the order of ``people`` metrics)."""
        self._build()

    # -- construction ---------------------------------------------------------------------------

    @classmethod
    def from_events(cls, events: Iterable[ev.Event]) -> Timeline:
        return cls(list(events))

    @classmethod
    def of(cls, events: Iterable[ev.Event | Mapping[str, Any]] | Timeline) -> Timeline:
        """A timeline of typed events, of records (a live trace's ``events`` or
        :func:`tasker.trace.read`'s), or the timeline itself."""
        if isinstance(events, Timeline):
            return events
        items = list(events)
        if items and not isinstance(items[0], ev.Event):
            return cls(typed(items))  # type: ignore[arg-type]
        return cls(items)  # type: ignore[arg-type]

    @classmethod
    def read(cls, path: str | Path) -> Timeline:
        """The timeline of a saved ``trace.jsonl`` (a damaged one is a ``ValueError`` naming its line)."""
        return cls(read_events(path))

    def _build(self) -> None:
        """Read every event once, through the handler of its type (:class:`_Reading`)."""
        _Reading(self).read(self.events)

    # -- queries --------------------------------------------------------------------------------

    def __iter__(self) -> Iterator[ev.Event]:
        return iter(self.events)

    def of_kind(self, kind: type[ev.Event]) -> list[Any]:
        """Every event of one type, in order."""
        return [e for e in self.events if isinstance(e, kind)]

    def exe_changes(self) -> list[tuple[float, str | None]]:
        """``(t, exeDA)`` at every change of the executing agent."""
        out: list[tuple[float, str | None]] = []
        for r in self.roles:
            if not out or out[-1][1] != r.exe_da:
                out.append((r.t, r.exe_da))
        return out

    def exe_at(self, t: float) -> str | None:
        """``exeDA`` at ``t``: the last ``roles`` event at or before it."""
        if self._role_times is None or len(self._role_times) != len(self.roles):
            self._role_times = [r.t for r in self.roles]
        k = bisect.bisect_right(self._role_times, t) - 1
        return self.roles[k].exe_da if k >= 0 else None

    def decisions_by(self, *, rule: str | None = None, dac: str | None = None, exe: str | None = None,
                     switched: bool | None = None, after: float = -math.inf) -> list[ev.Decision]:
        """Decisions at or after ``after`` matching what is given."""
        return [d for d in self.decisions if d.t >= after and (rule is None or d.rule == rule)
                and (dac is None or d.dac == dac) and (exe is None or d.exe_da == exe)
                and (switched is None or d.switch == switched)]

    def commands_to(self, agent: str, flag: str | None = None, after: float = -math.inf) -> list[ev.CommandSent]:
        a = self.agents.get(agent)
        return [c for c in (a.commands if a else []) if c.t >= after and (flag is None or c.flag == flag)]

    def first_needs(self) -> list[str]:
        """The agents that first asked for a need (a renewal is the same need: ``renews``)."""
        return [a for a in self.agents if self.needs.get(a) == a]


class _Reading:
    """One pass over a trace's events, building a :class:`Timeline`: a small handler per event type
    (:data:`_HANDLERS`), the spans and episodes still open kept here until their closing event, then
    closed at the trace's last time (``closed=False``) by :meth:`finish`."""

    def __init__(self, tl: Timeline) -> None:
        self.tl = tl
        self.state: dict[str, tuple[str, float, str]] = {}  # agent -> (state, since, entered_by)
        self.stage_open: dict[str, int] = {}  # agent -> index of its running stage in its stages
        self.susp_open: dict[str, dict[str, Any]] = {}
        self.inter_open: dict[str, dict[str, Any]] = {}
        self.roles_now: dict[str, tuple[str, float]] = {}
        self.person_open: dict[tuple[str, str], tuple[float, str]] = {}
        self.hazard_open: dict[tuple[str | None, str, tuple[str, ...]], ev.HazardChanged] = {}
        self.resuming: dict[str, float] = {}

    def read(self, events: Iterable[ev.Event]) -> None:
        for e in events:
            handler = _HANDLERS.get(type(e))
            if handler is not None:
                handler(self, e)
        self.finish()

    def _agent(self, agent: str | None) -> AgentTimeline | None:
        return self.tl.agents.get(agent) if agent is not None else None

    # -- one handler per event type ----------------------------------------------------------------

    def request(self, e: ev.TaskRequested) -> None:
        tl = self.tl
        tl.agents[e.agent] = AgentTimeline(e.agent, e.task_type, e.args, e.requester, e.renews, e.t)
        self.state[e.agent] = (S.INIT_COMM.value, e.t, "request")
        tl.needs[e.agent] = (tl.needs.get(e.renews, e.renews) if e.renews is not None else e.agent)

    def transition(self, e: ev.Transition) -> None:
        a = self._agent(e.agent)
        if a is None:
            return
        a.transitions.append(e)
        was, since, by = self.state.pop(e.agent, (e.source, e.t, ""))
        a.states.append(StateSpan(since, e.t, True, was, by, e.trigger))
        if e.target != S.END.value:
            self.state[e.agent] = (e.target, e.t, e.trigger)
        if e.source == S.WAIT.value and e.target == S.UP_TSK.value:
            self.resuming[e.agent] = e.t
        if e.target == S.GEN_SUSP.value and not (e.source == S.EXE_SUSP.value and a.id in self.susp_open):
            self.susp_open[a.id] = {"agent": a.id, "start": e.t, "trigger": e.trigger, "plan": None, "stages": [],
                                    "ready": None, "replans": [], "goal": None}
        elif e.source in SUSPENDING and e.target not in SUSPENDING and a.id in self.susp_open:
            a.suspensions.append(_suspension(self.susp_open.pop(a.id), e.t, e.target))
        if e.target == S.WAIT.value and a.id in self.inter_open and self.inter_open[a.id]["wait_t"] is None:
            self.inter_open[a.id]["wait_t"] = e.t

    def stage(self, e: ev.StageChanged) -> None:
        a = self._agent(e.agent)
        if a is None:
            return
        if e.status == "begin":
            if e.agent in self.resuming:
                a.resumptions.append(Span(self.resuming.pop(e.agent), e.t))
            a.stages.append(StageRun(e.agent, e.fsm, e.index, e.action, tuple(e.args), e.kind, e.t, None, "running"))
            self.stage_open[e.agent] = len(a.stages) - 1
            opened = self.susp_open.get(e.agent)
            if e.fsm == S.EXE_SUSP.value and opened is not None and opened["ready"] is None:
                opened["ready"] = e.t
        elif e.agent in self.stage_open:
            k = self.stage_open.pop(e.agent)
            run = a.stages[k]
            a.stages[k] = StageRun(run.agent, run.fsm, run.index, run.action, run.args, run.kind, run.begin,
                                   e.t, e.status, e.reason)
            if run.fsm == S.EXE_SUSP.value and e.agent in self.susp_open:
                self.susp_open[e.agent]["stages"].append(a.stages[k])

    def plan(self, e: ev.PlanMade) -> None:
        a = self._agent(e.agent)
        if a is None:
            return
        a.plans.append(e)
        opened = self.susp_open.get(e.agent)
        if e.purpose == S.GEN_SUSP.value and opened is not None:
            if opened["plan"] is None:
                opened["plan"] = e
            else:
                opened["replans"].append(e)

    def goal(self, e: ev.GoalChecked) -> None:
        self.tl.goals.append(e)
        if e.agent in self.susp_open:
            self.susp_open[e.agent]["goal"] = e

    def command(self, e: ev.CommandSent) -> None:
        self.tl.commands.append(e)
        a = self._agent(e.agent)
        if a is None:
            return
        a.commands.append(e)
        if e.flag == "start" and not e.secure:
            opened = self.inter_open.pop(a.id, None)
            if opened is not None:
                outcome = "resumed" if opened["wait_t"] is not None else "not suspended"
                a.interruptions.append(Interruption(**opened, resume_t=e.t if outcome == "resumed" else None,
                                                    outcome=outcome))
        elif e.flag == "susp":
            self.inter_open[a.id] = {"agent": a.id, "task_type": a.task_type, "by": e.by, "susp_t": e.t,
                                     "expected_s": e.expected_s, "wait_t": None}

    def end(self, e: ev.TaskEnded) -> None:
        a = self._agent(e.agent)
        if a is None:
            return
        a.end = e
        opened = self.inter_open.pop(e.agent, None)
        if opened is not None:
            a.interruptions.append(Interruption(**opened, resume_t=None, outcome="ended"))

    def roles(self, e: ev.RolesChanged) -> None:
        self.tl.roles.append(e)
        now = {x: "idleDA" for x in e.idle_da}
        if e.exe_da:
            now[e.exe_da] = "exeDA"
        if e.irr_da:
            now[e.irr_da] = "irrDA"
        for agent in [x for x in self.roles_now if now.get(x) != self.roles_now[x][0]]:
            role, t0 = self.roles_now.pop(agent)
            if e.t > t0 and agent in self.tl.agents:
                self.tl.agents[agent].roles.append(RoleSpan(t0, e.t, True, agent, role))
        for agent, role in now.items():
            self.roles_now.setdefault(agent, (role, e.t))

    def role(self, e: ev.RoleChanged) -> None:
        tl = self.tl
        if e.agent in tl.agents and e.agent not in tl.people_order:
            tl.people_order.append(e.agent)
        key = (e.agent, e.role)
        if e.status == "on":
            self.person_open.setdefault(key, (e.t, e.person))
        elif key in self.person_open and e.agent in tl.agents:
            t0, person = self.person_open.pop(key)
            tl.agents[e.agent].person_roles.append(PersonRoleSpan(t0, e.t, True, e.agent, e.role, person))

    def hazard(self, e: ev.HazardChanged) -> None:
        key = (e.agent, e.hazard, tuple(str(x) for x in e.args))
        if e.status == "on" and key not in self.hazard_open:
            self.hazard_open[key] = e
        elif e.status == "off" and key in self.hazard_open:
            self.tl.hazards.append(_episode(self.hazard_open.pop(key), e.t))

    def run(self, e: ev.RunStarted) -> None:
        self.tl.started = self.tl.started or e

    def stopped(self, e: ev.RunStopped) -> None:
        self.tl.stopped = e

    # -- what the trace left open ----------------------------------------------------------------

    def finish(self) -> None:
        """Close what is still open at the trace's last time (``closed=False``) and sort."""
        tl, t_end = self.tl, self.tl.t_end
        for agent, (st, since, by) in self.state.items():
            tl.agents[agent].states.append(StateSpan(since, t_end, False, st, by, None))
        for agent, k in self.stage_open.items():
            run = tl.agents[agent].stages[k]
            if run.fsm == S.EXE_SUSP.value and agent in self.susp_open:
                self.susp_open[agent]["stages"].append(run)
        for agent, opened in self.susp_open.items():
            tl.agents[agent].suspensions.append(_suspension(opened, t_end, "open"))
        for agent, opened in self.inter_open.items():
            tl.agents[agent].interruptions.append(Interruption(**opened, resume_t=None,
                                                               outcome="open at the end of the run"))
        for agent, (role, t0) in self.roles_now.items():
            if agent in tl.agents:
                tl.agents[agent].roles.append(RoleSpan(t0, t_end, False, agent, role))
        for (agent, role), (t0, person) in self.person_open.items():
            if agent in tl.agents:
                tl.agents[agent].person_roles.append(PersonRoleSpan(t0, t_end, False, agent, role, person))
        tl.hazards += [_episode(on, None) for on in self.hazard_open.values()]
        tl.hazards.sort(key=lambda h: (h.start, h.hazard, h.args, str(h.owner)))
        for a in tl.agents.values():
            a.roles.sort(key=lambda s: s.start)
            a.person_roles.sort(key=lambda s: (s.start, s.role))


def _appender(name: str) -> Callable[[_Reading, Any], None]:
    """A handler that only keeps the event in the timeline's list ``name``."""
    return lambda r, e: getattr(r.tl, name).append(e)


_HANDLERS: dict[type[ev.Event], Callable[[_Reading, Any], None]] = {
    ev.TaskRequested: _Reading.request, ev.Transition: _Reading.transition, ev.StageChanged: _Reading.stage,
    ev.PlanMade: _Reading.plan, ev.CommandSent: _Reading.command, ev.TaskEnded: _Reading.end,
    ev.RolesChanged: _Reading.roles, ev.RoleChanged: _Reading.role, ev.HazardChanged: _Reading.hazard,
    ev.Decision: _appender("decisions"), ev.WorldChanged: _appender("world"), ev.ModeChanged: _appender("modes"),
    ev.ArgsChanged: _appender("changes"), ev.SecureChanged: _appender("secures"),
    ev.RunStarted: _Reading.run, ev.RunStopped: _Reading.stopped, ev.GoalChecked: _Reading.goal,
}
"""How each event type is read; a type not listed (none today) is skipped."""


def _episode(on: ev.HazardChanged, end: float | None) -> HazardEpisode:
    return HazardEpisode(on.agent, on.hazard, tuple(str(x) for x in on.args), tuple(str(x) for x in on.fact),
                         float(on.budget_s), float(on.severity), on.t, end, bool(on.carried))


def _suspension(opened: dict[str, Any], end: float, outcome: str) -> Suspension:
    return Suspension(opened["agent"], opened["start"], opened["trigger"], opened["plan"], tuple(opened["stages"]),
                      opened["ready"], end, outcome, tuple(opened["replans"]), opened["goal"])


def timeline(source: Timeline | Iterable[ev.Event | Mapping[str, Any]] | str | Path) -> Timeline:
    """A :class:`Timeline` of whatever a reader has: a timeline, events, records or a trace file."""
    if isinstance(source, str | Path):
        return Timeline.read(source)
    return Timeline.of(source)
