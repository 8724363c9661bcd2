"""Shortest-remaining-time-first baseline: preempts when a waiting task is shorter
than what remains of the executing one (its current ``cTime``)."""

from __future__ import annotations

from tasker.schedulers.base import NO_CHANGE, Candidate, Decision, Scheduler, ScheduleView


class ShortestRemainingTimeFirst(Scheduler):
    name = "srtf"
    preemptive = True
    indexed = True  # the lowest queue_key runs: the harmoniser may find it without a scan

    def queue_key(self, c: Candidate) -> tuple[float, int]:
        return (self.cost_params(c, self.name).c_time, c.order)

    def schedule(self, view: ScheduleView) -> Decision:
        best = view.best(self.select_key)
        if best is None:
            return NO_CHANGE
        if view.exe is None:
            return Decision(best.id)
        t_dac = self.cost_params(best, self.name).c_time
        t_exe = self.cost_params(view.exe, self.name).c_time
        switch = t_dac < t_exe
        record = {"algorithm": self.name, "dac": best.id, "exeDA": view.exe.id,
                  "cTime_dac": t_dac, "cTime_exeDA": t_exe, "switch": switch}
        return Decision(best.id if switch else None, record)
