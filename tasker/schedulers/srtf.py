"""Shortest-remaining-time-first baseline: preempts when a waiting task is shorter
than what remains of the executing one (its current ``cTime``)."""

from __future__ import annotations

from tasker.schedulers.base import Candidate, Decision, Scheduler, ScheduleView


class ShortestRemainingTimeFirst(Scheduler):
    name = "srtf"
    preemptive = True
    indexed = True  # the lowest queue_key runs: the harmoniser may find it without a scan
    key_cost = False  # select_key never reads the cost
    reads_cost = False  # nor does schedule(): the candidates as reported, none aged for it

    def queue_key(self, c: Candidate) -> tuple[float, int]:
        return (self.cost_params(c, self.name).c_time, c.order)

    def schedule(self, view: ScheduleView) -> Decision:
        return self.preempt_when_better(view, "cTime", lambda c: self.cost_params(c, self.name).c_time)
