"""A dynamic agent's reports while its loop does not step it (*parked*, :mod:`tasker.inputs`).

A waiting agent whose task says what its estimate reads (:meth:`tasker.task.TaskType.estimate_inputs`)
offers, after each report, to be parked (:attr:`ParkedReports.offer`, a
:class:`~tasker.inputs.Parking`).  The loop (:mod:`tasker.loop`) takes the offer when it can
keep the agent's place among the agents stepped at the same tick: from then on the agent is
not stepped at ``repRate``; at each of its report ticks its report is the parked one with the
cost aged to that tick (:func:`tasker.inputs.aged`) — what it would have computed and
published, bit for bit.  ``clock()`` (the loop's) says when its last report tick was.  The loop
unparks it (:meth:`ParkedReports.unpark`) before stepping it again: when a command or new
arguments wake it, when its inputs change, or when ``until`` comes.

Mixed into :class:`tasker.agent.DynamicAgent`, which owns the attributes below.  Stdlib only.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Callable, Iterator
from typing import Any, Protocol

from tasker.errors import FSMError, InvariantViolation
from tasker.inputs import EstimateInputs, Parking, aged, aging
from tasker.messages import CostParams, Report, ScheduleParams
from tasker.task import TaskContext, TaskType


def parking(task: TaskType, ctx: TaskContext, params: ScheduleParams | None, now: float) -> Parking | None:
    """What a waiting agent's report, just made at ``now``, offers its loop: None unless the task says
    what its estimate read and its cost follows the model's."""
    if type(params) is not CostParams:
        return None
    inputs = task.estimate_inputs(ctx)
    if inputs is None or not inputs.until > now:
        return None
    form = aging(params, ctx.request_time, now)
    return Parking(inputs, form, params, now) if form is not None else None


class ParkedReports:
    """The report buffer of an agent that may be parked; see the module docstring."""

    id: str
    task: TaskType
    ctx: TaskContext
    _report: Report | None
    _params: ScheduleParams | None
    _params_at: float | None
    offer: Parking | None
    _parked: Parking | None
    _next: Parking | None  # a new estimate (its inputs changed), in effect from its own report tick
    _clock: Callable[[], float | None] | None
    _aged: tuple[float, Report] | None

    def refresh(self, now: float) -> None: ...  # the agent's (tasker.agent.DynamicAgent.refresh)

    def _in_effect(self, at: float | None) -> Parking | None:
        """The parking the report at tick ``at`` comes from (a new estimate takes over at its tick)."""
        nxt = self._next
        if nxt is not None and at is not None and at >= nxt.at:
            self._parked, self._next, self._aged = nxt, None, None
        return self._parked

    @property
    def report(self) -> Report | None:
        """The report buffer; while parked, the last report aged to the agent's last report tick."""
        report, clock = self._report, self._clock
        if self._parked is None or report is None or clock is None:
            return report
        at = clock()
        if at is None:  # parked, and no report tick since
            return report
        parked = self._in_effect(at)
        assert parked is not None
        cached = self._aged
        if cached is None or cached[0] != at:
            params = aged(parked.params, parked.form, at)
            cached = self._aged = (at, Report(report.fsm_state, params, report.ack, report.reason))
        return cached[1]

    @report.setter
    def report(self, value: Report | None) -> None:  # a test's: the agent's own reports go through _publish
        self._report, self._aged = value, None

    @property
    def parked(self) -> Parking | None:
        """What the agent's reports come from while its loop does not step it (None: it is stepped)."""
        return self._in_effect(self._clock()) if self._parked is not None and self._clock is not None else None

    @property
    def inputs(self) -> EstimateInputs | None:
        """What its latest estimate read, while parked."""
        latest = self._next or self._parked
        return latest.inputs if latest is not None else None

    def reported_at(self) -> float | None:
        """While parked, its last report tick since it was parked (None: none yet, or not parked)."""
        return self._clock() if self._parked is not None and self._clock is not None else None

    def settled(self) -> bool:
        """While parked: its reports age in one form from now on (a report tick has come since it was
        parked, and no new estimate waits for its own)."""
        at = self.reported_at()
        return at is not None and self._in_effect(at) is not None and self._next is None

    def park(self, clock: Callable[[], float | None]) -> None:
        """The loop takes :attr:`offer`: the agent is not stepped; ``clock()`` is its last report tick
        (None: none since it was parked)."""
        if self.offer is None:
            raise FSMError(f"agent {self.id}: parked without an offer")
        self._parked, self._next, self._clock, self._aged, self.offer = self.offer, None, clock, None, None

    def reestimate(self, at: float) -> Parking | None:
        """What the agent, parked, would report and offer at its report tick ``at`` (its inputs
        changed since): its step there, which would do nothing else (no command, no ``ic_term``); None
        if it would (a reason to end), or if its parameters could not be aged."""
        self.refresh(at)
        if self.task.check_terminate(self.ctx):
            return None
        return parking(self.task, self.ctx, self.task.compute_params(self.ctx), at)

    def repark(self, estimate: Parking) -> None:
        """From its report tick ``estimate.at`` on, its reports come from ``estimate`` (:meth:`reestimate`)."""
        self._next = estimate

    def unpark(self, at: float | None) -> None:
        """The loop steps the agent again; ``at`` is its last report tick while parked (None: none):
        the report buffer holds that report, as if the agent had made it."""
        parked = self._in_effect(at)
        if parked is None:
            return
        if at is not None and self._report is not None:
            params = aged(parked.params, parked.form, at)
            self._report = Report(self._report.fsm_state, params, self._report.ack, self._report.reason)
            self._params, self._params_at = params, at
        self._parked = self._next = self._clock = self._aged = None


# -- the loop's side ----------------------------------------------------------------------------------

class Agent(Protocol):
    """What the lot reads of a dynamic agent (:class:`tasker.agent.DynamicAgent` is one)."""

    @property
    def id(self) -> str: ...
    @property
    def task(self) -> TaskType: ...
    @property
    def ctx(self) -> TaskContext: ...
    @property
    def offer(self) -> Parking | None: ...
    @property
    def parked(self) -> Parking | None: ...
    @property
    def inputs(self) -> EstimateInputs | None: ...
    def refresh(self, now: float) -> None: ...
    def park(self, clock: Callable[[], float | None]) -> None: ...
    def reestimate(self, at: float) -> Parking | None: ...
    def repark(self, estimate: Parking) -> None: ...
    def unpark(self, at: float | None) -> None: ...

Key = tuple[Any, Any]
"""Where an agent's wake sorts among the wakes of its tick: ``(tick of the push, place)``."""
BEFORE: Key = (-math.inf, ())
AFTER: Key = (math.inf, ())


class _Member:
    """A parked agent: its first report tick, the key its wake there would have had, its place in
    the block (None until that tick), and when ``until`` makes it step again."""

    __slots__ = ("agent", "first", "first_key", "place", "due")

    def __init__(self, agent: Agent, first: int, first_key: Key, place: Any, due: int | None) -> None:
        self.agent, self.first, self.first_key, self.place, self.due = agent, first, first_key, place, due


class Lot:
    """Which agents a loop has parked, and where each would stand among the agents stepped at a tick.

    The loop (:mod:`tasker.loop`) steps the agents due at a tick in the order their wakes were
    pushed.  Waiting agents wake on one grid, every ``period`` ticks (``repRate``); call
    *block* the wakes pushed at a grid tick for the next one.  At grid tick ``g`` the order is:
    wakes pushed before ``g - period`` (*early*), the block (in the order its agents were
    stepped at ``g - period``), wakes pushed after it (*late*).  So the block keeps its order
    from tick to tick; an early agent that pushes for the next grid tick joins it at the
    front, a late one at the back.  The lot gives every block wake a *place* that sorts so,
    and keeps a parked agent's place while it is not stepped: its report at ``g`` comes where
    its step would have come, and if something it reads changes at ``g`` the lot knows
    whether its step at ``g`` saw the change (:meth:`changed`).  Wakes sort by
    ``(tick of the push, place)``, places being ``(0, seq)`` for wakes outside the block:
    the order the loop's sequence numbers gave before.
    """

    def __init__(self, period: int, resolution: float, seq: Iterator[int]) -> None:
        self.period, self.resolution, self._seq = period, resolution, seq
        self.members: dict[str, _Member] = {}
        self._pending: dict[int, list[_Member]] = {}  # late members without a place, by first report tick
        self._dues: list[tuple[int, int, str]] = []
        self._effects: dict[int, list[str]] = {}  # tick -> members whose new estimate is reported then
        self.tick = 0
        self.cur: Key = AFTER  # the wake being stepped at ``tick`` (BEFORE: none yet; AFTER: all done)

    # -- keys ---------------------------------------------------------------------------------------

    def key(self, tick: int, stepped: Key, target: int) -> Key:
        """The key of a wake pushed at ``tick`` for ``target`` by the agent just stepped from ``stepped``."""
        q = self.period
        if tick % q or target != tick + q:
            return (tick, (0, next(self._seq)))
        if stepped[0] == tick - q:  # in the block: keeps its place
            return (tick, stepped[1])
        if stepped[0] < tick - q:  # early: joins the block at the front
            return (tick, (-(tick + 1), next(self._seq)))
        return (tick, (tick + 1, next(self._seq)))  # late: at the back

    def _key_at(self, m: _Member, target: int) -> Key:
        return m.first_key if target == m.first else (target - self.period, m.place)

    def _stepped(self, m: _Member, tick: int) -> bool:
        """Whether ``m``'s (unseen) step at ``tick`` has come, where the loop is now."""
        return tick % self.period == 0 and tick >= m.first and self._key_at(m, tick) < self.cur

    def last(self, m: _Member) -> float | None:
        """``m``'s last report tick, as a time (None: none since it was parked)."""
        tick = self.tick
        if self.cur is not BEFORE and self._stepped(m, tick):
            return tick * self.resolution
        last = (tick - 1) // self.period * self.period
        return last * self.resolution if last >= m.first else None

    # -- parking ------------------------------------------------------------------------------------

    def park(self, agent: Agent, tick: int, key: Key, target: int) -> bool:
        """Park ``agent`` (its :attr:`ParkedReports.offer`), whose wake for ``target`` would be ``key``.
        False if it cannot be (``until`` comes before its first report tick)."""
        offer = agent.offer
        if offer is None or target % self.period:
            return False
        due = None
        if math.isfinite(offer.inputs.until):
            due = self.grid_tick_at(offer.inputs.until)
            if due <= target:
                return False
        place = key[1] if key[0] == target - self.period else None
        m = _Member(agent, target, key, place, due)
        self.members[agent.id] = m
        if place is None:
            self._pending.setdefault(target, []).append(m)
        if due is not None:
            heapq.heappush(self._dues, (due, next(self._seq), agent.id))
        agent.park(lambda: self.last(m))
        return True

    def grid_tick_at(self, t: float) -> int:
        """The first grid tick whose time (``tick * resolution``, as the loop computes it) is ``>= t``."""
        q, res = self.period, self.resolution
        tick = max(0, math.ceil(t / res / q)) * q
        while tick >= q and (tick - q) * res >= t:
            tick -= q
        while tick * res < t:
            tick += q
        return tick

    def place(self, tick: int, upto: Key) -> None:
        """Give a place to the late members first reporting at ``tick`` whose wake sorts before ``upto``."""
        pending = self._pending.get(tick)
        if not pending:
            return
        while pending and pending[0].first_key < upto:
            m = pending.pop(0)
            if self.members.get(m.agent.id) is m:
                m.place = (tick + 1, next(self._seq))
        if not pending:
            del self._pending[tick]

    def leave(self, agent_id: str) -> tuple[Agent, int, Key] | None:
        """Unpark an agent now (woken, or its inputs changed): ``(agent, tick, key)`` of the wake its
        next report tick would have had (the loop may wake it elsewhere instead)."""
        m = self.members.pop(agent_id, None)
        if m is None:
            return None
        tick = self.tick
        stepped = self.cur is not BEFORE and self._stepped(m, tick)
        m.agent.unpark(self.last(m))
        if tick < m.first:
            target = m.first
        elif tick % self.period == 0 and not stepped:
            target = tick
        else:
            target = (tick // self.period + 1) * self.period
        if m.place is None and target != m.first:  # never reached its first report tick: cannot happen
            raise InvariantViolation(f"agent {agent_id} left the lot at tick {tick} without a place")
        return m.agent, target, self._key_at(m, target)

    def repark(self, agent_id: str) -> bool:
        """A member whose inputs changed: estimate anew, at its next report tick, what it would report
        there (:meth:`ParkedReports.reestimate`) and keep it parked; False if its step there would do
        more (then :meth:`leave` it)."""
        m = self.members[agent_id]
        tick, q = self.tick, self.period
        if tick < m.first:
            at = m.first
        elif tick % q == 0 and not (self.cur is not BEFORE and self._stepped(m, tick)):
            at = tick
        else:
            at = (tick // q + 1) * q
        try:
            estimate = m.agent.reestimate(at * self.resolution)
        except Exception:  # its own step will call the hooks again, and contain what they raise
            return False
        if estimate is None:
            return False
        due = self.grid_tick_at(estimate.inputs.until) if math.isfinite(estimate.inputs.until) else None
        if due is not None and due <= at:
            return False
        m.due = due
        if due is not None:
            heapq.heappush(self._dues, (due, next(self._seq), agent_id))
        m.agent.repark(estimate)
        self._effects.setdefault(at, []).append(agent_id)
        return True

    def effects(self, tick: int) -> list[str]:
        """The members whose new estimate (:meth:`repark`) was reported at ``tick`` (call after its agents)."""
        return [a for a in self._effects.pop(tick, ()) if a in self.members]

    def due(self, tick: int) -> list[str]:
        """The members whose ``until`` comes at ``tick`` (call at the start of the tick)."""
        out = []
        while self._dues and self._dues[0][0] <= tick:
            due, _, agent_id = heapq.heappop(self._dues)
            m = self.members.get(agent_id)
            if m is not None and m.due == due:
                if due != tick:
                    raise InvariantViolation(f"agent {agent_id} was due at tick {due}, the loop is at {tick}")
                out.append(agent_id)
        return out

    def changed(self) -> list[str]:
        """The members whose inputs no longer hold (asked of each, now)."""
        out = []
        for agent_id, m in self.members.items():
            agent = m.agent
            try:
                agent.refresh(self.tick * self.resolution)
                inputs = agent.task.estimate_inputs(agent.ctx)
            except Exception:  # its own step will call the hook again, and contain what it raises
                inputs = None
            if inputs is None or inputs != agent.inputs:
                out.append(agent_id)
        return out
