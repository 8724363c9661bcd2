"""TaBSA's scheduler agent (``tabsa-scheduler``): a time table of slots booked by priority.

Read from the original TaskER request table (RCPRG-ros-pkg/tasker, branch ``smit-reqTab``:
``src/TaskER/RequestTable.py``, ``src/TaskER/PriorityShdl.py``) and the agent that uses it
(RCPRG-ros-pkg/Smit-Sim ``scripts/global_planner/my_agents.py``: ``RequestTableAgentPlugin``,
``SchedulerAgent``); re-written here, not copied.

**The table** (:func:`book`): the requests, highest priority first (ties in the order they
entered the table), each ask for the interval ``[deadline − burst, deadline]``: the task
ends exactly at its deadline.  If that interval lies inside one free slot, it is booked
and the slot is split into what is left before and after it — a leftover of 5 s or less
is dropped, and when the whole slot exceeds the burst by 5 s or less the task gets the
whole slot.  Otherwise the request is rejected: it is never placed earlier.  The free
time is unbounded (TaBSA's is the calendar day from midnight, 8 h before its days begin).
``burst`` is the task's estimated duration (``cTime``) when it entered the table; the
table is rebuilt when the number of tasks changes (bursts kept) or, with the number
unchanged, the latest request changed (bursts re-read) — ``SchedulerAgent.select_task``.

**The decision**, each step: a non-preemptive executing task is kept (option
``non_preemptive``, as in :mod:`tasker.schedulers.tabsa`); then, taking the booked slots
in order of start, the first whose window ``[start − (stop − start), stop)`` holds
``now`` names the task to run (a task may start up to one slot length early).  No slot
due: the robot idles — nothing is started.  Our departure: with a task executing, a
:class:`~tasker.schedulers.base.Decision` cannot suspend it without a replacement, so it
goes on where TaBSA's robot would stand still.  TaBSA also keeps the executing task
until its deadline when its last table update changed nothing (``recently_updated``
false); but the table is updated only when the tasks changed, so every update changes
something and that branch never runs — it is left out.

A task without a deadline (TaBSA's all have one) is read as a ``now`` request of the
table (``TaskerReqest.evaluate_rules``: start at the rule's time, end a burst later),
"now" being each time the table is rebuilt: it asks for the time from then on, and a
rejected one asks again at the next rebuild (our reading).  Priority is
``CostParams.priority`` (none: 0).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from tasker.schedulers.base import NO_CHANGE, Candidate, Decision, ScheduleView
from tasker.schedulers.tabsa import TabsaAgent

MINIMAL_SLOT_S = 5.0
"""``TimeSlot.minimalSlot``: a free slot this short or shorter is not kept."""


@dataclass(frozen=True, slots=True)
class Request:
    """A task as the table holds it: its interval ends at ``deadline`` and lasts ``burst``
    (``deadline`` None: a ``now`` request, ending a burst after the table is rebuilt)."""

    id: str
    deadline: float | None
    burst: float
    priority: int

    def end(self, now: float) -> float:
        return now + self.burst if self.deadline is None else self.deadline


@dataclass(frozen=True, slots=True)
class Slot:
    """A booked slot: ``job`` runs in ``[start, stop]``."""

    start: float
    stop: float
    job: str

    def due(self, now: float) -> bool:
        """``SchedulerAgent``: a slot is taken up to one slot length before its start."""
        return self.start - (self.stop - self.start) <= now < self.stop


def book(requests: Sequence[Request], now: float = 0.0) -> tuple[list[Slot], list[str]]:
    """``PriorityScheduler.scheduleJobs`` at time ``now``: the booked slots in order of start, and
    the rejected ids."""
    free: list[tuple[float, float]] = [(-math.inf, math.inf)]  # disjoint, in order of start
    booked: list[Slot] = []
    rejected: list[str] = []
    for r in sorted(requests, key=lambda r: -r.priority):  # stable: ties keep the table's order
        end = r.end(now)
        if not (math.isfinite(end) and math.isfinite(r.burst)):  # an infeasible task: no interval
            rejected.append(r.id)
            continue
        begin = end - r.burst
        at = next((k for k, (a, b) in enumerate(free) if begin >= a and end <= b and b - a >= r.burst), None)
        if at is None:
            rejected.append(r.id)
            continue
        a, b = free.pop(at)
        if (b - a) - r.burst <= MINIMAL_SLOT_S:
            booked.append(Slot(a, b, r.id))  # the whole slot
            continue
        rest = [(x, y) for x, y in ((a, begin), (end, b)) if y - x > MINIMAL_SLOT_S]
        free[at:at] = rest
        booked.append(Slot(begin, end, r.id))
    booked.sort(key=lambda s: s.start)  # stable: equal starts keep the booking order
    return booked, rejected


class TabsaScheduler(TabsaAgent):
    """TaBSA's ``SchedulerAgent`` over the request table; see the module docstring."""

    name = "tabsa-scheduler"
    preemptive = True
    work_conserving = False

    def __init__(self, non_preemptive: Sequence[str] = (), estimates: str = "events") -> None:
        super().__init__(non_preemptive=non_preemptive, estimates=estimates)
        self._table: dict[str, Request] = {}  # in the order requests entered it
        self._slots: list[Slot] = []
        self._rejected: list[str] = []
        self._count = 0
        self._last: str | None = None
        # (generation, exeDA, job ids, how many, the latest): the jobs of the last decision
        self._jobs: tuple[int, str | None, frozenset[str], int, str] | None = None

    def schedule(self, view: ScheduleView) -> Decision:
        exe = view.exe
        exe_id = exe.id if exe is not None else None
        seen = self._jobs
        if seen is not None and view.generation is not None and seen[:2] == (view.generation, exe_id) \
                and self.estimates == "events":  # the same jobs as at the last decision: nothing to refresh
            present, count, last = seen[2], seen[3], seen[4]
            if exe is not None:
                self._here = self._exe_pose(exe)
        else:
            if not view.candidates:
                return NO_CHANGE
            jobs = sorted([*view.candidates, *([exe] if exe is not None else [])], key=lambda c: c.order)
            self.refresh(jobs, exe)
            present, count, last = frozenset(c.id for c in jobs), len(jobs), jobs[-1].id
            self._jobs = None if view.generation is None else (view.generation, exe_id, present, count, last)
        record: dict[str, Any] = {"algorithm": self.name, "exeDA": exe_id}
        if exe is not None and exe.task_type in self.non_preemptive:
            record.update(rule="non-preemptive", dac=None, switch=False)
            return Decision(None, record)
        rebuilt = False
        if count != self._count:
            rebuilt = self.update(jobs, view.now, update_old=False)
        elif last != self._last:
            rebuilt = self.update(jobs, view.now, update_old=True)
        self._count, self._last = count, last
        record["rebuilt"] = rebuilt
        if rebuilt:
            record["slots"] = [[s.job, s.start, s.stop] for s in self._slots]
            record["rejected"] = list(self._rejected)
        slot = next((s for s in self._slots if s.due(view.now)), None)
        if slot is None:
            record.update(rule="no slot due", dac=None, switch=False)
            return Decision(None, record)
        dac = slot.job if slot.job in present else None
        switch = dac is not None and (exe is None or dac != exe.id)
        record.update(rule="slot", dac=dac, slot_dac=[slot.start, slot.stop], switch=switch)
        return Decision(dac if switch else None, record)

    def update(self, jobs: Sequence[Candidate], now: float, *, update_old: bool) -> bool:
        """``RequestTableAgentPlugin.schedule``: drop the tasks gone, add the new ones, re-read the
        bursts of the others if ``update_old``; rebuild the slots if anything changed."""
        present = {c.id: c for c in jobs}
        removed = [a for a in self._table if a not in present]
        for a in removed:
            del self._table[a]
        updated = update_old and bool(self._table)
        if update_old:
            for a, r in self._table.items():
                self._table[a] = Request(a, r.deadline, self._est[a][0], r.priority)
        added = [c for c in jobs if c.id not in self._table]
        for c in added:
            p = self.cost_params(c, self.name)
            self._table[c.id] = Request(c.id, p.deadline, self._est[c.id][0], p.priority or 0)
        if added or removed or updated:
            self._slots, self._rejected = book(list(self._table.values()), now)
            return True
        return False
