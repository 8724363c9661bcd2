"""Hazard-aware waiting: which waiting task must secure its hazard now, and how long securing takes.

A ``conditional`` suspension policy may leave a hazard on for an interruption it expects
to be short; the expectation is a lower bound, so the hazard could stay unattended past
its budget.  With hazard-aware waiting the harmoniser (:mod:`tasker.harmoniser`) asks a
:class:`HazardWatch` at every ``timer(sFreq)`` whether a waiting agent's unattended
hazard is about to run out of budget; if so it lets that agent *secure* it (``start``
with ``secure``: ``wait --secure--> genSusp``, the ``strict`` suspension, ``exeSusp``,
``wait``), whatever the scheduler.  ``docs/model.md`` ("Hazard-aware waiting") is the
full account; this module holds the decision and the estimates it rests on:

* :func:`secure_estimate` — seconds a waiting agent needs to reach its ``strict`` safe
  state from the world now;
* :func:`suspend_estimate` — seconds the executing agent needs to suspend safely first.

Both call the task's own ``generate_suspension`` on a copy of its context, under the
``static`` strategy (the decision list: same goal as a planned suspension, no planner
call), and add its planning time and stage durations.  Stdlib only.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any, Protocol

from tasker.errors import AgentEnded, ConfigError, InvariantViolation, PlanningFailed, WorldError
from tasker.fsm import FsmState
from tasker.memory import WatchedMemory
from tasker.stage import Stage, StagePlan
from tasker.task import TaskContext, TaskType

S = FsmState


class WatchedAgent(Protocol):
    """What the decision and the estimates read of a dynamic agent (:class:`tasker.agent.DynamicAgent` is one).

    Defined here so that this module needs nothing of the agent's module, which calls it.
    """

    @property
    def id(self) -> str: ...
    @property
    def state(self) -> FsmState: ...
    @property
    def ended(self) -> bool: ...
    @property
    def end_reason(self) -> str | None: ...
    @property
    def ctx(self) -> TaskContext: ...
    @property
    def task(self) -> TaskType: ...
    @property
    def progress(self) -> tuple[FsmState, int]: ...
    @property
    def ready_at(self) -> float: ...
    @property
    def stage_plan(self) -> StagePlan | None: ...
    def refresh(self, now: float) -> None: ...
    def fail(self, now: float, exc: BaseException) -> None: ...

HazardSource = Callable[[], Iterable[Any]]
"""The hazards that hold now, each with ``agent``, ``name``, ``fact``, ``budget_s`` and ``since``
(:class:`tasker.meaning.ActiveHazard`; :meth:`tasker.meaning.Monitor.active` is one)."""

Episode = tuple[str, str, tuple[str, ...], float]
"""One hazard episode: (agent, hazard name, ground fact, when it went on)."""


@dataclass(frozen=True, slots=True)
class Due:
    """A waiting agent that must secure now: the hazard whose budget runs out first, and why now."""

    agent: str
    hazard: Any
    remaining_s: float
    secure_s: float
    suspend_s: float
    episodes: tuple[Episode, ...]


class HazardWatch:
    """What hazard-aware waiting remembers in one harmoniser, and its decision (:meth:`due`).

    ``margin_s`` is the slack added to the estimated time to secure; ``period_s`` the
    harmoniser's scheduling period (the next check may come one period too late).
    """

    def __init__(self, margin_s: float, period_s: float) -> None:
        if isinstance(margin_s, bool) or not isinstance(margin_s, int | float) \
                or not math.isfinite(margin_s) or margin_s < 0:
            raise ConfigError(f"secure_margin_s must be a finite number of seconds >= 0, got {margin_s!r}")
        self.margin_s = float(margin_s)
        self.period_s = float(period_s)
        self.secured: set[Episode] = set()  # episodes already secured: never twice
        self.left_cmd: dict[str, float] = {}  # when each agent last left cmd (its hazards unattended since)
        # per watched agent: (re-estimate at, exeDA and its progress then, secure_s, suspend_s)
        self._estimates: dict[str, tuple[float, tuple[str | None, Any], float, float]] = {}

    def lead_time(self, secure_s: float, suspend_s: float) -> float:
        """How early to secure: the time to secure, the executing agent's safe suspension
        first, one scheduling period and the margin."""
        return secure_s + suspend_s + self.period_s + self.margin_s

    def due(self, now: float, hazards: Iterable[Any], waiting: Mapping[str, WatchedAgent],
            exe: WatchedAgent | None, order: Mapping[str, int], *, mark: bool = True) -> Due | None:
        """The waiting agent that must secure now, if any (with ``mark``, its episodes are then
        marked secured: they will not be secured twice).

        ``waiting`` are the idle agents whose report is ``wait``; ``exe`` the executing
        agent.  A hazard's unattended stretch began when it went on or when its agent
        last left ``cmd``, whichever is later.  Estimates cost a suspension hook call
        each, so an agent's are reused until half its slack (budget left minus lead
        time) has passed or the executing agent moved on (another agent, state or
        stage).  Raises :class:`~tasker.errors.AgentEnded` if an estimate ended an agent.
        """
        watched: dict[str, tuple[float, Any]] = {}  # agent -> (budget left, that hazard), least first
        episodes: dict[str, list[Episode]] = {}
        for hz in hazards:
            agent = hz.agent
            if agent is None or agent not in waiting:  # nobody's, ended, executing, chosen or not waiting
                continue
            episode = (agent, str(hz.name), tuple(hz.fact), float(hz.since))
            if episode in self.secured:
                continue
            episodes.setdefault(agent, []).append(episode)
            if not math.isfinite(float(hz.budget_s)):
                continue
            since = max(float(hz.since), self.left_cmd.get(agent, float(hz.since)))
            remaining = float(hz.budget_s) - (now - since)
            if agent not in watched or remaining < watched[agent][0]:
                watched[agent] = (remaining, hz)
        for agent in [a for a in self._estimates if a not in watched]:
            del self._estimates[agent]
        at = (exe.id, exe.progress) if exe is not None else (None, None)
        best: tuple[float, int, str] | None = None
        for agent, (remaining, _) in watched.items():
            cached = self._estimates.get(agent)
            if cached is None or now >= cached[0] or cached[1] != at:
                secure_s = secure_estimate(waiting[agent], now)
                suspend_s = suspend_estimate(exe, now, secure_s) if exe is not None else 0.0
                slack = remaining - self.lead_time(secure_s, suspend_s)
                recheck = now + max(0.0, slack / 2) if math.isfinite(slack) else now
                cached = self._estimates[agent] = (recheck, at, secure_s, suspend_s)
            slack = remaining - self.lead_time(cached[2], cached[3])
            if slack <= 0 and (best is None or (slack, order.get(agent, 0)) < best[:2]):
                best = (slack, order.get(agent, 0), agent)
        if best is None:
            return None
        agent = best[2]
        remaining, hz = watched[agent]
        _, _, secure_s, suspend_s = self._estimates.pop(agent) if mark else self._estimates[agent]
        if mark:
            self.secured.update(episodes[agent])
        return Due(agent, hz, remaining, secure_s, suspend_s, tuple(episodes[agent]))


# -- estimates ------------------------------------------------------------------------------


def secure_estimate(agent: WatchedAgent, now: float) -> float:
    """Seconds from ``now`` until a waiting agent asked to secure is safe.

    The task's own suspension under the ``strict`` policy from the world now (the
    robot wherever it is: travel included), estimated with the ``static`` strategy:
    its planning time plus its stages' durations.  ``inf`` if it cannot be planned.
    """
    return suspension_estimate(agent, now, "strict", agent.ctx.interrupted, None)


def suspend_estimate(agent: WatchedAgent, now: float, expected_s: float | None = None,
                     reads: set[str] | None = None) -> float:
    """Seconds from ``now`` until an agent in ``cmd`` reports ``wait`` if it is sent ``susp`` now.

    In ``exeTsk``: what is left of a blocking stage and the blocking stages after it
    (eq. 25), then its suspension at the first suspendable stage (own policy, the
    interruption expected to last ``expected_s``), or nothing more if no suspendable
    stage is left (it ends instead) — or, if longer, the same from the start of its next
    blocking run, which it may enter right after this estimate.  In ``upTsk``: the
    planning time left, then the same from the first stage.  In ``genSusp``/``exeSusp``:
    what is left of the suspension.  0 outside ``cmd``.

    ``reads``, when given, gets ``"interruption_s"`` added if the task's suspension read the
    expected interruption (:class:`tasker.memory.WatchedMemory`): without it, the estimate is
    the same for every ``expected_s``.
    """
    if agent.ended:
        raise AgentEnded(agent.id, agent.end_reason or "ended")
    running, (_, at) = agent.stage_plan, agent.progress
    if agent.state in (S.GEN_SUSP, S.EXE_SUSP):
        left = max(0.0, agent.ready_at - now) if agent.state is S.GEN_SUSP else 0.0
        if running is not None:
            left += _stages_left(agent, now, running.stages, at, lambda s: True)
        return left
    if agent.state is S.UP_TSK and agent.ctx.plan is not None:
        stages, index, left = agent.ctx.plan.stages, 0, max(0.0, agent.ready_at - now)
    elif agent.state is S.EXE_TSK and running is not None:
        stages, index, left = running.stages, at, 0.0
    else:
        return 0.0
    policy = agent.ctx.strategy.policy
    estimate = left + _from(agent, now, stages, index, policy, expected_s, reads=reads)
    # the agent may enter its next blocking run just after this estimate: that run is the worst case
    # until the next estimate (re-made whenever the agent moves on), so the lead covers it already
    nxt = next((j for j in range(index + 1, len(stages)) if stages[j].blocking and not stages[j - 1].blocking), None)
    if nxt is not None:
        estimate = max(estimate, _from(agent, now, stages, nxt, policy, expected_s, whole=True, reads=reads))
    return estimate


def _from(agent: WatchedAgent, now: float, stages: Sequence[Stage], index: int, policy: str,
          expected_s: float | None, whole: bool = False, reads: set[str] | None = None) -> float:
    """Suspending from stage ``index``: its blocking run (eq. 25), then the suspension at the first
    suspendable stage (eq. 26) — none left: the task ends instead.  ``whole``: the run not yet begun."""
    left = _stages_left(agent, now, stages, index, lambda s: s.blocking, whole)
    at = next((s for s in stages[index:] if not s.blocking), None)
    if at is None:
        return left
    return left + suspension_estimate(agent, now, policy, at, expected_s, reads)


def _stages_left(agent: WatchedAgent, now: float, stages: Sequence[Stage], index: int,
                 take: Callable[[Stage], bool], whole: bool = False) -> float:
    """Durations of ``stages`` from ``index`` while ``take`` holds; of a running stage of
    ``exeTsk``, what is left of it (unless ``whole``)."""
    total = 0.0
    started = agent.ctx.stage_started
    for i in range(index, len(stages)):
        if not take(stages[i]):
            break
        d = stages[i].duration
        if i == index and not whole and started is not None and agent.state is S.EXE_TSK:
            d = max(0.0, d - (now - started))
        total += d
    return total


def suspension_estimate(agent: WatchedAgent, now: float, policy: str, interrupted: Stage | None,
                        expected_s: float | None, reads: set[str] | None = None) -> float:
    """``generate_suspension`` on a copy of the agent's context (static strategy, ``policy``,
    interrupted at ``interrupted``): the seconds the plan takes, ``inf`` if it cannot be made.

    A hook that raises otherwise ends the agent (cause ``error``) and raises
    :class:`~tasker.errors.AgentEnded`, like :meth:`~tasker.agent.DynamicAgent.fresh_params`.
    """
    if agent.ended:
        raise AgentEnded(agent.id, agent.end_reason or "ended")
    memory: WatchedMemory | None = None
    try:
        agent.refresh(now)
        memory = WatchedMemory(agent.ctx.memory)  # a copy that notes whether the suspension reads the expectation
        if expected_s is not None:
            memory.interruption_s = float(expected_s)
        ctx = replace(agent.ctx, memory=memory, done=list(agent.ctx.done), interrupted=interrupted,
                      suspended=True, strategy=replace(agent.ctx.strategy, suspension="static", policy=policy))
        plan = agent.task.generate_suspension(ctx)
        if not isinstance(plan, StagePlan):
            raise ConfigError(f"task type {agent.ctx.task_type!r} returned a {type(plan).__name__} "
                              f"from generate_suspension, expected a StagePlan")
        return float(plan.sim_time) + float(plan.expected_duration)
    except PlanningFailed:
        return math.inf
    except (InvariantViolation, WorldError):
        raise
    except Exception as exc:
        agent.fail(now, exc)
        raise AgentEnded(agent.id, agent.end_reason or "error") from exc
    finally:  # a failed plan may have read it too: inf for one expectation need not be inf for all
        if reads is not None and memory is not None and memory.interruption_read:
            reads.add("interruption_s")
