"""Shortest-job-first baseline: the shortest ``cTime`` runs next; never preempts."""

from __future__ import annotations

from tasker.schedulers.base import NO_CHANGE, Candidate, Decision, Scheduler, ScheduleView


class ShortestJobFirst(Scheduler):
    name = "sjf"
    preemptive = False
    indexed = True  # the lowest queue_key runs: the harmoniser may find it without a scan
    key_cost = False  # select_key never reads the cost
    reads_cost = False  # nor does schedule(): the candidates as reported, none aged for it

    def queue_key(self, c: Candidate) -> tuple[float, int]:
        return (self.cost_params(c, self.name).c_time, c.order)

    def schedule(self, view: ScheduleView) -> Decision:
        if view.exe is not None:
            return NO_CHANGE
        best = view.best(self.select_key)
        return NO_CHANGE if best is None else Decision(best.id)
