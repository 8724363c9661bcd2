"""Metrics of a run, computed from its timeline alone (``docs/metrics.md`` defines each one).

Every section is a function of the run's :class:`~experiments.trace.timeline.Timeline`
(STYLE principle 10: metrics observe, they never touch the model), and :func:`compute`
composes them into the JSON-ready dict written as ``metrics.json``.  What is hazardous and
who waits is declared by each task folder and reaches the metrics only through the
timeline's hazard episodes and person roles (the trace's ``hazard`` and ``role`` events):
this module names no task, action or predicate, so a user's new domain is measured
exactly like a bundled one.  The definitions of a state, a suspension or a hazard episode
are the timeline's; the meaning, unit and direction of every number is in
:mod:`experiments.metrics.registry`.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from experiments.metrics.calibration import calibration
from experiments.trace.timeline import CMD, AgentTimeline, HazardEpisode, Timeline, timeline
from tasker import events as ev
from tasker.fsm import FsmState
from tasker.trace import FAILED, INAPPLICABLE

S = FsmState
TARGETED = "perturbation (targeted"
"""How the note of a targeted perturbation's world event begins (:mod:`experiments.run.targeting`)."""
Source = Timeline | Iterable[ev.Event | Mapping[str, Any]]


def _stats(values: list[float]) -> dict[str, float | None]:
    return {"mean": sum(values) / len(values) if values else None, "max": max(values) if values else None}


# -- run ------------------------------------------------------------------------------------------


def run_info(tl: Timeline) -> dict[str, Any]:
    """The run's header and how it stopped."""
    info: dict[str, Any] = {"events": len(tl.events), "duration_s": tl.t_end, "horizon_reached": False,
                            "active_at_end": [],
                            # world events a targeted perturbation made (experiments.run.targeting)
                            "targeted_changes": sum(1 for w in tl.world if w.note.startswith(TARGETED))}
    if tl.started is not None:
        info.update(seed=tl.started.seed, scheduler=tl.started.scheduler, mode=tl.started.mode)
    if tl.stopped is not None:
        info.update(horizon_reached=True, active_at_end=list(tl.stopped.active))
    return info


# -- tasks --------------------------------------------------------------------------------------


def _task(a: AgentTimeline) -> dict[str, Any]:
    wait = [s for s in a.states if s.state == S.WAIT.value]
    plans_by = Counter(f"{p.purpose}/{p.strategy}" for p in a.plans)
    closed = Counter(r.status for r in a.stages if r.status != "running")
    end = a.end
    return {
        "task_type": a.task_type, "request_t": a.request_t,
        "end_t": end.t if end else None, "duration_s": end.t - a.request_t if end else None,
        "reason": end.reason if end else None, "cause": end.cause if end else None,
        "suspensions": len(a.suspensions),
        "suspended_s": math.fsum(s.duration for s in wait),
        "suspension_s": [s.duration for s in a.suspensions if s.outcome == S.WAIT.value],
        "resumption_s": [r.duration for r in a.resumptions],
        "plans": len(a.plans), "plans_by": dict(sorted(plans_by.items())),
        "static_fallbacks": sum(1 for p in a.plans if _static_fallback(p.strategy, p.note)),
        "stages": {status: closed.get(status, 0) for status in ("done", "stopped", "failed")},
        "stage_failures": [f"{r.action}: {r.reason or '?'}" for r in a.stages if r.status == "failed"],
    }


def tasks(tl: Timeline) -> tuple[dict[str, Any], dict[str, Any]]:
    """Per task (``tasks``) and over tasks (``totals``)."""
    per = {a.id: _task(a) for a in tl.agents.values()}
    ended = [v for v in per.values() if v["end_t"] is not None]
    causes = Counter(v["cause"] for v in ended)
    plans_by: Counter[str] = Counter()
    for v in per.values():
        plans_by.update(v["plans_by"])
    first = min((v["request_t"] for v in per.values()), default=0.0)
    last = tl.t_end if len(ended) < len(per) else max((v["end_t"] for v in ended), default=first)
    suspensions = [d for v in per.values() for d in v["suspension_s"]]
    resumptions = [d for v in per.values() for d in v["resumption_s"]]
    totals = {
        "requested": len(per), "ended": len(ended), "unfinished": len(per) - len(ended),
        # a task that ended itself (ic_term: "Peter is fine") or was cancelled did not fail
        "finished": causes.get("finished", 0), "failed": sum(causes.get(c, 0) for c in FAILED),
        "ended_by_itself": causes.get("self", 0), "terminated": causes.get("term", 0),
        "by_cause": dict(sorted(causes.items())),
        "failure_reasons": [f"{a}: {v['reason']}" for a, v in per.items()
                            if v["end_t"] is not None and v["cause"] in FAILED],
        "duration_s": _stats([v["duration_s"] for v in ended]), "makespan_s": last - first if per else 0.0,
        "suspensions": sum(v["suspensions"] for v in per.values()),
        "suspended_s": math.fsum(v["suspended_s"] for v in per.values()),
        "suspension_s": _stats(suspensions), "resumption_s": _stats(resumptions),
        "plans": sum(plans_by.values()), "plans_by": dict(sorted(plans_by.items())),
        "static_fallbacks": sum(v["static_fallbacks"] for v in per.values()),
    }
    return per, totals


# -- switching and decisions -------------------------------------------------------------------------


def switching(tl: Timeline) -> dict[str, Any]:
    """Commands of the harmoniser; a switch is a ``susp`` followed by a ``start`` of another agent."""
    counts: Counter[str] = Counter()
    switches: list[dict[str, Any]] = []
    suspended: tuple[float, str] | None = None
    for c in tl.commands:
        counts[c.flag] += 1
        if c.flag == "susp":
            suspended = (c.t, c.agent)
        elif c.flag == "start" and suspended is not None:
            t0, old = suspended
            suspended = None
            if c.agent != old:
                switches.append({"t_susp": t0, "t_start": c.t, "from": old, "to": c.agent, "latency_s": c.t - t0})
    order = [agent for _, agent in tl.exe_changes() if agent is not None]
    return {"switches": len(switches), "switch_list": switches,
            # the agents that held the robot, in turn: two runs with the same order had the same schedule
            "schedule": " ".join(a for k, a in enumerate(order) if k == 0 or a != order[k - 1]),
            "switch_latency_s": _stats([s["latency_s"] for s in switches]),
            "commands": dict(sorted(counts.items())), "mode_changes": len(tl.modes),
            "changes": sum(1 for c in tl.changes if c.ignored is None)}


HYSTERESES = (0.85, 0.9, 0.95, 1.0)
"""The hysteresis values a run's cost decisions are re-read under (how many would have gone the other way)."""
MARGIN_BINS = 0.1
"""Width of the bins of the cost decisions' margins ``1 − c_switch / c_wait`` (clipped to [−1, 1])."""


def decisions(tl: Timeline) -> dict[str, Any]:
    """Scheduling decisions: how many, by algorithm and rule, and how many chose to switch; for Alg. 2's
    finite cost comparisons, a histogram of their margins ``1 − c_switch / c_wait`` and, per hysteresis
    of :data:`HYSTERESES`, how many would have decided the other way (a sensitivity check, decision by
    decision: what would have happened after is not re-run)."""
    by = Counter(f"{d.algorithm}/{d.rule if d.rule is not None else '-'}" for d in tl.decisions)
    margins: Counter[str] = Counter()
    flips = dict.fromkeys((f"{h:g}" for h in HYSTERESES), 0)
    compared = 0
    for d in tl.decisions:
        if d.rule != "cost":
            continue
        try:
            cs, cw, h = float(d.get("c_switch")), float(d.get("c_wait")), float(d.get("hysteresis", 1.0))
        except (TypeError, ValueError):
            continue
        if not (math.isfinite(cs) and math.isfinite(cw) and cw > 0 and math.isfinite(h)):
            continue
        compared += 1
        margin = max(-1.0, min(1.0, 1.0 - cs / cw))
        margins[f"{math.floor(margin / MARGIN_BINS + 1e-9) * MARGIN_BINS:+.1f}"] += 1
        for other in HYSTERESES:
            if (cs < other * cw) != (cs < h * cw):
                flips[f"{other:g}"] += 1
    return {"decisions": len(tl.decisions), "switch_decisions": sum(d.switch for d in tl.decisions),
            "decisions_by": dict(sorted(by.items())), "cost_compared": compared,
            "margins": dict(sorted(margins.items(), key=lambda kv: float(kv[0]))), "hysteresis_flips": flips}


# -- safety: hazards -------------------------------------------------------------------------------


def _stretches(owner: AgentTimeline | None, start: float, end: float) -> list[tuple[float, float]]:
    """The unattended stretches of a hazard owned by ``owner`` and on during ``[start, end]``:
    ``(seconds, of which after the owner ended)`` for each maximal stretch of time the owner
    spent out of ``cmd``.  Only time spent in ``cmd`` breaks a stretch."""
    pieces: list[tuple[float, float, bool, bool]] = []  # (from, to, in cmd, after the owner ended)
    if owner is not None:
        for s in owner.states:
            lo, hi = max(s.start, start), min(s.end, end)
            if hi > lo:
                pieces.append((lo, hi, s.state in CMD, False))
        if owner.end is not None and end > max(owner.end.t, start):
            pieces.append((max(owner.end.t, start), end, False, True))
    out: list[tuple[float, float]] = []
    stretch = after = 0.0
    cursor = start
    for lo, hi, in_cmd, after_end in sorted(pieces):
        if lo > cursor:  # no state covers it (before the request): out of cmd
            stretch += lo - cursor
        cursor = max(cursor, hi)
        if in_cmd:
            if stretch > 0:
                out.append((stretch, after))
            stretch = after = 0.0
            continue
        stretch += hi - lo
        if after_end:
            after += hi - lo
    if end > cursor:
        stretch += end - cursor
    if stretch > 0:
        out.append((stretch, after))
    return out


def _exposure(h: HazardEpisode, owner: AgentTimeline | None, t_end: float) -> dict[str, Any]:
    end = h.end if h.end is not None else t_end
    runs = _stretches(owner, h.start, end)
    return {"hazard": h.hazard, "args": list(h.args), "agent": h.owner, "budget_s": h.budget_s,
            "severity": h.severity, "start": h.start,
            "unattended_s": math.fsum(s for s, _ in runs),
            "longest_unattended_s": max((s for s, _ in runs), default=0.0),
            "overruns": sum(1 for s, _ in runs if s > h.budget_s),
            "overrun_s": math.fsum(max(0.0, s - h.budget_s) for s, _ in runs),
            "after_end_s": math.fsum(a for _, a in runs),
            "end": h.end, "active_s": end - h.start}


def _active_at(episodes: Sequence[HazardEpisode], t: float) -> list[HazardEpisode]:
    """Owned episodes on once every event of instant ``t`` has happened."""
    return [h for h in episodes if h.owner is not None and h.start <= t and (h.end is None or h.end > t)]


def safety(tl: Timeline) -> dict[str, Any]:
    """Hazard exposure from the hazard episodes, and what each switch left behind.

    A hazard is *unattended* while it is on and its owner is not in ``cmd``; a stretch of
    unattended time longer than its ``budget_s`` is an *overrun*.  A hazard nobody owns is
    counted apart.  A *switch* here is an agent entering ``wait``; what it leaves on is read
    once every event of that instant has happened."""
    rows: list[dict[str, Any]] = []
    for h in tl.hazards:
        if h.owner is None:
            end = h.end if h.end is not None else tl.t_end
            rows.append({"hazard": h.hazard, "args": list(h.args), "agent": None, "budget_s": h.budget_s,
                         "severity": h.severity, "start": h.start, "unattended_s": 0.0,
                         "longest_unattended_s": 0.0, "overruns": 0, "overrun_s": 0.0, "after_end_s": 0.0,
                         "end": h.end, "active_s": end - h.start})
        else:
            rows.append(_exposure(h, tl.agents.get(h.owner), tl.t_end))
    into_wait = sorted(((s.start, a.id) for a in tl.agents.values() for s in a.states
                        if s.state == S.WAIT.value), key=lambda x: x[0])
    at_switch: list[dict[str, Any]] = []
    for t, agent in into_wait:
        on = _active_at(tl.hazards, t)
        at_switch.append({"t": t, "agent": agent, "own": [(h.hazard, list(h.args)) for h in on if h.owner == agent],
                          "all": len(on)})
    owned = [r for r in rows if r["agent"] is not None]
    open_owned = [h for h in tl.hazards if h.end is None and h.owner is not None]
    kinds = {}
    for k in sorted({r["hazard"] for r in rows}):
        mine = [r for r in owned if r["hazard"] == k]
        kinds[k] = {"episodes": len(mine), "budget_s": max((r["budget_s"] for r in mine), default=None),
                    "active_s": math.fsum(r["active_s"] for r in mine),
                    "unattended_s": math.fsum(r["unattended_s"] for r in mine),
                    "longest_unattended_s": max((r["longest_unattended_s"] for r in mine), default=0.0),
                    "overruns": sum(r["overruns"] for r in mine),
                    "overrun_s": math.fsum(r["overrun_s"] for r in mine),
                    "after_end_s": math.fsum(r["after_end_s"] for r in mine),
                    "at_switch": sum(1 for s in at_switch for hz, _ in s["own"] if hz == k),
                    "active_at_end": sum(1 for h in open_owned if h.hazard == k),
                    "unowned": sum(1 for r in rows if r["hazard"] == k and r["agent"] is None)}
    switches = [{"t": s["t"], "agent": s["agent"], "hazards": [f"{hz}({', '.join(a)})" for hz, a in s["own"]]}
                for s in at_switch]
    return {
        "hazards": kinds, "episodes": rows, "switches_into_wait": switches,
        "violations_at_switch": sum(len(s["own"]) for s in at_switch),
        "hazards_active_at_switch": sum(s["all"] for s in at_switch),
        "unattended_s": math.fsum(r["unattended_s"] for r in owned),
        "longest_unattended_s": max((r["longest_unattended_s"] for r in owned), default=0.0),
        "budget_overruns": sum(r["overruns"] for r in owned),
        "overrun_s": math.fsum(r["overrun_s"] for r in owned),
        "after_end_s": math.fsum(r["after_end_s"] for r in owned),
        "unowned_hazards": len(rows) - len(owned),
        # within the owner's lifetime (what a suspension or hazard-aware waiting could attend to); the
        # rest, after the owner ended, is a task-design defect reported apart (after_end_s)
        "unattended_alive_s": math.fsum(r["unattended_s"] - r["after_end_s"] for r in owned),
        "severity_unattended_s": math.fsum(float(r["severity"]) * (r["unattended_s"] - r["after_end_s"])
                                           for r in owned),
        "unowned_s": math.fsum(r["active_s"] for r in rows if r["agent"] is None),
    }


def _static_fallback(strategy: str | None, note: str | None) -> bool:
    """Whether a plan is a planned call that ran the static template instead: a plan of strategy
    ``static`` whose note says it fell back (``fallback to static: ...``, planners.pddl_task), or a
    ``fallback`` suspension whose planner timed out, so that the tree's branch ran.  A ``fallback``
    suspension that ran its tree's branch because every stage could run is that strategy working,
    not a fall back."""
    text = (note or "").lower()
    return (strategy == "static" and "fallback" in text) or (strategy == "fallback" and "timed out" in text)


def suspensions(tl: Timeline) -> dict[str, Any]:
    """Each suspension episode (entering ``genSusp`` until ``wait`` or ``end``) judged by what it left
    behind: *safe* when, as it ended, the goal its ``exeSusp`` aimed for held (the ``goal`` event) and
    no hazard its agent owns, nor one the robot carries, was on.  A genSusp that made no plan (it
    never entered ``exeSusp``) is not safe.  Without a declared goal (a task type that gives none)
    the stages stand for it: every stage it ran ended ``done`` or ``already_done``.  A stage skipped
    because its effects held already (``already_done``) is never a failure."""
    rows: list[dict[str, Any]] = []
    for a in tl.agents.values():
        for s in a.suspensions:
            if s.outcome == "open":
                continue
            on = _active_at(tl.hazards, s.end)
            left_on = [f"{h.hazard}({', '.join(h.args)})" for h in on if h.owner == a.id or h.carried]
            inapplicable = [r.action for r in s.stages if r.status == "failed" and (r.reason or "").startswith(
                INAPPLICABLE)]
            failed = [r.action for r in s.stages if r.status == "failed"]
            unmet = [" ".join(lit) for lit in s.goal.unmet] if s.goal is not None else []
            entered = any(st.state == S.EXE_SUSP.value and s.start <= st.start <= s.end for st in a.states)
            if not entered:  # genSusp made no plan: the task ended there
                reached = False
            elif s.goal is not None:
                reached = not unmet
            else:
                reached = not failed
            last = s.last_plan
            rows.append({"agent": a.id, "task_type": a.task_type, "start": s.start, "end": s.end,
                         "trigger": s.trigger, "outcome": s.outcome,
                         "strategy": s.plan.strategy if s.plan is not None else None,
                         "fallback": (last.info or {}).get("fallback") if last is not None else None,
                         "replanned": len(s.replans), "stages": len(s.stages), "left_on": left_on,
                         "goal_unmet": unmet, "inapplicable": inapplicable,
                         "already_done": sum(1 for r in s.stages if r.status == "already_done"),
                         "no_plan": not entered,
                         "safe": reached and not left_on, "duration_s": s.duration})
    rows.sort(key=lambda r: (r["start"], r["agent"]))
    safe = [r for r in rows if r["safe"]]
    return {"episodes": rows, "count": len(rows), "safe": len(safe), "unsafe": len(rows) - len(safe),
            "all_safe": not rows or len(safe) == len(rows),
            "goal_unmet": sum(1 for r in rows if r["goal_unmet"]),
            "no_plan": sum(1 for r in rows if r["no_plan"]),
            "inapplicable_stages": sum(len(r["inapplicable"]) for r in rows),
            "already_done_stages": sum(r["already_done"] for r in rows),
            "fallback_planned": sum(1 for r in rows if r["fallback"] == "planned"),
            "time_to_safe_s": _stats([r["duration_s"] for r in safe])}


def carried(tl: Timeline) -> dict[str, Any]:
    """Hazards the robot carried into another task: for each ``carried`` hazard episode, the time it
    was on while an agent other than its owner held the robot (was in ``cmd``), named after that
    agent's task (e.g. ``human_fell (d3) with hot_pan_held(robot, pan)``: helping with the hot pan in hand)."""
    rows: list[dict[str, Any]] = []
    for h in tl.hazards:
        if not h.carried:
            continue
        end = h.end if h.end is not None else tl.t_end
        for a in tl.agents.values():
            if a.id == h.owner:
                continue
            seconds = math.fsum(s.overlap(h.start, end) for s in a.in_cmd())
            if seconds > 0:
                rows.append({"hazard": h.hazard, "args": list(h.args), "owner": h.owner, "agent": a.id,
                             "task_type": a.task_type, "seconds": seconds,
                             "name": f"{a.task_type} ({a.id}) with {h.hazard}({', '.join(h.args)})"})
    rows.sort(key=lambda r: (r["agent"], r["hazard"], r["args"]))
    return {"episodes": rows, "count": len(rows), "seconds": math.fsum(r["seconds"] for r in rows)}


# -- people -------------------------------------------------------------------------------------


def people(tl: Timeline) -> dict[str, Any]:
    """People's roles: time waiting for the robot, following it, told to wait; for people who
    need help, the time from the request to help."""
    out: dict[str, dict[str, Any]] = {}
    for agent in tl.people_order:
        a = tl.agents[agent]
        spans = a.person_roles
        p: dict[str, Any] = {"person": spans[0].person if spans else None, "task_type": a.task_type,
                             "waiting_s": 0.0, "following_s": 0.0, "told_to_wait_s": 0.0, "needs_help": False,
                             "time_to_help_s": None}
        for s in sorted(spans, key=lambda s: (s.end, s.role)):
            key = f"{s.role}_s"
            if key in p:
                p[key] += s.duration
        p["needs_help"] = any(s.role == "needs_help" for s in spans)
        helped = min((s.start for s in spans if s.role == "helped"), default=None)
        p["time_to_help_s"] = helped - a.request_t if helped is not None else None
        out[agent] = p
    ps = out.values()
    helped_s = [p["time_to_help_s"] for p in ps if p["needs_help"] and p["time_to_help_s"] is not None]
    return {"people": out, "people_waiting_s": math.fsum(p["waiting_s"] for p in ps),
            "people_following_s": math.fsum(p["following_s"] for p in ps),
            "people_told_to_wait_s": math.fsum(p["told_to_wait_s"] for p in ps),
            "needing_help": sum(1 for p in ps if p["needs_help"]),
            "not_helped": sum(1 for p in ps if p["needs_help"] and p["time_to_help_s"] is None),
            "time_to_help_s": _stats(helped_s)}


# -- all of them ------------------------------------------------------------------------------------


def _clean(value: Any) -> Any:
    """JSON-ready: plain floats rounded to 6 decimals, infinities as ``"inf"``, tuples as lists."""
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return value
    if isinstance(value, int | float):
        f = float(value)
        if math.isinf(f):
            return "inf" if f > 0 else "-inf"
        return value if isinstance(value, int) else (round(f, 6) + 0.0)
    if isinstance(value, Mapping):
        return {str(k): _clean(v) for k, v in value.items()}
    return [_clean(v) for v in value]


def compute(events: Source) -> dict[str, Any]:
    """Every metric of one run, from its timeline (or its events): deterministic, JSON-serialisable."""
    tl = timeline(events)
    per, totals = tasks(tl)
    out = {"run": run_info(tl), "totals": totals, "switching": switching(tl), "decisions": decisions(tl),
           "safety": safety(tl), "suspensions": suspensions(tl), "carried": carried(tl), "people": people(tl),
           "calibration": calibration(tl), "tasks": per}
    return _clean(out)


def compute_file(path: str | Path) -> dict[str, Any]:
    """:func:`compute` on a saved ``trace.jsonl``."""
    return compute(Timeline.read(path))
