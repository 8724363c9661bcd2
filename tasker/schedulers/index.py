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

import heapq
from collections.abc import Container, Iterator, Mapping, Sequence
from typing import Any, overload

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

    def __init__(self, scheduler: Scheduler) -> None:
        if not scheduler.indexed:
            raise TypeError(f"scheduler {scheduler.name!r} is not indexed: it does not pick the lowest select_key")
        self.scheduler = scheduler
        self._key = scheduler.select_key
        self._heap: list[tuple[_Key, int, str]] = []
        self._live: dict[str, tuple[_Key, int]] = {}  # agent -> (key, version) of its one valid entry
        self._unkeyed: set[str] = set()  # agents whose key is not indexed: the harmoniser scans while one is idle
        self._dirty: dict[str, None] = {}  # agents that reported since the last refresh, in report order
        self._touched = False  # a report since the last decision
        self._version = 0

    def __len__(self) -> int:
        """Agents indexed (with a usable key), as of the last refresh."""
        return len(self._live)

    def touch(self, agent: str) -> None:
        """``agent`` reported new parameters: re-key it at the next :meth:`refresh`."""
        self._dirty[agent] = None
        self._touched = True

    def discard(self, agent: str) -> None:
        """``agent`` ended: its entries become stale."""
        self._live.pop(agent, None)
        self._unkeyed.discard(agent)
        self._dirty.pop(agent, None)

    def update(self, c: Candidate) -> None:
        """``c``'s agent reported ``c``: re-key it now (a push only if its key changed)."""
        self._dirty.pop(c.id, None)
        self._rekey(c, push=True)

    def ready(self, cands: Mapping[str, Candidate]) -> bool:
        """At a decision: refresh the heap and return True, or return False if a scan is cheaper now.

        A scan is cheaper when most agents reported since the last refresh and
        some since the last decision (reports about as frequent as decisions).
        """
        touched, self._touched = self._touched, False
        if touched and 2 * len(self._dirty) > len(self._live):
            return False
        self.refresh(cands)
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
