"""Ours: a priority-first variant of TaBSA's ``simple`` agent (longest task first).

Not TaBSA's agent (that is ``tabsa-simple``, :mod:`tasker.schedulers.tabsa`): TaBSA's
ignores priority and keeps a preemptive executing task with probability ``hesitance``;
this one ranks by priority first and turns hesitance into a deterministic margin.

Candidates are ranked by static priority (``CostParams.priority``, higher first; none
counts as 0), then by ``cTime``, longest first, then by request order.  An executing
task of lower priority is preempted at once; one of the same priority only when the
candidate is longer by more than the ``hesitance`` margin:

    switch  iff  cTime_dac > (1 + hesitance) * cTime_exeDA

``hesitance = 0`` switches on any strict gain; a large one almost never switches at
equal priority.  (Our reading of TaBSA's hesitance: a margin the rival must beat, made
deterministic; see ``docs/benchmark.md``.)
"""

from __future__ import annotations

from tasker.errors import ConfigError
from tasker.schedulers.base import NO_CHANGE, Candidate, Decision, Scheduler, ScheduleView


def priority(s: Scheduler, c: Candidate) -> int:
    p = s.cost_params(c, s.name).priority
    return 0 if p is None else p


class LongestFirst(Scheduler):
    name = "simple"
    preemptive = True
    indexed = True  # the lowest key runs: the harmoniser may find it without a scan
    key_cost = False  # select_key never reads the cost
    reads_cost = False  # nor does schedule(): the candidates as reported, none aged for it

    def __init__(self, hesitance: float = 0.5) -> None:
        if not isinstance(hesitance, int | float) or not 0 <= hesitance:
            raise ConfigError(f"{self.name}: hesitance must be a number >= 0, got {hesitance!r}")
        self.hesitance = float(hesitance)

    def key(self, c: Candidate) -> tuple[float, float, int]:
        return (-priority(self, c), -self.cost_params(c, self.name).c_time, c.order)

    def queue_key(self, c: Candidate) -> tuple[float, float, int]:
        """This scheduler's own ranking (not request order): the tasks it runs first are the
        ones a suspended task waits for (the ``expected_s`` of ``susp``)."""
        return self.key(c)

    def better(self, dac: float, exe: float) -> bool:
        """Does a candidate of ``cTime`` ``dac`` beat the executing one (``exe``) at equal priority?"""
        return dac > (1 + self.hesitance) * exe

    def schedule(self, view: ScheduleView) -> Decision:
        best = view.best(self.select_key)
        if best is None:
            return NO_CHANGE
        exe = view.exe
        if exe is None:
            return Decision(best.id)
        p_dac, p_exe = priority(self, best), priority(self, exe)
        t_dac, t_exe = self.cost_params(best, self.name).c_time, self.cost_params(exe, self.name).c_time
        switch = p_dac > p_exe or (p_dac == p_exe and self.better(t_dac, t_exe))
        record = {"algorithm": self.name, "dac": best.id, "exeDA": exe.id, "rule": "priority, then cTime",
                  "priority_dac": p_dac, "priority_exeDA": p_exe, "cTime_dac": t_dac, "cTime_exeDA": t_exe,
                  "hesitance": self.hesitance, "switch": switch}
        return Decision(best.id if switch else None, record)
