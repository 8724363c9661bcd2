"""Earliest-deadline-first baseline: preempts for an earlier ``deadline``.

Tasks without a deadline come after every task with one, in request order.
"""

from __future__ import annotations

import math

from tasker.schedulers.base import Candidate, Decision, Scheduler, ScheduleView


class EarliestDeadlineFirst(Scheduler):
    name = "edf"
    preemptive = True
    indexed = True  # the lowest queue_key runs: the harmoniser may find it without a scan
    key_cost = False  # select_key never reads the cost
    reads_cost = False  # nor does schedule(): the candidates as reported, none aged for it

    def deadline(self, c: Candidate) -> float:
        d = self.cost_params(c, self.name).deadline
        return math.inf if d is None else d

    def queue_key(self, c: Candidate) -> tuple[float, int]:
        return (self.deadline(c), c.order)

    def schedule(self, view: ScheduleView) -> Decision:
        return self.preempt_when_better(view, "deadline", self.deadline)
