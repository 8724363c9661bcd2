"""Apparent tardiness cost (``atc``): Vepsalainen and Morton's dispatching rule, preemptive.

Vepsalainen and Morton (1987, "Priority rules for job shops with weighted tardiness
costs", Management Science 33(8)) rank jobs on one machine at time ``t`` by

    I_j(t) = (w_j / p_j) * exp( -max(0, d_j - p_j - t) / (k * p_mean) )

``w_j / p_j`` is WSPT's index; the exponential discounts it by the job's slack
``d_j - p_j - t`` measured in units of ``k`` mean processing times ``p_mean``: a job
with no slack left keeps its full WSPT index, a job whose deadline is far ahead counts
little.  ``k`` is the look-ahead parameter (large ``k``: WSPT; small ``k``: the job
closest to being late first).  Here ``p_j`` is the task's ``cTime``, ``d_j`` its
``deadline``, ``p_mean`` the mean ``cTime`` of the executing task and the candidates
(finite ones), ``w_j`` its priority or cost rate (option ``weight``, as ``wspt``).

Preemptive: at each decision the executing task's index (with what is left of it) is
compared with the best candidate's, which preempts when strictly higher.  Indices are
compared as logarithms, so a long slack does not underflow every index to 0.  A task
without a deadline has infinite slack: index 0, after every task with one; equal
indices are ordered by WSPT, then by request order.
"""

from __future__ import annotations

import math
from typing import Any

from tasker.schedulers.base import NO_CHANGE, Candidate, Decision, Scheduler, ScheduleView
from tasker.schedulers.checks import choice, number
from tasker.schedulers.wspt import WEIGHTS, ratio, weight_of


class ApparentTardinessCost(Scheduler):
    """Preemptive ATC with look-ahead parameter ``k``; see the module docstring."""

    name = "atc"
    preemptive = True

    def __init__(self, k: float = 2.0, weight: str = "priority") -> None:
        self.k = number(self.name, "k", k, low=0.0, high=math.inf, low_open=True, high_open=True)
        self.weight = choice(self.name, "weight", weight, WEIGHTS)

    def log_index(self, c: Candidate, now: float, p_mean: float) -> tuple[float, float]:
        """``(log I_j(now), w_j / p_j)``."""
        p = self.cost_params(c, self.name)
        w = weight_of(self, c, self.weight)
        base = ratio(w, p.c_time)
        if base == 0.0:
            return -math.inf, base
        if math.isinf(base):
            return math.inf, base
        slack = math.inf if p.deadline is None else max(0.0, p.deadline - p.c_time - now)
        if slack == 0.0:
            discount = 0.0
        elif p_mean > 0:
            discount = slack / (self.k * p_mean)
        else:
            discount = math.inf
        return math.log(base) - discount, base

    def queue_key(self, c: Candidate) -> tuple[float, int]:
        """The time-free part of the ranking (WSPT), for the harmoniser's wait estimate."""
        return (-ratio(weight_of(self, c, self.weight), self.cost_params(c, self.name).c_time), c.order)

    def schedule(self, view: ScheduleView) -> Decision:
        if not view.candidates:
            return NO_CHANGE
        exe = view.exe
        jobs = [*view.candidates, *([exe] if exe is not None else [])]
        times = [t for c in jobs if math.isfinite(t := self.cost_params(c, self.name).c_time)]
        p_mean = sum(times) / len(times) if times else 0.0
        keys = {c.id: self.log_index(c, view.now, p_mean) for c in jobs}
        best = min(view.candidates, key=lambda c: (-keys[c.id][0], -keys[c.id][1], c.order))
        record: dict[str, Any] = {"algorithm": self.name, "dac": best.id, "exeDA": exe.id if exe else None,
                                  "k": self.k, "p_mean": p_mean, "log_atc_dac": keys[best.id][0],
                                  "wspt_dac": keys[best.id][1]}
        if exe is None:
            record.update(rule="no exeDA", switch=True)
            return Decision(best.id, record)
        switch = keys[best.id][0] > keys[exe.id][0]
        record.update(rule="atc", log_atc_exeDA=keys[exe.id][0], wspt_exeDA=keys[exe.id][1], switch=switch)
        return Decision(best.id if switch else None, record)
