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
    reads_cost = False  # cTime, deadline and priority or cps

    def __init__(self, k: float = 2.0, weight: str = "priority") -> None:
        self.k = number(self.name, "k", k, low=0.0, high=math.inf, low_open=True, high_open=True)
        self.weight = choice(self.name, "weight", weight, WEIGHTS)
        # per ScheduleView.generation: the candidates' time-free parts and the sum of their finite cTimes
        self._parts: tuple[int, list[tuple[Candidate, float, float, float | None]], float, int] | None = None

    def _time_free(self, view: ScheduleView) -> tuple[list[tuple[Candidate, float, float, float | None]], float, int]:
        """Each candidate with ``(w/p, log(w/p), deadline - cTime)`` and the sum and count of the finite
        cTimes (summed in the candidates' order, as :meth:`schedule` sums them), kept per generation."""
        parts = self._parts
        if parts is not None and view.generation is not None and parts[0] == view.generation:
            return parts[1], parts[2], parts[3]
        rows, times = [], []
        for c in view.candidates:
            p = self.cost_params(c, self.name)
            base = ratio(weight_of(self, c, self.weight), p.c_time)
            log = -math.inf if base == 0.0 else math.inf if math.isinf(base) else math.log(base)
            rows.append((c, base, log, None if p.deadline is None else p.deadline - p.c_time))
            if math.isfinite(p.c_time):
                times.append(p.c_time)
        total = sum(times)
        if view.generation is not None:
            self._parts = (view.generation, rows, total, len(times))
        return rows, total, len(times)

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
        rows, total, count = self._time_free(view)
        if not rows:
            return NO_CHANGE
        exe = view.exe
        t_exe = self.cost_params(exe, self.name).c_time if exe is not None else math.inf
        if math.isfinite(t_exe):  # the sum of every finite cTime, the executing task's last (sum() order)
            total, count = total + t_exe, count + 1
        p_mean = total / count if count else 0.0
        keys: dict[str, tuple[float, float]] = {}
        now, kp = view.now, self.k * p_mean
        best, best_key = rows[0][0], None
        for c, base, log, d_minus_p in rows:  # log_index, with its time-free parts kept
            if base == 0.0 or math.isinf(base):
                key = (log, base)
            else:
                slack = math.inf if d_minus_p is None else max(0.0, d_minus_p - now)
                discount = 0.0 if slack == 0.0 else slack / kp if p_mean > 0 else math.inf
                key = (log - discount, base)
            keys[c.id] = key
            order = (-key[0], -key[1], c.order)
            if best_key is None or order < best_key:
                best, best_key = c, order
        if exe is not None:
            keys[exe.id] = self.log_index(exe, now, p_mean)
        record: dict[str, Any] = {"algorithm": self.name, "dac": best.id, "exeDA": exe.id if exe else None,
                                  "k": self.k, "p_mean": p_mean, "log_atc_dac": keys[best.id][0],
                                  "wspt_dac": keys[best.id][1]}
        if exe is None:
            record.update(rule="no exeDA", switch=True)
            return Decision(best.id, record)
        switch = keys[best.id][0] > keys[exe.id][0]
        record.update(rule="atc", log_atc_exeDA=keys[exe.id][0], wspt_exeDA=keys[exe.id][1], switch=switch)
        return Decision(best.id if switch else None, record)
