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
metric of :mod:`experiments.metrics.run`, it reads the run's timeline and names no task type.
"""

from __future__ import annotations

import math
from typing import Any

from experiments.trace.timeline import CMD, AgentTimeline, Timeline
from tasker.trace import number


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


def _task(a: AgentTimeline) -> dict[str, Any]:
    first = a.first_start
    start = (first.t, _num(first.predicted_s) if first.predicted_s is not None else None) if first else None
    end = (a.end.t, a.end.cause) if a.end is not None else None
    executing = math.fsum(s.overlap(start[0], math.inf) for s in a.states if s.state in CMD) if start else 0.0
    row: dict[str, Any] = {"agent": a.id, "task_type": a.task_type,
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
    return row


def _interruptions(tl: Timeline) -> list[dict[str, Any]]:
    rows = sorted((i for a in tl.agents.values() for i in a.interruptions), key=lambda i: (i.susp_t, i.agent))
    out = []
    for i in rows:
        expected = _num(i.expected_s) if i.expected_s is not None else None
        row: dict[str, Any] = {"agent": i.agent, "task_type": i.task_type, "by": i.by, "susp_t": i.susp_t,
                               "expected_s": expected, "wait_t": i.wait_t, "resume_t": i.resume_t,
                               "outcome": i.outcome}
        if i.outcome == "resumed" and expected is not None and math.isfinite(expected):
            assert i.resume_t is not None and i.wait_t is not None
            row["realised_s"] = i.resume_t - i.wait_t
            row["error_s"] = row["realised_s"] - expected
        elif i.wait_t is not None:
            row["realised_s"] = None  # censored: at least (end or run stop) − wait_t
            end = tl.agents[i.agent].end
            row["waited_at_least_s"] = (end.t if end is not None else tl.t_end) - i.wait_t
        out.append(row)
    return out


def calibration(tl: Timeline) -> dict[str, Any]:
    """Predicted cTime at a task's first start against its realised duration; expected against
    realised interruptions (the module docstring defines both)."""
    tasks = [_task(a) for a in tl.agents.values()]
    inter = _interruptions(tl)
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
