"""First-in, first-out baseline: tasks run in request order, never preempted."""

from __future__ import annotations

from tasker.schedulers.base import NO_CHANGE, Decision, Scheduler, ScheduleView


class Fifo(Scheduler):
    name = "fifo"
    preemptive = False
    indexed = True  # the lowest queue_key runs: the harmoniser may find it without a scan
    key_cost = False  # select_key never reads the cost
    reads_cost = False  # nor does schedule(): the candidates as reported, none aged for it

    def schedule(self, view: ScheduleView) -> Decision:
        if view.exe is not None:
            return NO_CHANGE
        best = view.best(self.select_key)  # queue_key: request order
        return NO_CHANGE if best is None else Decision(best.id)
