"""Alg. 2 of the paper, generalised: priority classes, then a cost comparison.

The paper's algorithm has two classes, ``humanFell`` above ``guideHuman``:

* the best candidate of the highest class present is the lowest-cost one;
* if no agent executes, or the executing one is of a lower class, that candidate
  becomes ``irrDA`` at once (lines 9-12);
* if the executing agent is of the same class, the candidate ``dac`` is compared
  with it (lines 20-33): each is asked (``reqSP``) for ``{cc, ccps}`` when started
  from the other's ``endPose``, and

      c_switch = cost_dac + cc_exeDA + cps_exeDA * cTime_dac
      c_wait   = cost_exeDA + cc_dac + cps_dac * cTime_exeDA

  and the switch is made when ``c_switch < hysteresis * c_wait`` (the paper: 1.0;
  the original ROS code used 0.9); both agents' ``cost``, ``cps`` and ``cTime`` are
  computed afresh at the decision's moment (``ScheduleView.params_now``), and so are
  the ``reqSP`` answers, so the comparison never mixes reports of different ticks;
* a non-finite ``c_switch`` or ``c_wait`` (an infeasible task reports ``cost = inf``)
  never switches: the comparison is recorded with ``undecided: "non-finite"``; a
  candidate of a higher class whose cost is infinite does not preempt either;
* an executing agent of a higher class is never preempted.

Generalisation: ``classes`` is a list of lists of task-type names, highest first;
types not listed form one implicit class below all others.  The model names no task
type: without ``classes`` every type is in one class and Alg. 2 is its cost comparison
alone; a scenario gives the classes (``scheduler_options``), or they come from the task
folders' declared priorities (:attr:`tasker.task.TaskType.priority`, read by the scenario
loader).  The paper's Alg. 2
reads ``exeDA``'s parameters in lines 22-26 even when no agent executes; here an
empty ``exeDA`` means the candidate is started directly, as lines 9-12 do for
``humanFell`` (recorded as a decision with ``rule: "no exeDA"``).  In the paper only
the top class (``humanFell``) preempts without a cost comparison; a ``guideHuman``
candidate is compared on cost with any executing task that is not ``humanFell``
(lines 16-17).  Here any higher class preempts at once (``rule: "priority class"``):
with more than two classes, "more urgent class first" is the point of having
classes; ``docs/model.md`` states the departure.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from tasker.errors import ConfigError
from tasker.messages import SP_COMPLETION, CompletionCost, CostParams, ScheduleParams, SPRequest
from tasker.schedulers.base import NO_CHANGE, Candidate, Decision, Scheduler, ScheduleView


def _mul(a: float, b: float) -> float:
    """``a*b`` with ``0*inf = 0``: no cost growth times any duration adds nothing."""
    return 0.0 if a == 0 or b == 0 else a * b


class Alg2(Scheduler):
    """The paper's Alg. 2 with configurable priority classes and hysteresis."""

    name = "alg2"
    preemptive = True
    indexed = True  # dac is the lowest queue_key: the harmoniser may find it without a scan
    key_cost = True  # select_key is (class, cost, request order)

    def __init__(self, classes: Sequence[Sequence[str]] = (), hysteresis: float = 1.0) -> None:
        if not isinstance(hysteresis, int | float) or not 0 < hysteresis <= 1:
            raise ConfigError(f"alg2: hysteresis must be in (0, 1], got {hysteresis!r}")
        if isinstance(classes, str | bytes) or not isinstance(classes, Sequence):
            raise ConfigError(f"alg2: classes must be a list of classes (lists of task types), got {classes!r}")
        rank: dict[str, int] = {}
        for k, cls in enumerate(classes):
            if isinstance(cls, str):
                raise ConfigError(f"alg2: classes[{k}] must be a list of task types, got the string {cls!r}")
            if not isinstance(cls, Sequence) or not all(isinstance(t, str) for t in cls):
                raise ConfigError(f"alg2: classes[{k}] must be a list of task types (strings), got {cls!r}")
            for t in cls:
                if t in rank:
                    raise ConfigError(f"alg2: task type {t!r} appears in two priority classes")
                rank[t] = k
        self.classes = tuple(tuple(c) for c in classes)
        self.hysteresis = float(hysteresis)
        self._rank = rank
        self._lowest = len(self.classes)

    def outranks(self, a: Candidate, b: Candidate) -> bool:
        """``a``'s class is more urgent than ``b``'s (``classes`` is highest first)."""
        return self.rank(a.task_type) < self.rank(b.task_type)

    def rank(self, task_type: str) -> int:
        """Priority class of a task type: 0 is the highest."""
        return self._rank.get(task_type, self._lowest)

    def queue_key(self, c: Candidate) -> tuple[int, float, int]:
        """Lowest (class, reported cost, request order) first: the order Alg. 2 picks ``dac`` in."""
        return (self.rank(c.task_type), self.cost_params(c, self.name).cost, c.order)

    def select_key(self, c: Candidate) -> tuple[int, float, int]:
        """:meth:`queue_key`, inlined: the harmoniser's index computes it for every report."""
        p = c.params
        if not isinstance(p, CostParams):
            p = self.cost_params(c, self.name)  # raises the error the scan would
        return (self._rank.get(c.task_type, self._lowest), p.cost, c.order)

    def schedule(self, view: ScheduleView) -> Decision:
        best: Candidate | None = view.lowest  # found by the harmoniser's index, or
        best_key: tuple[int, float, int] | None = None if best is None else self.queue_key(best)
        if best is None:
            for c in view.candidates:  # one pass: lowest (class, cost, request order), lines 3-4
                key = (self._rank.get(c.task_type, self._lowest), self.cost_params(c, self.name).cost, c.order)
                if best_key is None or key < best_key:
                    best, best_key = c, key
        if best is None or best_key is None:
            return NO_CHANGE
        exe = view.exe
        if exe is None:  # departure 4 (docs/model.md): start the best candidate, and say so
            return Decision(best.id, {"algorithm": self.name, "dac": best.id, "exeDA": None, "rule": "no exeDA",
                                      "cost_dac": best_key[1], "switch": True})
        r_exe = self.rank(exe.task_type)
        if r_exe < best_key[0]:  # an executing agent of a higher class is never preempted
            return NO_CHANGE
        if r_exe > best_key[0]:  # lines 9-12, generalised: a higher class preempts without a cost comparison
            record: dict[str, Any] = {"algorithm": self.name, "dac": best.id, "exeDA": exe.id,
                                      "rule": "priority class", "cost_dac": best_key[1]}
            if not math.isfinite(best_key[1]):  # an infeasible candidate never forces a switch
                record.update(switch=False, undecided="non-finite cost_dac")
                return Decision(None, record)
            record["switch"] = True
            return Decision(best.id, record)
        return self._compare(view, best, exe)

    def _compare(self, view: ScheduleView, dac: Candidate, exe: Candidate) -> Decision:
        """Lines 20-33 with parameters of one moment: both agents compute them at ``view.now``."""
        p_dac = self._cost(view.params_now(dac), dac)
        p_exe = self._cost(view.params_now(exe), exe)
        a_dac = self._completion(view, dac, p_exe.end_pose, exe.id)  # dac once exeDA is complete
        a_exe = self._completion(view, exe, p_dac.end_pose, dac.id)  # exeDA resumed once dac is complete
        c_switch = p_dac.cost + a_exe.cc + _mul(p_exe.cps, p_dac.c_time)
        c_wait = p_exe.cost + a_dac.cc + _mul(p_dac.cps, p_exe.c_time)
        record: dict[str, Any] = {
            "algorithm": self.name, "dac": dac.id, "exeDA": exe.id, "rule": "cost",
            "cost_dac": p_dac.cost, "cost_exeDA": p_exe.cost,
            "cps_dac": p_dac.cps, "cps_exeDA": p_exe.cps,
            "cTime_dac": p_dac.c_time, "cTime_exeDA": p_exe.c_time,
            "cc_dac": a_dac.cc, "cc_exeDA": a_exe.cc,
            "ccps_dac": a_dac.ccps, "ccps_exeDA": a_exe.ccps,
            "c_switch": c_switch, "c_wait": c_wait, "hysteresis": self.hysteresis,
        }
        if math.isfinite(c_switch) and math.isfinite(c_wait):
            switch = bool(c_switch < self.hysteresis * c_wait)
        else:  # inf (or NaN) on either side: the comparison says nothing, so the executing task stays
            switch = False
            record["undecided"] = "non-finite"
        record["switch"] = switch
        return Decision(dac.id if switch else None, record)

    def _cost(self, params: ScheduleParams, c: Candidate) -> CostParams:
        if not isinstance(params, CostParams):
            raise ConfigError(f"scheduler {self.name!r} needs CostParams from task type {c.task_type!r} "
                              f"(agent {c.id}), got {type(params).__name__}")
        return params

    @staticmethod
    def _completion(view: ScheduleView, c: Candidate, pose: Any, after: str) -> CompletionCost:
        answer = view.req_sp(c.id, SPRequest(SP_COMPLETION, {"pose": pose, "after": after}))
        if not isinstance(answer, CompletionCost):
            raise ConfigError(
                f"alg2: task type {c.task_type!r} answered reqSP {SP_COMPLETION!r} with "
                f"{type(answer).__name__}, expected CompletionCost"
            )
        return answer
