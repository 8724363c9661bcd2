"""Protocol metrics of one simulated day, from its trace: TaBSA's and ours (``docs/benchmark.md``).

:func:`day_metrics` reads one day's trace (never the model) and returns the TaBSA-like
metrics — tasks completed per type, completion minus deadline, falls that died,
interruptions per type and per task, oscillation, how the day ended — plus ours:
suspensions (every entry into ``genSusp``, as every run counts them) and those whose
``exeSusp`` ran stages, time spent suspending, switches, and for whole-queue
schedulers the longest queue ordered and the decisions whose search hit its budget.  On
the robot backend, :mod:`experiments.metrics.paths` adds abandonment and travel distance
from the recorded trajectory, and :func:`hazard_metrics` the task folders' hazards as every
run counts them (``safety`` of :mod:`experiments.metrics.run`).  Tasks are counted as
needs: a request made again after its task failed (``renews`` in the trace,
:func:`tasker.trace.needs`) is the same need, served when any of its tasks finishes;
``failed`` counts the needs whose tasks failed and were never served, ``renewals`` the
requests made again.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

from experiments.metrics.run import safety
from experiments.trace.timeline import Timeline, timeline
from tasker import events as ev
from tasker.trace import FAILED, number

OSCILLATION_SWITCHES = 3
OSCILLATION_WINDOW_S = 180.0
ENDINGS = ("all done", "a fall died", "oscillation", "time ran out")
TABSA_STEP_S = 5.0
"""TaBSA's step (``SystemConfig.dt``): its oscillation rule looks at the task run in each step."""
TABSA_GAPS = 2
"""TaBSA's oscillation (``my_eval_functions.py``, ``StatisticEval``): the task run in this step
ran in more than this many separate stretches (gaps between them) in the window."""


def day_metrics(events: Timeline | Iterable[ev.Event | Mapping[str, Any]], *, day_end: float | None = None,
                kinds: Mapping[str, str] | None = None, step_s: float = TABSA_STEP_S) -> dict[str, Any]:
    """The protocol metrics of one day's trace (see the module docstring and ``docs/benchmark.md``).

    ``kinds`` maps a trace's task type to the protocol's task type (the robot backend runs
    task folders under their own names); per-type metrics are keyed by the protocol's.

    ``day_end`` is when the day stops (default: the time of the last event).  A fall is
    dead when it was not finished by its request's ``death_at`` and that time falls
    within the day.  A switch to a task is a ``start`` command to its agent; the day
    oscillates (ours) when a task gets its third switch within 180 s of the first of the
    three.  An interruption is a suspension not made because the task's own stage failed.

    TaBSA's own readings (``tabsa_*``, :func:`tabsa_oscillation`, :func:`tabsa_stop`): its
    oscillation, sampled every ``step_s``; the time its day would have stopped, and why; the
    needs served by then; and each served fall's completion − death time.
    """
    tl = timeline(events)
    end_t = day_end if day_end is not None else tl.t_end
    agents = tl.agents
    kind = {a: (kinds or {}).get(x.task_type, x.task_type) for a, x in agents.items()}
    finished = {a: x.end.t for a, x in agents.items() if x.end is not None and x.cause == "finished"}
    failed = {a for a, x in agents.items() if x.cause in FAILED}  # a plan, a skill or a hook: not the scheduler's
    starts = {a: [c.t for c in x.commands if c.flag == "start"] for a, x in agents.items()}
    starts = {a: ts for a, ts in starts.items() if ts}
    interruptions = {a: sum(1 for s in x.suspensions if s.trigger != "stage_failed") for a, x in agents.items()}
    episodes = [s for x in agents.values() for s in x.suspensions]
    with_stages = sum(1 for x in agents.values() for p in x.plans if p.purpose == "genSusp" and p.stages)
    suspension_time = math.fsum(s.duration for s in episodes if s.outcome != "open")
    orders = [d for d in tl.decisions if "order" in d.data]  # whole-queue decisions (lookahead)
    longest_order = max((len(d.data["order"]) for d in orders), default=0)
    anytime = sum(1 for d in orders if d.rule == "anytime")
    first = tl.needs  # a renewed request (a failed fall asked again) is the same need
    firsts = set(tl.first_needs())
    served: dict[str, float] = {}
    for a, when in finished.items():
        served[first[a]] = min(when, served.get(first[a], math.inf))
    unserved_failed = {first[a] for a in failed} - set(served)
    args = {a: x.args for a, x in agents.items()}
    per_type: dict[str, dict[str, Any]] = {}
    dead: list[float] = []
    for t in sorted(set(kind.values())):
        mine = [a for a in kind if kind[a] == t]
        asked = [a for a in mine if a in firsts]
        done = [a for a in asked if a in served]
        gaps = [served[a] - number(args[a]["deadline"]) for a in done if args[a].get("deadline") is not None]
        n_int = sum(interruptions.get(a, 0) for a in mine)
        per_type[t] = {"requested": len(asked), "completed": len(done),
                       "failed": sum(a in unserved_failed for a in asked), "renewals": len(mine) - len(asked),
                       "completion_minus_deadline_s": _mean(gaps), "lateness_s": sum(max(0.0, g) for g in gaps),
                       "late": sum(1 for g in gaps if g > 0), "interruptions": n_int,
                       "interruptions_per_task": n_int / len(asked) if asked else None,
                       "gaps_s": gaps}
        for a in asked:
            death = args[a].get("death_at")
            if death is not None and number(death) <= end_t and served.get(a, math.inf) > number(death):
                dead.append(number(death))
    oscillation = _oscillation(starts)
    first_death = min(dead) if dead else None
    stops = [(first_death, "a fall died"), (oscillation, "oscillation")]
    stops_at = [(t, why) for t, why in stops if t is not None]
    if stops_at:
        ending = min(stops_at)[1]
    else:
        ending = "all done" if len(served) == len(firsts) else "time ran out"
    all_gaps = [served[a] - number(args[a]["deadline"]) for a in served if args[a].get("deadline") is not None]
    to_death = [served[a] - number(args[a]["death_at"]) for a in served if args[a].get("death_at") is not None]
    t_osc = tabsa_oscillation(tl, end_t, step_s)
    stop_t, stop_why = tabsa_stop(served, len(firsts), first_death, t_osc, end_t)
    for t, row in per_type.items():
        row["tabsa_completed"] = sum(1 for a in served if kind[a] == t and served[a] <= stop_t)
    return {
        "completion_minus_death_s": _mean(to_death), "tabsa_oscillation_t": t_osc, "tabsa_ending": stop_why,
        "tabsa_stop_t": stop_t, "tabsa_completed": sum(1 for when in served.values() if when <= stop_t),
        "requested": len(firsts), "completed": len(served), "failed": len(unserved_failed),
        "renewals": len(kind) - len(firsts),
        "completion_minus_deadline_s": _mean(all_gaps), "lateness_s": sum(max(0.0, g) for g in all_gaps),
        "dead_falls": len(dead), "first_death_t": first_death,
        "interruptions": sum(interruptions.values()), "suspensions": len(episodes),
        "suspensions_with_stages": with_stages,
        "suspension_time_s": suspension_time, "switches": sum(len(v) for v in starts.values()),
        "oscillation_t": oscillation, "ending": ending, "per_type": per_type,
        "longest_order": longest_order, "anytime_decisions": anytime,
    }


def hazard_metrics(events: Timeline | Iterable[ev.Event | Mapping[str, Any]]) -> dict[str, Any]:
    """Ours, robot backend: the hazards the task folders declare, as :mod:`experiments.metrics.run`
    counts them for every run (``safety``): time unattended (including what a task left on
    when it ended, to the day's end) and the part of it after the task ended, budget
    overruns, hazards left on at a switch."""
    h = safety(timeline(events))
    return {"hazard_unattended_s": h["unattended_s"], "hazard_after_end_s": h["after_end_s"],
            "hazard_overruns": h["budget_overruns"], "hazards_left_at_switch": h["violations_at_switch"]}


def _mean(values: Sequence[float]) -> float | None:
    return sum(values) / len(values) if values else None


def _oscillation(starts: Mapping[str, list[float]]) -> float | None:
    """Earliest time a task got its third switch within the window, or None."""
    k = OSCILLATION_SWITCHES - 1
    hits = [ts[i + k] for ts in starts.values() for i in range(len(ts) - k)
            if ts[i + k] - ts[i] <= OSCILLATION_WINDOW_S]
    return min(hits) if hits else None


def tabsa_oscillation(tl: Timeline, day_end: float, step_s: float = TABSA_STEP_S) -> float | None:
    """When TaBSA's oscillation rule first fires, or None.

    TaBSA (``StatisticEval.calculate_results``) keeps the task run in each of the last
    ``180 / step + 1`` steps; the day oscillates when the task run in this step has more than
    :data:`TABSA_GAPS` gaps between its runs there (a gap: other steps between two of its runs),
    so at least four separate stretches in three minutes.
    Here the task run in a step is the need (a renewal is its request's need) whose agent is
    ``exeDA`` at the step's time; steps before the day count as idle."""
    width = int(OSCILLATION_WINDOW_S / step_s) + 1
    changes = tl.exe_changes()
    k, current = 0, None
    window: list[str | None] = [None] * width
    for n in range(int(day_end / step_s) + 1):
        t = n * step_s
        while k < len(changes) and changes[k][0] <= t + 1e-9:
            current = changes[k][1]
            k += 1
        job = tl.needs.get(current, current) if current is not None else None
        window.append(job)
        window.pop(0)
        if job is None or window.count(job) <= TABSA_GAPS:
            continue
        idx = [i for i, x in enumerate(window) if x == job]
        if sum(1 for i, j in zip(idx, idx[1:], strict=False) if j - i > 1) > TABSA_GAPS:
            return t
    return None


TABSA_ENDINGS = ("all done", "a fall died", "oscillation", "time ran out")
"""How TaBSA's day ends (``test_planner.py``: its loop stops at the first; the day's end otherwise)."""


def tabsa_stop(served: Mapping[str, float], needs: int, first_death: float | None, oscillation: float | None,
               day_end: float) -> tuple[float, str]:
    """When and why TaBSA's day would stop: the earliest of every need served, a fall dead,
    TaBSA's oscillation; else the day's end ("time ran out")."""
    done = max(served.values()) if served and len(served) == needs else None
    stops = [(t, why) for t, why in ((done, "all done"), (first_death, "a fall died"), (oscillation, "oscillation"))
             if t is not None and t <= day_end]
    return min(stops, key=lambda s: (s[0], TABSA_ENDINGS.index(s[1]))) if stops else (day_end, "time ran out")
