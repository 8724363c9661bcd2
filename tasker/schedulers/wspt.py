"""Weighted shortest processing time (``wspt``): the highest ``weight / cTime`` runs, preemptively.

Smith's rule (1956): on one machine, ordering jobs by ``p_j / w_j`` ascending minimises the
weighted sum of completion times, so it is the reference a scheduling reviewer expects
beside the unweighted SJF/SRTF.  Preemptive here: the executing task's index uses what is
left of it (its current ``cTime``), and a candidate with a strictly higher index preempts
it (the weighted shortest-remaining-time form).  It knows no deadlines.

``weight``: ``"priority"`` (``CostParams.priority``, none counting 0) or ``"cps"`` (the
task's cost per second of delay: then the rule orders by the model's own cost rate).  A
task with ``cTime = 0`` and a positive weight has an infinite index (it is done at once).
"""

from __future__ import annotations

import math

from tasker.schedulers.base import Candidate, Decision, Scheduler, ScheduleView
from tasker.schedulers.checks import choice

WEIGHTS = ("priority", "cps")


def weight_of(s: Scheduler, c: Candidate, weight: str) -> float:
    """The weight a task carries: its priority (none: 0) or its cost per second."""
    p = s.cost_params(c, s.name)
    return float(p.cps) if weight == "cps" else float(p.priority or 0)


def ratio(w: float, p: float) -> float:
    """``w / p`` with ``p = 0`` read as "done at once" (inf for a positive weight, 0 otherwise)."""
    if p > 0:
        return w / p
    return math.inf if w > 0 else 0.0


class WeightedShortestFirst(Scheduler):
    """Preemptive WSPT; see the module docstring."""

    name = "wspt"
    preemptive = True
    indexed = True  # the lowest select_key runs: the harmoniser may find it without a scan
    key_cost = False  # select_key never reads the cost
    reads_cost = False  # nor does schedule(): the candidates as reported, none aged for it

    def __init__(self, weight: str = "priority") -> None:
        self.weight = choice(self.name, "weight", weight, WEIGHTS)

    def index(self, c: Candidate) -> float:
        return ratio(weight_of(self, c, self.weight), self.cost_params(c, self.name).c_time)

    def queue_key(self, c: Candidate) -> tuple[float, int]:
        return (-self.index(c), c.order)

    def schedule(self, view: ScheduleView) -> Decision:
        return self.preempt_when_better(view, "wspt", self.index, higher=True)
