"""An incremental index of the candidates, for schedulers that pick the lowest key.

Alg. 2 and most baselines choose, among the waiting agents, the one with the lowest
key (:meth:`~tasker.schedulers.base.Scheduler.select_key`: class and cost, priority,
cTime, deadline, ...), then compare it with the executing agent.  Scanning every
waiting agent at each decision makes one harmoniser tick O(n): 2 ms at 10,000
waiting agents.  A key changes only when its agent's report does, so the harmoniser
keeps the keys in a binary heap (:mod:`heapq`) and a decision reads the top.

Reports only mark their agent; the marked agents are re-keyed when a decision needs
the heap (one push each, or one ``heapify`` when most of them reported).  The heap
holds every agent with a report, idle or not; the index is told nothing of roles.
:meth:`CandidateIndex.lowest` skips the entries that are stale (an agent that
reported again, or ended) and sets aside the live ones that are not idle (the
executing agent and ``irrDA``: at most two), so a decision costs O(log n) amortised.
Stale entries are compacted away when they outnumber the live ones.

Exactness: the scan returns the first lowest candidate in ``idleDA`` order; keys are
unique (they end with the request order), so the heap's lowest is the same agent.  A
key that is not a tuple of real numbers (or whose computation raises) is not
indexed: while such an agent is idle the harmoniser scans as before
(:meth:`needs_scan`), so a scheduler's error is raised where it always was.  The
harmoniser keeps the scan callable (``TaskHarmoniser.incremental = False``) as the
reference the tests compare whole traces against.
"""

from __future__ import annotations

import bisect
import heapq
import math
from collections.abc import Container, Iterator, Mapping, Sequence
from typing import Any, Protocol, overload

from tasker.schedulers.base import Candidate, Scheduler

_Key = tuple[Any, ...]


def _usable(key: object) -> bool:
    """A key the heap can order without raising: a tuple of real numbers, none of them NaN."""
    if type(key) is not tuple:
        return isinstance(key, tuple) and _usable(tuple(key))
    for x in key:
        t = type(x)
        if t is float:
            if x != x:
                return False
        elif t is not int and not (isinstance(x, int | float) and x == x):
            return False
    return True


class CandidateIndex:
    """The agents' :meth:`Scheduler.select_key` in a heap, for one :attr:`Scheduler.indexed` scheduler.

    Reports only mark their agent (:meth:`touch`, O(1)); :meth:`refresh` re-keys the
    marked agents when a decision needs the heap — one push each, or, when most
    agents changed, one ``heapify`` of all of them — so a report costs nothing and a
    decision with no new report costs O(log n).  When most agents reported since the
    last decision (every waiting agent reports on the same tick), re-keying them all
    costs more than reading them, and reports that frequent would undo it by the
    next decision: :meth:`ready` then tells the harmoniser to scan this once, and the
    heap is rebuilt at the first decision that follows no new report.
    """

    def __init__(self, scheduler: Scheduler, agents: Mapping[str, _Reporting] | None = None) -> None:
        if not scheduler.indexed:
            raise TypeError(f"scheduler {scheduler.name!r} is not indexed: it does not pick the lowest select_key")
        self.scheduler = scheduler
        self._key = scheduler.select_key
        self._agents: Mapping[str, _Reporting] = agents if agents is not None else {}
        self._aging = _Aging(scheduler)  # parked agents whose key ages with their cost
        self._young: set[str] = set()  # parked, keyed on their last real report until their first aged one
        self._volatile: set[str] = set()  # parked, with a key of unknown make: keyed anew at every decision
        self._cands: Mapping[str, Candidate] = {}
        self._heap: list[tuple[_Key, int, str]] = []
        self._live: dict[str, tuple[_Key, int]] = {}  # agent -> (key, version) of its one valid entry
        self._unkeyed: set[str] = set()  # agents whose key is not indexed: the harmoniser scans while one is idle
        self._dirty: dict[str, None] = {}  # agents that reported since the last refresh, in report order
        self._touched = 0  # reports since the last decision
        self._version = 0

    def __len__(self) -> int:
        """Agents indexed (with a usable key), as of the last refresh."""
        return len(self._live) + len(self._aging)

    def touch(self, agent: str) -> None:
        """``agent`` reported new parameters: re-key it at the next :meth:`refresh`."""
        self._dirty[agent] = None
        self._touched += 1

    def discard(self, agent: str) -> None:
        """``agent`` ended: its entries become stale."""
        self._live.pop(agent, None)
        self._unkeyed.discard(agent)
        self._dirty.pop(agent, None)
        self._aging.discard(agent)
        self._young.discard(agent)
        self._volatile.discard(agent)

    def update(self, c: Candidate) -> None:
        """``c``'s agent reported ``c``: re-key it now (a push only if its key changed)."""
        self._dirty.pop(c.id, None)
        self._rekey(c, push=True)

    def ready(self, cands: Mapping[str, Candidate]) -> bool:
        """At a decision: refresh the heap and return True, or return False if a scan is cheaper now.

        A scan is cheaper when most agents reported since the last refresh and
        some since the last decision (reports about as frequent as decisions).
        """
        self._cands = cands
        for agent in [a for a in self._young if self._agents[a].settled()] + list(self._volatile):
            self._dirty[agent] = None  # its key ages from now on, or is of unknown make: keyed anew
        touched, self._touched = self._touched, 0
        if 2 * touched > len(self) and 2 * len(self._dirty) > len(self):
            return False
        # a key that never reads the cost is keyed on the candidates as reported, not aged (ReportedCandidates)
        self.refresh(getattr(cands, "raw", cands) if self.scheduler.key_cost is False else cands)
        return True

    def refresh(self, cands: Mapping[str, Candidate]) -> None:
        """Re-key every agent touched since the last refresh, from its latest candidate in ``cands``."""
        dirty = self._dirty
        if not dirty:
            return
        rebuild = 4 * len(dirty) > len(self._live)  # most changed: one heapify beats a push each
        changed = False
        for agent in dirty:
            c = cands.get(agent)
            if c is not None:
                changed = self._rekey(c, push=not rebuild) or changed
            else:  # no candidate any more: as if it ended
                self._live.pop(agent, None)
                self._unkeyed.discard(agent)
        dirty.clear()
        if (rebuild and changed) or len(self._heap) > 2 * len(self._live) + 64:
            self._compact()

    def needs_scan(self, idle: Container[str]) -> bool:
        """True while an idle agent's key is not indexed: the decision must scan."""
        return any(a in idle for a in self._unkeyed)

    def lowest(self, idle: Container[str]) -> str | None:
        """The idle agent with the lowest key, or None if no idle agent is indexed (call :meth:`refresh` first)."""
        found = self._lowest_static(idle)
        if not self._aging:
            return found
        best = None if found is None else (self._live[found][0], found)
        for agent in self._aging.lowest(idle, self._cands, self._agents):
            key = self._key(self._cands[agent])
            if best is None or key < best[0]:
                best = (key, agent)
        return None if best is None else best[1]

    def _lowest_static(self, idle: Container[str]) -> str | None:
        heap, live = self._heap, self._live
        aside: list[tuple[_Key, int, str]] = []
        found = None
        while heap:
            key, version, agent = heap[0]
            entry = live.get(agent)
            if entry is None or entry[1] != version:
                heapq.heappop(heap)  # stale: re-keyed or ended
            elif agent in idle:
                found = agent
                break
            else:  # live but executing or irrDA: keep it for later
                aside.append(heapq.heappop(heap))
        for item in aside:
            heapq.heappush(heap, item)
        return found

    def _rekey(self, c: Candidate, *, push: bool) -> bool:
        """Re-key ``c``'s agent; True if its heap entry changed."""
        agent = c.id
        self._young.discard(agent)
        self._volatile.discard(agent)
        self._aging.discard(agent)
        reporter = self._agents.get(agent)
        parked = reporter.parked if reporter is not None else None
        if parked is not None and not parked.form.steady and self.scheduler.key_cost is not False:
            if reporter is not None and not reporter.settled():
                self._young.add(agent)  # keyed below on its report now, until its reports age in one form
            elif self.scheduler.key_cost and self._aging.add(c, parked.form):
                self._unkeyed.discard(agent)
                return self._live.pop(agent, None) is not None
            else:
                self._volatile.add(agent)
        try:
            key = self._key(c)
        except Exception:  # the scan will call the same key and raise it in schedule(), where errors belong
            key = None
        if not _usable(key):
            self._unkeyed.add(agent)
            return self._live.pop(agent, None) is not None
        assert isinstance(key, tuple)
        self._unkeyed.discard(agent)
        old = self._live.get(agent)
        if old is not None and old[0] == key:
            return False
        self._version += 1
        self._live[agent] = (key, self._version)
        if push:
            heapq.heappush(self._heap, (key, self._version, agent))
            if len(self._heap) > 2 * len(self._live) + 64:
                self._compact()
        return True

    def _compact(self) -> None:
        self._heap = [(key, version, agent) for agent, (key, version) in self._live.items()]
        heapq.heapify(self._heap)


class _Reporting(Protocol):
    """What the index reads of an agent (:class:`tasker.agent.DynamicAgent` is one)."""

    @property
    def parked(self) -> Any: ...
    def reported_at(self) -> float | None: ...
    def settled(self) -> bool: ...
    @property
    def report(self) -> Any: ...


class _Aging:
    """Parked candidates whose key is ``(*prefix, cost, order)`` with a cost that ages
    (:class:`tasker.inputs.Aging`: ``cps * ((t - origin) + offset)``, all aged to one report tick).

    Within a group of equal prefix and ``cps`` the cost orders as ``offset - origin`` does, up
    to the rounding of the float operations: each group is a list sorted on that, and the
    lowest cost is found among the members within a tolerance of the first (far wider than
    any rounding), by their exact keys.  So the lowest is exact without keying every member
    at every report tick."""

    def __init__(self, scheduler: Scheduler) -> None:
        self.scheduler = scheduler
        self._groups: dict[tuple[Any, ...], list[tuple[float, int, str]]] = {}
        self._size: dict[tuple[Any, ...], float] = {}  # a bound on |origin| + |offset| in the group
        self._where: dict[str, tuple[tuple[Any, ...], tuple[float, int, str]]] = {}

    def __len__(self) -> int:
        return len(self._where)

    def add(self, c: Candidate, form: Any) -> bool:
        """Index ``c`` (aged by ``form``); False if its key is not ``(*prefix, cost, order)`` after all."""
        prefix = tuple(self.scheduler.key_prefix(c))
        if self.scheduler.select_key(c) != (*prefix, c.params.cost, c.order):  # type: ignore[attr-defined]
            return False
        group = (*prefix, form.cps)
        item = (form.offset - form.origin, c.order, c.id)
        bisect.insort(self._groups.setdefault(group, []), item)
        self._size[group] = max(self._size.get(group, 0.0), abs(form.origin) + abs(form.offset))
        self._where[c.id] = (group, item)
        return True

    def discard(self, agent: str) -> None:
        where = self._where.pop(agent, None)
        if where is not None:
            items = self._groups[where[0]]
            del items[bisect.bisect_left(items, where[1])]
            if not items:
                del self._groups[where[0]], self._size[where[0]]

    def lowest(self, idle: Container[str], cands: Mapping[str, Candidate],
               agents: Mapping[str, _Reporting]) -> list[str]:
        """Per group, the idle member of lowest exact key (the caller compares them)."""
        out = []
        for group, items in self._groups.items():
            window: list[str] = []
            limit = math.inf
            for approx, _, agent in items:
                if approx > limit:
                    break
                if agent in idle:
                    if not window:
                        at = agents[agent].reported_at() or 0.0
                        limit = approx + 2.0**-40 * (abs(at) + self._size[group] + 1.0)
                    window.append(agent)
            if window:
                out.append(min(window, key=lambda a: self.scheduler.select_key(cands[a])))
        return out


class ReportedCandidates(dict[str, Candidate]):
    """The harmoniser's candidates as last reported, by agent: a parked agent's (:mod:`tasker.parking`)
    is its report aged to its last report tick, made when read (:meth:`get`, ``[]``), as is the
    report the loop leaves an agent it stops parking."""

    def __init__(self, agents: Mapping[str, _Reporting], idle: IdleAgents | None = None) -> None:
        super().__init__()
        self._agents = agents
        self._idle = idle if idle is not None else IdleAgents()
        self.parked: set[str] = set()  # agents the loop does not step (tasker.parking)
        self.raw: Mapping[str, Candidate] = _Raw(self, agents)
        """The same candidates, a parked agent's from its estimate, not aged: for a scheduler that reads
        no waiting cost (its ``cost`` is the estimate's, of the tick the estimate was made)."""

    def get(self, key: str, default: Any = None) -> Any:
        c = dict.get(self, key)
        return default if c is None else self._now(key, c)

    def __getitem__(self, key: str) -> Candidate:
        return self._now(key, dict.__getitem__(self, key))

    def __setitem__(self, key: str, c: Candidate) -> None:  # a report
        if key in self._idle:
            self._idle.version += 1
        super().__setitem__(key, c)

    def park(self, agent: str, parked: bool, index: CandidateIndex | None) -> None:
        """The loop parked ``agent`` or steps it again: its candidate may have changed (keyed anew)."""
        (self.parked.add if parked else self.parked.discard)(agent)
        if agent in self._idle:
            self._idle.version += 1
        if index is not None:
            index.touch(agent)

    def of(self, idle: Mapping[str, None], *, aged: bool) -> Sequence[Candidate] | None:
        """The candidates of the ``idle`` agents (None: none has one); ``aged`` False: as :attr:`raw`,
        read only if the scheduler reads them (:class:`IdleCandidates`)."""
        if not any(dict.__contains__(self, a) for a in idle):
            return None
        return [c for a in idle if (c := self.get(a)) is not None] if aged else IdleCandidates(idle, self.raw)

    def _now(self, key: str, c: Candidate) -> Candidate:
        agent = self._agents.get(key)
        report = agent.report if agent is not None else None
        params = report.params if report is not None else None
        if params is None or params is c.params:
            return c
        c = Candidate(c.id, c.task_type, params, c.request_time, c.order)
        dict.__setitem__(self, key, c)
        return c


class _Raw(Mapping[str, Candidate]):
    """:class:`ReportedCandidates` without aging: a parked agent's candidate carries its estimate as made."""

    def __init__(self, of: dict[str, Candidate], agents: Mapping[str, _Reporting]) -> None:
        self._of, self._agents = of, agents
        self._made: dict[str, Candidate] = {}

    def __getitem__(self, key: str) -> Candidate:
        return self._now(key, dict.__getitem__(self._of, key))

    def get(self, key: str, default: Any = None) -> Any:
        c = dict.get(self._of, key)
        return default if c is None else self._now(key, c)

    def _now(self, key: str, c: Candidate) -> Candidate:
        agent = self._agents.get(key)
        if agent is None:
            return c
        parked = agent.parked
        report = agent.report if parked is None else None
        params = parked.params if parked is not None else report.params if report is not None else None
        if params is None or params is c.params:
            return c
        made = self._made.get(key)
        if made is None or made.params is not params:
            made = self._made[key] = Candidate(c.id, c.task_type, params, c.request_time, c.order)
        return made

    def __contains__(self, key: object) -> bool:
        return dict.__contains__(self._of, key)

    def __iter__(self) -> Iterator[str]:
        return dict.__iter__(self._of)

    def __len__(self) -> int:
        return dict.__len__(self._of)


class IdleAgents(dict[str, None]):
    """``idleDA`` in order, and a :attr:`version` that changes with its members or their reports
    (the harmoniser bumps it on an idle agent's report): what :attr:`ScheduleView.generation` is."""

    def __init__(self) -> None:
        super().__init__()
        self.version = 0

    def __setitem__(self, key: str, value: None) -> None:
        self.version += 1
        super().__setitem__(key, value)

    def __delitem__(self, key: str) -> None:
        self.version += 1
        super().__delitem__(key)

    def pop(self, key: str, *default: Any) -> Any:
        self.version += 1
        return super().pop(key, *default)

    def clear(self) -> None:
        self.version += 1
        super().clear()

    def sort(self, key: Any) -> None:
        """Reorder the members by ``key``."""
        items = sorted(self, key=key)
        super().clear()
        super().update(dict.fromkeys(items))
        self.version += 1


class IdleCandidates(Sequence[Candidate]):
    """``ScheduleView.candidates`` for an indexed scheduler: the scan's list, built only if read."""

    def __init__(self, idle: Mapping[str, None], cands: Mapping[str, Candidate]) -> None:
        self._idle, self._cands = idle, cands
        self._items: list[Candidate] | None = None

    def _list(self) -> list[Candidate]:
        if self._items is None:
            self._items = [c for a in self._idle if (c := self._cands.get(a)) is not None]
        return self._items

    def __len__(self) -> int:
        return len(self._list())

    @overload
    def __getitem__(self, i: int) -> Candidate: ...
    @overload
    def __getitem__(self, i: slice) -> Sequence[Candidate]: ...
    def __getitem__(self, i: int | slice) -> Candidate | Sequence[Candidate]:
        return self._list()[i]

    def __iter__(self) -> Iterator[Candidate]:
        return iter(self._list())


def reported_c_time(cands: ReportedCandidates, agent: str | None) -> float | None:
    """``agent``'s reported cTime (a parked agent's does not age: read as reported), None without one."""
    cand = cands.raw.get(agent) if agent is not None else None
    c_time = getattr(cand.params, "c_time", None) if cand is not None else None
    return float(c_time) if isinstance(c_time, int | float) else None


class QueueAhead:
    """The cTime of every waiting agent a scheduler ranks ahead of ``exeDA`` (:meth:`Scheduler.queue_key`):
    what runs before a suspended ``exeDA`` resumes.  One sum per moment, ``exeDA`` report and idle set,
    whoever the replacement; 0 when a queue key is not defined on the parameters."""

    def __init__(self, cands: ReportedCandidates, idle: IdleAgents) -> None:
        self._cands, self._idle = cands, idle
        self._at: tuple[float, Candidate | None, int] | None = None
        self._sum = 0.0

    def of(self, scheduler: Any, exe_da: str | None, now: float) -> float:
        reported = self._cands.raw.get(exe_da) if exe_da is not None else None  # its queue key is the bar
        at = self._at
        if at is not None and at[0] == now and at[1] is reported and at[2] == self._idle.version:
            return self._sum
        exe = self._cands.get(exe_da) if exe_da is not None else None
        ahead = 0.0
        if exe is not None:
            try:
                mine = scheduler.queue_key(exe)
                for agent in self._idle:
                    cand = self._cands.get(agent)
                    other = reported_c_time(self._cands, agent)
                    if cand is not None and other is not None and math.isfinite(other) \
                            and scheduler.queue_key(cand) < mine:
                        ahead += other
            except Exception:  # a queue key the parameters do not support: the replacement alone
                ahead = 0.0
        self._at, self._sum = (now, reported, self._idle.version), ahead
        return ahead
