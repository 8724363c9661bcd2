"""Shortest-job-first baseline: the shortest ``cTime`` runs next; never preempts."""

from __future__ import annotations

from tasker.schedulers.base import NO_CHANGE, Decision, Scheduler, ScheduleView


class ShortestJobFirst(Scheduler):
    name = "sjf"
    preemptive = False

    def schedule(self, view: ScheduleView) -> Decision:
        if view.exe is not None or not view.candidates:
            return NO_CHANGE
        best = min(view.candidates, key=lambda c: (self.cost_params(c, self.name).c_time, c.order))
        return Decision(best.id)
