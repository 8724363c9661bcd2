"""Fixed-priority baseline: the highest priority runs, and preempts a lower one.

A task's priority is ``CostParams.priority`` when its task type reports one, else
``priorities[task_type]`` from configuration, else ``default``.  Ties go to the
earlier request.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from tasker.errors import ConfigError
from tasker.schedulers.base import Candidate, Decision, Scheduler, ScheduleView


class FixedPriority(Scheduler):
    name = "priority"
    preemptive = True
    indexed = True  # the lowest queue_key runs: the harmoniser may find it without a scan
    key_cost = False  # select_key never reads the cost
    reads_cost = False  # nor does schedule(): the candidates as reported, none aged for it

    def __init__(self, priorities: Mapping[str, int] | None = None, default: int = 0) -> None:
        if priorities is not None and not isinstance(priorities, Mapping):
            raise ConfigError(f"priority: priorities must be a table of task type = priority, got {priorities!r}")
        for key, value in [*(priorities or {}).items(), ("default", default)]:
            if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
                what = "default" if key == "default" else f"priorities[{key!r}]"
                raise ConfigError(f"priority: {what} must be a number, got {value!r}")
        self.priorities = dict(priorities or {})
        self.default = default

    def priority(self, c: Candidate) -> int:
        p = getattr(c.params, "priority", None)
        return p if p is not None else self.priorities.get(c.task_type, self.default)

    def outranks(self, a: Candidate, b: Candidate) -> bool:
        return self.priority(a) > self.priority(b)

    def queue_key(self, c: Candidate) -> tuple[int, int]:
        return (-self.priority(c), c.order)

    def schedule(self, view: ScheduleView) -> Decision:
        return self.preempt_when_better(view, "priority", self.priority, higher=True)
