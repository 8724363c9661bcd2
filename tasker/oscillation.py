"""The harmoniser's oscillation guard: no task becomes ``exeDA`` too often within a window."""

from __future__ import annotations

import math
from dataclasses import dataclass

from tasker.errors import ConfigError


@dataclass(frozen=True, slots=True)
class OscillationGuard:
    """Hysteresis in the harmoniser: no task becomes ``exeDA`` more than ``count`` times in ``window_s``.

    After the oscillation definition of the TaBSA benchmark: with no new request in
    between, no task becomes ``exeDA`` a third time within 180 s.  The harmoniser
    holds back a preemption (the scheduler chose a candidate while an agent
    executes) when either the candidate or the executing agent has already become
    ``exeDA`` ``count`` times within the last ``window_s`` seconds: the candidate
    would be one too many, and the executing agent would have to become ``exeDA``
    again to finish.  A new request clears the history (it may legitimately
    preempt again, as in Appendix B).  Starting a task when no agent executes is
    never held, so nothing starves.  Independent of the scheduler.
    """

    window_s: float = 180.0
    count: int = 2

    def __post_init__(self) -> None:
        if not isinstance(self.window_s, int | float) or not self.window_s >= 0 or math.isinf(self.window_s):
            raise ConfigError(f"OscillationGuard.window_s must be a number of seconds >= 0, got {self.window_s!r}")
        if isinstance(self.count, bool) or not isinstance(self.count, int) or self.count < 1:
            raise ConfigError(f"OscillationGuard.count must be an integer >= 1, got {self.count!r}")
