"""First-in, first-out baseline: tasks run in request order, never preempted."""

from __future__ import annotations

from tasker.schedulers.base import NO_CHANGE, Decision, Scheduler, ScheduleView


class Fifo(Scheduler):
    name = "fifo"
    preemptive = False

    def schedule(self, view: ScheduleView) -> Decision:
        if view.exe is not None or not view.candidates:
            return NO_CHANGE
        return Decision(min(view.candidates, key=lambda c: c.order).id)
