"""Metrics of a run, computed from its trace alone (``docs/metrics.md`` defines each one).

A metric family is a small collector: it observes events one at a time through
``on_event`` and never touches the model (STYLE principle 10), and ``result`` gives
a JSON-ready dict.  :func:`compute` feeds every collector the same events in order
and composes their results; the same collectors can subscribe to a live
:class:`tasker.trace.Trace`.  What is hazardous and who waits is declared by each
task folder and reaches the metrics only through the trace's ``hazard`` and ``role``
events (:mod:`tasker.meaning`): this module names no task, action or predicate, so a
user's new domain is measured exactly like a bundled one.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any, Protocol

from experiments.metrics.calibration import CalibrationCollector
from tasker.meaning import CMD_STATES as CMD
from tasker.trace import FAILED, read

Event = Mapping[str, Any]


class Collector(Protocol):
    """One metric family: observes events in order, then reports a JSON-ready dict."""

    def on_event(self, e: Event) -> None: ...

    def result(self) -> dict[str, Any]: ...


def _stats(values: list[float]) -> dict[str, float | None]:
    return {"mean": sum(values) / len(values) if values else None, "max": max(values) if values else None}


class TaskCollector:
    """Per task: lifetime, end, suspensions, resumptions and plans; totals over tasks."""

    def __init__(self) -> None:
        self.tasks: dict[str, dict[str, Any]] = {}
        self._since: dict[str, dict[str, float]] = {}
        self.last_t = 0.0

    def on_event(self, e: Event) -> None:
        t, kind = float(e["t"]), e["event"]
        self.last_t = max(self.last_t, t)
        if kind == "request":
            self.tasks[e["agent"]] = {
                "task_type": e["task_type"], "request_t": t, "end_t": None, "duration_s": None,
                "reason": None, "cause": None, "suspensions": 0, "suspended_s": 0.0,
                "suspension_s": [], "resumption_s": [], "plans": 0, "plans_by": {}, "static_fallbacks": 0,
                "stages": {"done": 0, "stopped": 0, "failed": 0}, "stage_failures": [],
            }
            self._since[e["agent"]] = {}
            return
        task = self.tasks.get(e.get("agent", ""))
        if task is None:
            return
        since = self._since[e["agent"]]
        if kind == "transition":
            to = e["to"]
            if to == "genSusp":
                task["suspensions"] += 1
                since["genSusp"] = t
            elif to == "wait":
                task["suspension_s"].append(t - since.pop("genSusp", t))
                since["wait"] = t
            if e["from"] == "wait":
                task["suspended_s"] += t - since.pop("wait", t)
                if to == "upTsk":
                    since["resume"] = t
        elif kind == "stage" and e["status"] == "begin" and "resume" in since:
            task["resumption_s"].append(t - since.pop("resume"))
        elif kind == "stage" and e["status"] in task["stages"]:
            task["stages"][e["status"]] += 1
            if e["status"] == "failed":
                task["stage_failures"].append(f"{e['action']}: {e.get('reason', '?')}")
        elif kind == "plan":
            task["plans"] += 1
            key = f"{e['purpose']}/{e['strategy']}"
            task["plans_by"][key] = task["plans_by"].get(key, 0) + 1
            if "fallback" in str(e.get("note", "")).lower():
                task["static_fallbacks"] += 1
        elif kind == "end":
            task.update(end_t=t, duration_s=t - task["request_t"], reason=e["reason"], cause=e["cause"])
            if "wait" in since:
                task["suspended_s"] += t - since.pop("wait")

    def result(self) -> dict[str, Any]:
        tasks = {a: dict(v, plans_by=dict(sorted(v["plans_by"].items()))) for a, v in self.tasks.items()}
        for a, task in tasks.items():
            if task["end_t"] is None and "wait" in self._since[a]:  # still waiting when the run stopped
                task["suspended_s"] += self.last_t - self._since[a]["wait"]
        ended = [v for v in tasks.values() if v["end_t"] is not None]
        durations = [v["duration_s"] for v in ended]
        causes = Counter(v["cause"] for v in ended)
        plans_by: Counter[str] = Counter()
        for v in tasks.values():
            plans_by.update(v["plans_by"])
        first = min((v["request_t"] for v in tasks.values()), default=0.0)
        last = self.last_t if len(ended) < len(tasks) else max((v["end_t"] for v in ended), default=first)
        suspensions = [d for v in tasks.values() for d in v["suspension_s"]]
        resumptions = [d for v in tasks.values() for d in v["resumption_s"]]
        totals = {
            "requested": len(tasks), "ended": len(ended), "unfinished": len(tasks) - len(ended),
            # a task that ended itself (ic_term: "Peter is fine") or was cancelled did not fail
            "finished": causes.get("finished", 0), "failed": sum(causes.get(c, 0) for c in FAILED),
            "ended_by_itself": causes.get("self", 0), "terminated": causes.get("term", 0),
            "by_cause": dict(sorted(causes.items())),
            "failure_reasons": [f"{a}: {v['reason']}" for a, v in tasks.items()
                                if v["end_t"] is not None and v["cause"] in FAILED],
            "duration_s": _stats(durations), "makespan_s": last - first if tasks else 0.0,
            "suspensions": sum(v["suspensions"] for v in tasks.values()),
            "suspended_s": math.fsum(v["suspended_s"] for v in tasks.values()),
            "suspension_s": _stats(suspensions), "resumption_s": _stats(resumptions),
            "plans": sum(plans_by.values()), "plans_by": dict(sorted(plans_by.items())),
            "static_fallbacks": sum(v["static_fallbacks"] for v in tasks.values()),
        }
        return {"tasks": tasks, "totals": totals}


class SwitchCollector:
    """Commands of the harmoniser; a switch is a ``susp`` followed by a ``start`` of another agent."""

    def __init__(self) -> None:
        self.commands: Counter[str] = Counter()
        self.switches: list[dict[str, Any]] = []
        self._suspended: tuple[float, str] | None = None
        self.mode_changes = 0
        self.changes = 0

    def on_event(self, e: Event) -> None:
        kind = e["event"]
        if kind == "command":
            self.commands[e["flag"]] += 1
            if e["flag"] == "susp":
                self._suspended = (float(e["t"]), e["agent"])
            elif e["flag"] == "start" and self._suspended is not None:
                t0, old = self._suspended
                self._suspended = None
                if e["agent"] != old:
                    self.switches.append({"t_susp": t0, "t_start": float(e["t"]), "from": old, "to": e["agent"],
                                          "latency_s": float(e["t"]) - t0})
        elif kind == "mode":
            self.mode_changes += 1
        elif kind == "change" and "ignored" not in e:
            self.changes += 1

    def result(self) -> dict[str, Any]:
        return {"switches": len(self.switches), "switch_list": self.switches,
                "switch_latency_s": _stats([s["latency_s"] for s in self.switches]),
                "commands": dict(sorted(self.commands.items())), "mode_changes": self.mode_changes,
                "changes": self.changes}


class DecisionCollector:
    """Scheduling decisions: how many, by algorithm and rule, and how many chose to switch."""

    def __init__(self) -> None:
        self.count = 0
        self.switch = 0
        self.by: Counter[str] = Counter()

    def on_event(self, e: Event) -> None:
        if e["event"] == "decision":
            self.count += 1
            self.switch += bool(e.get("switch"))
            self.by[f"{e.get('algorithm', '?')}/{e.get('rule', '-')}"] += 1

    def result(self) -> dict[str, Any]:
        return {"decisions": self.count, "switch_decisions": self.switch, "decisions_by": dict(sorted(self.by.items()))}


class HazardCollector:
    """Hazard exposure from the trace's ``hazard`` edges, and what each switch left behind.

    A hazard is *unattended* while it is on and its agent is not ``exeDA`` (not in
    ``cmd``); a stretch of unattended time longer than the hazard's ``budget_s`` is an
    *overrun*.  A hazard nobody owns (``agent: null``, e.g. a door open in the world
    file) is counted apart: nobody could attend to it.  A *switch* here is an agent
    entering ``wait``; what it leaves on is read at the end of that instant (a hazard
    its suspension turned off in the same tick is not left behind).
    """

    def __init__(self) -> None:
        self.state: dict[str, str] = {}
        self.active: dict[tuple[str, str, tuple[str, ...]], dict[str, Any]] = {}
        self.episodes: list[dict[str, Any]] = []
        self.at_switch: list[dict[str, Any]] = []
        self._pending: list[tuple[float, str]] = []
        self.t = 0.0

    def _advance(self, t: float) -> None:
        dt = t - self.t
        for h in self.active.values():
            if h["agent"] is None or dt <= 0:
                continue
            if self.state.get(h["agent"]) in CMD:
                h["stretch"] = 0.0
                continue
            before = h["stretch"]
            h["stretch"] += dt
            h["unattended_s"] += dt
            if self.state.get(h["agent"]) == "end":  # left behind by a task that has ended
                h["after_end_s"] += dt
            h["longest_unattended_s"] = max(h["longest_unattended_s"], h["stretch"])
            over = h["stretch"] - max(h["budget_s"], before)
            if over > 0:
                h["overrun_s"] += over
                if before <= h["budget_s"]:
                    h["overruns"] += 1
        self.t = max(self.t, t)

    def _settle(self, t: float) -> None:
        """Switches of an earlier instant see the hazards as that instant left them."""
        while self._pending and self._pending[0][0] < t:
            t0, agent = self._pending.pop(0)
            owned = [h for h in self.active.values() if h["agent"] is not None]
            own = [h for h in owned if h["agent"] == agent]
            self.at_switch.append({"t": t0, "agent": agent, "own": [(h["hazard"], h["args"]) for h in own],
                                   "all": len(owned)})

    def _close(self, key: tuple[str, str, tuple[str, ...]]) -> None:
        h = self.active.pop(key)
        self.episodes.append(dict(h, end=self.t, active_s=self.t - h["start"]))

    def on_event(self, e: Event) -> None:
        t = float(e["t"])
        self._settle(t)
        self._advance(t)
        kind, agent = e["event"], e.get("agent")
        if kind == "request":
            self.state[str(agent)] = "initComm"
        elif kind == "transition":
            self.state[str(agent)] = e["to"]
            if e["to"] == "wait":
                self._pending.append((t, str(agent)))
        elif kind == "hazard":
            key = (str(agent), str(e["hazard"]), tuple(str(a) for a in e.get("args", [])))
            if e["status"] == "on" and key not in self.active:
                self.active[key] = {"hazard": e["hazard"], "args": list(key[2]), "agent": agent,
                                    "budget_s": float(e.get("budget_s", 0.0)), "severity": e.get("severity", 1.0),
                                    "start": self.t, "unattended_s": 0.0, "longest_unattended_s": 0.0,
                                    "stretch": 0.0, "overruns": 0, "overrun_s": 0.0, "after_end_s": 0.0}
            elif e["status"] == "off" and key in self.active:
                self._close(key)

    def result(self) -> dict[str, Any]:
        self._settle(math.inf)
        open_now = [dict(h, end=None, active_s=self.t - h["start"]) for h in self.active.values()]
        episodes = sorted(self.episodes + open_now, key=lambda h: (h["start"], h["hazard"], h["args"],
                                                                    str(h["agent"])))
        for h in episodes:
            h.pop("stretch", None)
        owned = [h for h in episodes if h["agent"] is not None]
        kinds = {}
        for k in sorted({h["hazard"] for h in episodes}):
            mine = [h for h in owned if h["hazard"] == k]
            kinds[k] = {"episodes": len(mine), "budget_s": max((h["budget_s"] for h in mine), default=None),
                        "active_s": math.fsum(h["active_s"] for h in mine),
                        "unattended_s": math.fsum(h["unattended_s"] for h in mine),
                        "longest_unattended_s": max((h["longest_unattended_s"] for h in mine), default=0.0),
                        "overruns": sum(h["overruns"] for h in mine),
                        "overrun_s": math.fsum(h["overrun_s"] for h in mine),
                        "after_end_s": math.fsum(h["after_end_s"] for h in mine),
                        "at_switch": sum(1 for s in self.at_switch for hz, _ in s["own"] if hz == k),
                        "active_at_end": sum(1 for h in open_now if h["hazard"] == k and h["agent"] is not None),
                        "unowned": sum(1 for h in episodes if h["hazard"] == k and h["agent"] is None)}
        switches = [{"t": s["t"], "agent": s["agent"], "hazards": [f"{hz}({', '.join(a)})" for hz, a in s["own"]]}
                    for s in self.at_switch]
        return {
            "hazards": kinds, "episodes": episodes, "switches_into_wait": switches,
            "violations_at_switch": sum(len(s["own"]) for s in self.at_switch),
            "hazards_active_at_switch": sum(s["all"] for s in self.at_switch),
            "unattended_s": math.fsum(h["unattended_s"] for h in owned),
            "longest_unattended_s": max((h["longest_unattended_s"] for h in owned), default=0.0),
            "budget_overruns": sum(h["overruns"] for h in owned),
            "overrun_s": math.fsum(h["overrun_s"] for h in owned),
            "after_end_s": math.fsum(h["after_end_s"] for h in owned),
            "unowned_hazards": len(episodes) - len(owned),
        }


class PeopleCollector:
    """People's roles from the trace's ``role`` edges: time waiting for the robot, following
    it, told to wait; and, for people who need help, the time from request to help."""

    def __init__(self) -> None:
        self.requests: dict[str, dict[str, Any]] = {}
        self.people: dict[str, dict[str, Any]] = {}
        self._on: dict[tuple[str, str], float] = {}
        self.t = 0.0

    def on_event(self, e: Event) -> None:
        t, kind, agent = float(e["t"]), e["event"], str(e.get("agent", ""))
        self.t = max(self.t, t)
        if kind == "request":
            self.requests[agent] = {"task_type": e["task_type"], "request_t": t}
        elif kind == "role" and agent in self.requests:
            p = self.people.setdefault(agent, {
                "person": e.get("person"), "task_type": self.requests[agent]["task_type"], "waiting_s": 0.0,
                "following_s": 0.0, "told_to_wait_s": 0.0, "needs_help": False, "time_to_help_s": None})
            role = str(e["role"])
            if e["status"] == "on":
                self._on.setdefault((agent, role), t)
                if role == "needs_help":
                    p["needs_help"] = True
                elif role == "helped" and p["time_to_help_s"] is None:
                    p["time_to_help_s"] = t - self.requests[agent]["request_t"]
            elif (agent, role) in self._on:
                self._add(agent, role, t - self._on.pop((agent, role)))

    def _add(self, agent: str, role: str, seconds: float) -> None:
        key = f"{role}_s"
        if key in self.people[agent]:
            self.people[agent][key] += seconds

    def result(self) -> dict[str, Any]:
        for (agent, role), t0 in sorted(self._on.items()):  # still on when the run stopped
            self._add(agent, role, self.t - t0)
        self._on.clear()
        ps = self.people.values()
        helped = [p["time_to_help_s"] for p in ps if p["needs_help"] and p["time_to_help_s"] is not None]
        return {"people": self.people, "people_waiting_s": math.fsum(p["waiting_s"] for p in ps),
                "people_following_s": math.fsum(p["following_s"] for p in ps),
                "people_told_to_wait_s": math.fsum(p["told_to_wait_s"] for p in ps),
                "needing_help": sum(1 for p in ps if p["needs_help"]),
                "not_helped": sum(1 for p in ps if p["needs_help"] and p["time_to_help_s"] is None),
                "time_to_help_s": _stats(helped)}


class RunCollector:
    """The run's header and how it stopped."""

    def __init__(self) -> None:
        self.info: dict[str, Any] = {"events": 0, "duration_s": 0.0, "horizon_reached": False, "active_at_end": []}

    def on_event(self, e: Event) -> None:
        self.info["events"] += 1
        self.info["duration_s"] = max(self.info["duration_s"], float(e["t"]))
        if e["event"] == "run" and "status" not in e:
            self.info.update({k: e[k] for k in ("seed", "scheduler", "mode") if k in e})
        elif e["event"] == "run":
            self.info.update(horizon_reached=True, active_at_end=list(e.get("active", [])))

    def result(self) -> dict[str, Any]:
        return dict(self.info)


def collectors() -> dict[str, Collector]:
    """A fresh set of collectors, keyed by the section of :func:`compute`'s result they fill."""
    return {"run": RunCollector(), "tasks": TaskCollector(), "switching": SwitchCollector(),
            "decisions": DecisionCollector(), "safety": HazardCollector(), "people": PeopleCollector(),
            "calibration": CalibrationCollector()}


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


def compute(events: Iterable[Event]) -> dict[str, Any]:
    """Every metric of one run, from its trace events (deterministic, JSON-serialisable)."""
    cs = collectors()
    for e in events:
        for c in cs.values():
            c.on_event(e)
    parts = {name: c.result() for name, c in cs.items()}
    tasks = parts.pop("tasks")
    out = {"run": parts.pop("run"), "totals": tasks["totals"], **parts, "tasks": tasks["tasks"]}
    return _clean(out)


def compute_file(path: str | Path) -> dict[str, Any]:
    """:func:`compute` on a saved ``trace.jsonl``."""
    return compute(read(path))

