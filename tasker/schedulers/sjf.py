"""Shortest-job-first baseline: the shortest ``cTime`` runs next; never preempts."""

from __future__ import annotations

from tasker.schedulers.base import NO_CHANGE, Candidate, Decision, Scheduler, ScheduleView


class ShortestJobFirst(Scheduler):
    name = "sjf"
    preemptive = False

    def queue_key(self, c: Candidate) -> tuple[float, int]:
        return (self.cost_params(c, self.name).c_time, c.order)

    def schedule(self, view: ScheduleView) -> Decision:
        if view.exe is not None or not view.candidates:
            return NO_CHANGE
        best = min(view.candidates, key=self.queue_key)
        return Decision(best.id)
