"""Ours: a priority-first variant of TaBSA's ``distance`` agent (distance against duration).

Not TaBSA's agent (that is ``tabsa-distance``, :mod:`tasker.schedulers.tabsa`): TaBSA's
ignores priority and *maximises* ``distance − ratio × duration``, so with ``ratio = 0`` it
goes to the farthest task first; this one minimises ``distance / cTime`` within priority.

A candidate's score is the distance from where the robot will be (the executing
task's ``endPose``, or the ``endPose`` of the last task it ran) to the candidate's
``endPose``, divided by its ``cTime``: the share of going there in what the task
costs.  Lowest score first, within static priority (higher first).  An executing task
is preempted only by a higher priority: from its own end pose its score is 0.
Tasks without an ``endPose`` score 0.
"""

from __future__ import annotations

import math
from typing import Any

from tasker.schedulers.base import NO_CHANGE, Candidate, Decision, Scheduler, ScheduleView
from tasker.schedulers.simple import priority


class DistanceOverDuration(Scheduler):
    name = "distance"
    preemptive = True
    reads_cost = False  # priority, cTime and endPose

    def __init__(self) -> None:
        self._here: tuple[float, ...] | None = None  # end pose of the last task seen executing
        self._best: tuple[int, Any, Candidate] | None = None  # (generation, here, best): the last scan's answer

    def score(self, c: Candidate, here: tuple[float, ...] | None) -> float:
        p = self.cost_params(c, self.name)
        if here is None or p.end_pose is None:
            return 0.0
        d = math.hypot(p.end_pose[0] - here[0], p.end_pose[1] - here[1])
        return d / p.c_time if p.c_time > 0 else (math.inf if d > 0 else 0.0)

    def schedule(self, view: ScheduleView) -> Decision:
        exe = view.exe
        if exe is not None:
            self._here = self.cost_params(exe, self.name).end_pose
        here = self._here
        seen = self._best
        if seen is not None and view.generation is not None and seen[:2] == (view.generation, here):
            best = seen[2]  # the same candidates (ScheduleView.generation) from the same place
        else:
            if not view.candidates:
                return NO_CHANGE
            best = min(view.candidates, key=lambda c: (-priority(self, c), self.score(c, here), c.order))
            self._best = None if view.generation is None else (view.generation, here, best)
        if exe is None:
            return Decision(best.id)
        p_dac, p_exe = priority(self, best), priority(self, exe)
        switch = p_dac > p_exe
        record = {"algorithm": self.name, "dac": best.id, "exeDA": exe.id, "rule": "priority, then distance/cTime",
                  "priority_dac": p_dac, "priority_exeDA": p_exe, "score_dac": self.score(best, here),
                  "switch": switch}
        return Decision(best.id if switch else None, record)
