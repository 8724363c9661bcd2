"""Calibration of the harmoniser's estimates, from the trace alone (``docs/metrics.md``, ``calibration``).

Two estimates steer harmonisation and can be checked against what happened:

* **A task's cTime** — the ``predicted_s`` of the ``start`` command that first gives it
  the robot: its predicted completion time if it ran uninterrupted.  It is compared with
  the time the task then spent owning the robot (in ``cmd``: ``upTsk``, ``exeTsk``,
  ``genSusp``, ``exeSusp``) until it *finished* — its realised uninterrupted duration —
  and, apart, with the elapsed time from that start to its end (interruptions included).
  Tasks that failed, were terminated or never ended are counted, never compared: their
  realised duration is not that of the task the estimate was about.
* **An interruption's expected length** — the ``expected_s`` of a ``susp`` command.  The
  realised interruption runs from the agent entering ``wait`` after that suspension to its
  next ``start`` — a ``start`` with ``secure`` (hazard-aware waiting: it reaches its safe
  state and waits again) does not end it.  An interruption that never ends in a ``start`` (the task ended while
  waiting, or the run stopped) is *censored*: counted, never compared.

A non-finite estimate (``"inf"`` in the trace) is counted, never averaged.  Like every
collector of :mod:`experiments.metrics.run`, this one observes events and names no task type.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from tasker.meaning import CMD_STATES as CMD
from tasker.trace import number

Event = Mapping[str, Any]


def _num(value: Any) -> float:
    """A trace number as the saved trace has it (6 decimals), so a live and a saved trace agree."""
    f = number(value)
    return round(f, 6) if math.isfinite(f) else f


def _mean(values: list[float]) -> float | None:
    return math.fsum(values) / len(values) if values else None


def _summary(errors: list[float], ratios: list[float]) -> dict[str, Any]:
    """Signed error (realised − estimate), its absolute value, and realised / estimate."""
    return {"error_s": {"mean": _mean(errors), "max": max(errors) if errors else None},
            "abs_error_s": {"mean": _mean([abs(e) for e in errors])},
            "ratio": {"mean": _mean(ratios)}}


class CalibrationCollector:
    """Predicted cTime at a task's first start against its realised duration; expected against
    realised interruptions (see the module's docstring for the definitions)."""

    def __init__(self) -> None:
        self.task_type: dict[str, str] = {}
        self.state: dict[str, str] = {}
        self.first_start: dict[str, tuple[float, float | None]] = {}  # agent -> (t, predicted_s or None)
        self.in_cmd_since: dict[str, float] = {}
        self.executing: dict[str, float] = {}
        self.ended: dict[str, tuple[float, str]] = {}  # agent -> (t, cause)
        self.interruptions: list[dict[str, Any]] = []
        self._open: dict[str, dict[str, Any]] = {}  # agent -> its last interruption not yet resumed
        self.t = 0.0

    def on_event(self, e: Event) -> None:
        t, kind, agent = float(e["t"]), e["event"], str(e.get("agent", ""))
        self.t = max(self.t, t)
        if kind == "request":
            self.task_type[agent] = str(e.get("task_type", "?"))
            self.state[agent] = "initComm"
        elif kind == "transition" and agent in self.task_type:
            was, now = self.state.get(agent), str(e["to"])
            self.state[agent] = now
            if was in CMD and now not in CMD and agent in self.in_cmd_since:
                self.executing[agent] = self.executing.get(agent, 0.0) + t - self.in_cmd_since.pop(agent)
            elif was not in CMD and now in CMD and agent in self.first_start:
                self.in_cmd_since[agent] = t
            if now == "wait" and agent in self._open and self._open[agent]["wait_t"] is None:
                self._open[agent]["wait_t"] = t
        elif kind == "command" and agent in self.task_type:
            flag = e.get("flag")
            if flag == "start" and e.get("secure"):
                pass  # hazard-aware waiting: it secures its hazard and waits again — not a (re)start of the task
            elif flag == "start":
                if agent not in self.first_start:
                    predicted = _num(e["predicted_s"]) if "predicted_s" in e else None
                    self.first_start[agent] = (t, predicted)
                    if self.state.get(agent) in CMD:
                        self.in_cmd_since[agent] = t
                opened = self._open.pop(agent, None)
                if opened is not None and opened["wait_t"] is not None:
                    self.interruptions.append(dict(opened, resume_t=t, outcome="resumed"))
                elif opened is not None:  # started again without having waited: no interruption to compare
                    self.interruptions.append(dict(opened, resume_t=None, outcome="not suspended"))
            elif flag == "susp":
                expected = _num(e["expected_s"]) if "expected_s" in e else None
                self._open[agent] = {"agent": agent, "task_type": self.task_type[agent], "by": e.get("by"),
                                     "susp_t": t, "expected_s": expected, "wait_t": None}
        elif kind == "end" and agent in self.task_type:
            if agent in self.in_cmd_since:
                self.executing[agent] = self.executing.get(agent, 0.0) + t - self.in_cmd_since.pop(agent)
            self.ended[agent] = (t, str(e.get("cause", "?")))
            opened = self._open.pop(agent, None)
            if opened is not None:
                self.interruptions.append(dict(opened, resume_t=None, outcome="ended"))

    def _tasks(self) -> list[dict[str, Any]]:
        out = []
        for agent, task_type in self.task_type.items():
            start = self.first_start.get(agent)
            end = self.ended.get(agent)
            executing = self.executing.get(agent, 0.0) + (self.t - self.in_cmd_since[agent]
                                                          if agent in self.in_cmd_since else 0.0)
            row: dict[str, Any] = {"agent": agent, "task_type": task_type,
                                   "start_t": start[0] if start else None,
                                   "predicted_s": start[1] if start else None,
                                   "executing_s": executing if start else None,
                                   "elapsed_s": end[0] - start[0] if start and end else None,
                                   "cause": end[1] if end else None}
            predicted = start[1] if start else None
            if start is None:
                row["compared"] = "never started"
            elif predicted is None:
                row["compared"] = "no prediction"
            elif not math.isfinite(predicted):
                row["compared"] = "non-finite prediction"
            elif end is None or end[1] != "finished":
                row["compared"] = "did not finish"
            else:
                row["compared"] = "yes"
                row["error_s"] = executing - predicted
                row["elapsed_error_s"] = end[0] - start[0] - predicted
            out.append(row)
        return out

    def _interruptions(self) -> list[dict[str, Any]]:
        rows = self.interruptions + [dict(o, resume_t=None, outcome="open at the end of the run")
                                     for o in self._open.values()]
        out = []
        for r in sorted(rows, key=lambda r: (r["susp_t"], r["agent"])):
            row = dict(r)
            if r["outcome"] == "resumed" and r["expected_s"] is not None and math.isfinite(r["expected_s"]):
                row["realised_s"] = r["resume_t"] - r["wait_t"]
                row["error_s"] = row["realised_s"] - r["expected_s"]
            elif r["wait_t"] is not None:
                row["realised_s"] = None  # censored: at least (end or run stop) − wait_t
                row["waited_at_least_s"] = (self.ended[r["agent"]][0] if r["agent"] in self.ended else self.t) \
                    - r["wait_t"]
            out.append(row)
        return out

    def result(self) -> dict[str, Any]:
        tasks, inter = self._tasks(), self._interruptions()
        compared = [r for r in tasks if r["compared"] == "yes"]
        resumed = [r for r in inter if "error_s" in r]
        est = _summary([r["error_s"] for r in compared],
                       [r["executing_s"] / r["predicted_s"] for r in compared if r["predicted_s"] > 0])
        est["elapsed_error_s"] = {"mean": _mean([r["elapsed_error_s"] for r in compared])}
        est.update(compared=len(compared), not_compared=len(tasks) - len(compared),
                   nonfinite=sum(1 for r in tasks if r["compared"] == "non-finite prediction"),
                   underestimated=sum(1 for r in compared if r["error_s"] > 0), tasks=tasks)
        sus = _summary([r["error_s"] for r in resumed],
                       [r["realised_s"] / r["expected_s"] for r in resumed if r["expected_s"] > 0])
        sus.update(compared=len(resumed), censored=sum(1 for r in inter if r["outcome"] in
                                                       ("ended", "open at the end of the run")),
                   nonfinite=sum(1 for r in inter
                                 if r["expected_s"] is not None and not math.isfinite(r["expected_s"])),
                   unknown=sum(1 for r in inter if r["expected_s"] is None),
                   underestimated=sum(1 for r in resumed if r["error_s"] > 0), list=inter)
        return {"estimates": est, "interruptions": sus}
