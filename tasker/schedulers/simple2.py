"""Ours: a priority-first variant of TaBSA's ``simple2`` agent (shortest task first).

Not TaBSA's agent (that is ``tabsa-simple2``, :mod:`tasker.schedulers.tabsa`): TaBSA's
ignores priority and keeps a preemptive executing task with probability ``hesitance``.

The mirror of :mod:`tasker.schedulers.simple`: priority first (higher first), then
``cTime`` shortest first; at equal priority the executing task is preempted when

    (1 + hesitance) * cTime_dac < cTime_exeDA
"""

from __future__ import annotations

from tasker.schedulers.base import Candidate
from tasker.schedulers.simple import LongestFirst, priority


class ShortestFirst(LongestFirst):
    name = "simple2"

    def __init__(self, hesitance: float = 0.0) -> None:
        super().__init__(hesitance)

    def key(self, c: Candidate) -> tuple[float, float, int]:
        return (-priority(self, c), self.cost_params(c, self.name).c_time, c.order)

    def better(self, dac: float, exe: float) -> bool:
        return (1 + self.hesitance) * dac < exe
