"""Earliest-deadline-first baseline: preempts for an earlier ``deadline``.

Tasks without a deadline come after every task with one, in request order.
"""

from __future__ import annotations

import math

from tasker.schedulers.base import NO_CHANGE, Candidate, Decision, Scheduler, ScheduleView


class EarliestDeadlineFirst(Scheduler):
    name = "edf"
    preemptive = True
    indexed = True  # the lowest queue_key runs: the harmoniser may find it without a scan

    def deadline(self, c: Candidate) -> float:
        d = self.cost_params(c, self.name).deadline
        return math.inf if d is None else d

    def queue_key(self, c: Candidate) -> tuple[float, int]:
        return (self.deadline(c), c.order)

    def schedule(self, view: ScheduleView) -> Decision:
        best = view.best(self.select_key)
        if best is None:
            return NO_CHANGE
        if view.exe is None:
            return Decision(best.id)
        d_dac, d_exe = self.deadline(best), self.deadline(view.exe)
        switch = d_dac < d_exe
        record = {"algorithm": self.name, "dac": best.id, "exeDA": view.exe.id,
                  "deadline_dac": d_dac, "deadline_exeDA": d_exe, "switch": switch}
        return Decision(best.id if switch else None, record)
