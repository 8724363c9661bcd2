"""The deterministic simulation loop: one simulated clock for everything.

The harmoniser, the agents, the world and the scenario's scheduled events all run on
an integer tick counter (``resolution`` seconds a tick, 1 ms by default).  The loop
is a discrete-event simulation: it jumps to the next tick at which something is due,
and within a tick it runs, in this fixed order,

1. scheduled events (requests, terminations, changes), in the order they were added;
2. the world's ``advance`` (at the world's rate);
3. the agents that are due, in the order they were woken;
4. the harmoniser's ``f^harm``, with ``timer(sFreq)`` when it is due.

No threads, no wall clock: the same inputs and seed give the same trace, byte for
byte.  A real-time runner can drive the same objects from a wall clock instead.
"""

from __future__ import annotations

import functools
import heapq
import itertools
import math
import random
from collections.abc import Callable, Mapping
from typing import Any

from tasker import events as ev
from tasker.agent import DynamicAgent, Rates
from tasker.errors import ConfigError, RunAborted, WorldError
from tasker.harmoniser import HazardSource, Mode, Request, TaskHarmoniser
from tasker.parking import AFTER, BEFORE, Key, Lot
from tasker.protocols import CoreAgent, World
from tasker.schedulers.base import Scheduler
from tasker.store import TaskStore
from tasker.task import Strategy, TaskContext
from tasker.trace import Trace

_EVENT, _WORLD, _AGENT, _TIMER = 0, 1, 2, 3


class SimulationLoop:
    """Builds the harmoniser and its agents and steps them on one simulated clock.

    ``strategies`` maps a task type to its :class:`Strategy`; others use ``strategy``.
    ``hazard_waiting`` switches hazard-aware waiting on, ``secure_over_higher`` lets it preempt a
    task of a higher priority class (off: the safety rule), and ``hazards`` says which hazards
    hold (all passed to the harmoniser; ``hazards`` may also be set later on
    ``harmoniser.hazards``, e.g. to a :meth:`tasker.meaning.Monitor.active` built on this loop).
    """

    parking: bool = True
    """Park waiting agents whose task says what its estimate reads (:mod:`tasker.parking`): they are
    not stepped while it holds.  False (on an instance before :meth:`run`, or the class) steps every
    agent whenever it asks: the reference computation, kept callable; traces are the same either way."""

    def __init__(
        self,
        store: TaskStore,
        scheduler: Scheduler,
        *,
        seed: int = 0,
        trace: Trace | None = None,
        mode: Mode | str = Mode.IT,
        s_freq: float = 1.0,
        rates: Rates | None = None,
        strategy: Strategy | None = None,
        strategies: Mapping[str, Strategy] | None = None,
        core: CoreAgent | None = None,
        world: World | None = None,
        motion: Any = None,
        resolution: float = 0.001,
        horizon: float = 24 * 3600.0,
        hazard_waiting: bool = False,
        hazards: HazardSource | None = None,
        secure_over_higher: bool = False,
    ) -> None:
        if not (isinstance(resolution, int | float) and 0 < resolution <= 1):
            raise ConfigError(f"resolution must be in (0, 1] seconds, got {resolution!r}")
        self.store = store
        self.seed = int(seed)
        self.trace = trace if trace is not None else Trace()
        self.rates = rates or Rates()
        self.strategy = strategy or Strategy()
        self.strategies = dict(strategies or {})
        self.core = core
        self.world = world
        self.motion = motion
        self.resolution = float(resolution)
        self.horizon = float(horizon)
        # hazard-aware waiting (a sweep factor): stored here and on the harmoniser, which implements it
        self.hazard_waiting = bool(hazard_waiting)
        self.harmoniser = TaskHarmoniser(scheduler, self._make_agent, trace=self.trace, mode=Mode(mode),
                                         s_freq=s_freq, hazard_waiting=self.hazard_waiting, hazards=hazards,
                                         secure_over_higher=secure_over_higher)
        self._heap: list[tuple[int, int, Any, Any, int, Any]] = []  # (tick, phase, key..., seq, item)
        self._seq = itertools.count()
        self._tick = 0
        self._pending_events = 0
        self._tokens: dict[str, int] = {}
        self._started = False
        self.aborted: str | None = None  # why the run was aborted, if it was
        self.all_agents: list[DynamicAgent] = []  # every agent created, ended ones included
        self.observers: list[Callable[[float], None]] = []  # called after each tick, e.g. tasker.meaning.Monitor
        self.lot: Lot | None = None  # the parked agents (tasker.parking); None: every agent is stepped
        self._versions: tuple[Any, Any] = (None, None)

    # -- time ---------------------------------------------------------------------------------

    @property
    def now(self) -> float:
        return self._tick * self.resolution

    def _to_tick(self, t: float) -> int:
        # the first tick at or after t (a hair of tolerance absorbs float noise in t / resolution)
        return max(self._tick, math.ceil(t / self.resolution - 1e-6))

    def _push(self, tick: int, phase: int, item: Any, key: Key = (0, ())) -> None:
        heapq.heappush(self._heap, (tick, phase, key[0], key[1], next(self._seq), item))

    # -- scenario -----------------------------------------------------------------------------

    def at(self, t: float, action: Callable[[], None]) -> None:
        """Run ``action`` at simulated time ``t`` (before agents and harmoniser in that tick)."""
        if not isinstance(t, int | float) or math.isnan(t) or t < 0:
            raise ConfigError(f"event time must be a number >= 0, got {t!r}")
        self._pending_events += 1
        self._push(self._to_tick(t), _EVENT, action)

    def next_free(self, t: float) -> float:
        """The first tick's time at or after ``t`` (and after now) at which no :meth:`at` action is due.

        An action added there with :meth:`at` runs alone in its tick, before anything added later
        for that tick: its order among the tick's actions cannot depend on when it was added.  A
        live controller injects what arrives there, so that a scenario holding the same action at
        that time replays the run byte for byte (``tasker serve``)."""
        due = {entry[0] for entry in self._heap if entry[1] == _EVENT}
        tick = max(self._to_tick(t), self._tick + 1)
        while tick in due:
            tick += 1
        return round(tick * self.resolution, 9)  # a time that reads as this tick, written without float noise

    def request(self, t: float, task_type: str, args: Mapping[str, Any] | None = None,
                requester: str = "user") -> Request:
        """Schedule a task request at ``t``.  Type and arguments are checked now, before the run."""
        checked = self.store.validate(task_type, args or {})
        req = Request(task_type, checked, requester)
        self.at(t, lambda: self._submit(req))
        return req

    def _submit(self, request: Request) -> None:
        self.harmoniser.submit(request)

    def terminate(self, t: float, agent_id: str, reason: str = "terminated by the requester") -> None:
        self.at(t, lambda: self.harmoniser.terminate(agent_id, reason))

    # -- agents ---------------------------------------------------------------------------------

    def _make_agent(self, agent_id: str, request: Request, now: float,
                    on_report: Callable[[DynamicAgent], None]) -> DynamicAgent:
        task = self.store.get(request.task_type)
        ctx = TaskContext(
            agent=agent_id,
            task_type=request.task_type,
            args=dict(request.args),
            request_time=now,
            rng=random.Random(f"{self.seed}:{agent_id}"),
            strategy=self.strategies.get(request.task_type, self.strategy),
            now=now,
            core=self.core,
            motion=self.motion,
            handover=functools.partial(self.harmoniser.handover, agent_id),
            hazards=functools.partial(self._owned_hazards, agent_id),
        )
        world = self._snapshot if self.world is not None else None
        agent = DynamicAgent(agent_id, task, ctx, trace=self.trace, rates=self.rates, core=self.core,
                             world=world, on_report=on_report, waker=self._wake_next_tick)
        self._wake(agent, self._tick + 1)
        self.all_agents.append(agent)
        return agent

    def _owned_hazards(self, agent_id: str) -> tuple[tuple[str, tuple[str, ...]], ...]:
        """The hazards ``agent_id`` owns that hold now (from the harmoniser's hazard source, e.g.
        :meth:`tasker.meaning.Monitor.active`; none without one)."""
        source = self.harmoniser.hazards
        if source is None:
            return ()
        return tuple((str(h.name), tuple(h.fact)) for h in source() if h.agent == agent_id)

    def _snapshot(self) -> Any:
        """The world's snapshot for a hook; a world that raises stops the run (:class:`WorldError`)."""
        assert self.world is not None
        try:
            return self.world.snapshot()
        except Exception as exc:
            raise WorldError(f"World.snapshot raised {type(exc).__name__}: {exc}") from exc

    def _advance_world(self, now: float) -> None:
        assert self.world is not None
        try:
            self.world.advance(now)
        except Exception as exc:
            raise WorldError(f"World.advance raised {type(exc).__name__}: {exc}") from exc

    def _abort(self, exc: BaseException) -> RunAborted:
        """End every live agent (cause ``error``), close the trace with ``run`` ``aborted``; never lose it."""
        reason = str(exc) if isinstance(exc, WorldError) else f"{type(exc).__name__}: {exc}"
        now = self.now
        self.aborted = reason
        live = [a for a in self.all_agents if not a.ended]
        for agent in live:
            if not agent.ended:
                try:
                    agent.abort(now, f"run aborted: {reason}")
                except Exception:  # ending the others matters more than this one's report
                    pass
        self.trace.emit(ev.RunStopped(now, "aborted", reason, sorted(a.id for a in live)))
        self._heap.clear()
        return RunAborted(reason)

    def _wake(self, agent: DynamicAgent, tick: int, key: Key | None = None) -> None:
        """Step ``agent`` at ``tick``; ``key`` sorts it among that tick's agents (default: after those
        already woken for it)."""
        token = self._tokens.get(agent.id, 0) + 1
        self._tokens[agent.id] = token
        self._push(tick, _AGENT, (agent, token), key if key is not None else (self._tick, (0, next(self._seq))))

    def _wake_next_tick(self, agent: DynamicAgent) -> None:
        if self.lot is not None and agent.id in self.lot.members:  # a command or new arguments: step it again
            self.lot.leave(agent.id)
            self.harmoniser.park(agent.id, False)
        self._wake(agent, self._tick + 1)

    def _lot(self) -> Lot | None:
        """The lot of parked agents (:mod:`tasker.parking`), when waiting agents' report ticks are ticks
        of the harmoniser's timer (so that a report no one steps changes no decision's moment)."""
        res = self.resolution
        period = 1.0 / (self.rates.rep_rate * res)
        q = round(period)
        timer = max(1, round(1.0 / (self.harmoniser.s_freq * res)))
        if self._tick != 0 or q < 2 or abs(period - q) > 1e-9 * q or q % timer:
            return None
        return Lot(q, res, self._seq)

    def _after_step(self, agent: DynamicAgent, tick: int, stepped: Key) -> None:
        """Wake ``agent`` when it asks (at ``stepped``'s place for a report tick), or park it."""
        lot = self.lot
        target = max(tick + 1, self._to_tick(agent.next_wake))
        if lot is None:
            self._wake(agent, target)
            return
        key = lot.key(tick, stepped, target)
        if agent.offer is not None and lot.park(agent, tick, key, target):
            self._tokens[agent.id] = self._tokens.get(agent.id, 0) + 1  # no wake of it stands
            self.harmoniser.park(agent.id, True)
        else:
            self._wake(agent, target, key)

    def _check_inputs(self, always: bool = False) -> None:
        """Step again, where their reports fall, the parked agents whose inputs changed."""
        lot = self.lot
        if lot is None or not lot.members:
            return
        versions = (getattr(self.core, "version", None), getattr(self.world, "version", None))
        if versions == self._versions and not always:
            return
        self._versions = versions
        for agent_id in lot.changed():
            if lot.repark(agent_id):
                self.harmoniser.park(agent_id, True)
            else:
                self._leave(agent_id)

    def _leave(self, agent_id: str) -> None:
        assert self.lot is not None
        left = self.lot.leave(agent_id)
        if left is not None:
            _, tick, key = left
            self._wake(self.harmoniser.agents[agent_id], tick, key)
            self.harmoniser.park(agent_id, False)

    # -- running --------------------------------------------------------------------------------

    def _start(self) -> None:
        self._started = True
        self.trace.emit(ev.RunStarted(self.now, self.seed, self.harmoniser.scheduler.name,
                                      self.harmoniser.mode.value, self.harmoniser.s_freq, self.rates.rep_rate,
                                      self.rates.task_exe_rate, self.rates.sp_up_rate,
                                      self.strategy.update, self.strategy.suspension))
        self._push(self._tick, _TIMER, None)
        if self.world is not None:
            self._push(self._tick, _WORLD, None)
        self.lot = self._lot() if self.parking else None
        self._versions = (getattr(self.core, "version", None), getattr(self.world, "version", None))

    @property
    def planner_calls(self) -> list[dict[str, Any]]:
        """Every planning hook call with its volatile info (wall time, cache hits), in order."""
        calls = [c for a in self.all_agents for c in a.planner_calls]
        return sorted(calls, key=lambda c: (c["t"], c["agent"]))

    def run(self, until: float | None = None) -> Trace:
        """Run until every request is served and every agent has ended, or until ``until``.

        Returns the trace.  Stops at ``horizon`` with a ``run`` event saying so.
        A task's exceptions end only that task (the agent contains them); anything
        else that raises (the world, a scheduled event, a broken invariant) ends
        every live agent with cause ``error``, writes ``run`` ``{"status":
        "aborted"}`` and raises :class:`~tasker.errors.RunAborted` from it.
        """
        if self.aborted is not None:
            raise RunAborted(self.aborted)
        if not self._started:
            self._start()
        try:
            return self._run(until)
        except Exception as exc:
            raise self._abort(exc) from exc

    def _run(self, until: float | None) -> Trace:
        stop_tick = self._to_tick(until) if until is not None else None
        horizon_tick = self._to_tick(self.horizon)
        harm, lot = self.harmoniser, self.lot
        tokens, heap, pop = self._tokens, self._heap, heapq.heappop
        isfinite = math.isfinite
        while self._heap:
            if self._pending_events == 0 and not harm.busy and until is None:
                break
            tick = self._heap[0][0]
            if stop_tick is not None and tick > stop_tick:
                self._tick = stop_tick
                if lot is not None:
                    lot.tick, lot.cur = stop_tick, BEFORE
                break
            if tick > horizon_tick:
                self._tick = horizon_tick
                if lot is not None:
                    lot.tick, lot.cur = horizon_tick, BEFORE
                self.trace.emit(ev.RunStopped(self.now, "horizon reached", None, sorted(harm.agents)))
                break
            self._tick = tick
            now = tick * self.resolution
            harm.now = now
            timer = False
            if lot is not None:
                lot.tick, lot.cur = tick, BEFORE
                for agent_id in lot.due(tick):  # its ic_term may answer otherwise from now on
                    self._leave(agent_id)
            while heap and heap[0][0] == tick:
                _, phase, k1, k2, _, item = pop(heap)
                if phase == _AGENT:
                    agent, token = item
                    if token != tokens.get(agent.id) or agent.ended:
                        continue
                    if lot is not None:
                        lot.place(tick, (k1, k2))
                        lot.cur = (k1, k2)
                    agent.step(now)
                    if isfinite(agent.next_wake):
                        self._after_step(agent, tick, (k1, k2))
                    self._check_inputs()
                elif phase == _EVENT:
                    self._pending_events -= 1
                    item()
                    self._check_inputs()
                elif phase == _WORLD:
                    assert self.world is not None
                    self._advance_world(now)
                    self._push(tick + max(1, round(1.0 / (self.world.rate_hz * self.resolution))), _WORLD, None)
                    self._check_inputs(always=True)
                else:
                    timer = True
                    self._push(tick + max(1, round(1.0 / (harm.s_freq * self.resolution))), _TIMER, None)
            if lot is not None:
                lot.place(tick, AFTER)
                lot.cur = AFTER
                for agent_id in lot.effects(tick):  # reported a new estimate: keyed anew
                    harm.park(agent_id, True)
            harm.step(now, timer)
            for observe in self.observers:
                observe(now)
        return self.trace
