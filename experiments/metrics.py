"""Metrics of a run, computed from its trace alone (``docs/metrics.md`` defines each one).

A metric family is a small collector: it observes events one at a time through
``on_event`` and never touches the model (STYLE principle 10), and ``result`` gives
a JSON-ready dict.  :func:`compute` feeds every collector the same events in order
and composes their results; the same collectors can subscribe to a live
:class:`tasker.trace.Trace`.  Hazards (a cooker on, an object held, a door open, a
person following) are declared in :data:`HAZARDS`, keyed on the bundled domains'
action names, so a new domain adds rows there rather than code.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

from tasker.trace import read

CMD = frozenset({"upTsk", "exeTsk", "genSusp", "exeSusp"})
"""Leaves of the ``cmd`` superstate (Fig. 5): the agent owns the robot."""

Event = Mapping[str, Any]


@dataclass(frozen=True)
class HazardRule:
    """A stage whose ``status`` turns a hazard on (``starts``) or off for ``args[1]``."""

    action: str
    hazard: str
    starts: bool
    status: str = "done"


HAZARDS: tuple[HazardRule, ...] = (
    HazardRule("turn_on", "cooker_on", True),  # cook
    HazardRule("turn_off", "cooker_on", False),
    HazardRule("pick_pan", "object_held", True),
    HazardRule("take_off_cooker", "object_held", True),
    HazardRule("put_on_cooker", "object_held", False),
    HazardRule("put_down", "object_held", False),
    HazardRule("pick", "object_held", True),  # carry_object
    HazardRule("place", "object_held", False),
    HazardRule("open_door", "door_open", True),
    HazardRule("close_door", "door_open", False),
    HazardRule("ask_to_follow", "person_following", True),  # guide_human
    HazardRule("guide", "person_following", True, "begin"),  # guiding implies following
    HazardRule("say_goodbye", "person_following", False),
    HazardRule("goodbye", "person_following", False),  # the synthetic demo's name
    HazardRule("ask_to_wait", "person_following", False),
)
"""The hazard table: every other action leaves hazards as they are."""

HAZARD_KINDS = ("cooker_on", "object_held", "door_open", "person_following")
PERSON_HAZARDS = frozenset({"person_following"})
"""Hazards that end with their task: nobody follows a robot whose task is over."""

WAITING_TASKS = frozenset({"guide_human", "human_fell"})
"""Task types whose person waits for the robot from the request on."""
WAIT_ENDS = frozenset({"greet", "greet_and_apologise", "apologise", "check_consciousness"})
WAIT_STARTS = frozenset({"ask_to_wait"})
"""A ``done`` stage of these actions ends / restarts the person's wait."""

_RULES = {(r.action, r.status): r for r in HAZARDS}


class Collector(Protocol):
    """One metric family: observes events in order, then reports a JSON-ready dict."""

    def on_event(self, e: Event) -> None: ...

    def result(self) -> dict[str, Any]: ...


def _subject(e: Event) -> str:
    """What a stage acts on: ``args[1]`` in the bundled domains (``args[0]`` is the robot)."""
    args = e.get("args") or []
    return str(args[1]) if len(args) > 1 else str(e["agent"])


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
            "finished": causes.get("finished", 0), "failed": causes.get("failed", 0) + causes.get("other", 0),
            "ended_by_itself": causes.get("self", 0), "terminated": causes.get("term", 0),
            "by_cause": dict(sorted(causes.items())),
            "failure_reasons": [f"{a}: {v['reason']}" for a, v in tasks.items()
                                if v["end_t"] is not None and v["cause"] in ("failed", "other")],
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
    """Hazard exposure (from :data:`HAZARDS`) and what each switch left behind.

    A hazard is owned by the agent whose stage started it; it is *unattended* while
    its owner is not in ``cmd``.  A *switch* here is an agent entering ``wait``.
    """

    def __init__(self) -> None:
        self.state: dict[str, str] = {}
        self.active: dict[tuple[str, str], dict[str, Any]] = {}
        self.episodes: list[dict[str, Any]] = []
        self.at_switch: list[dict[str, Any]] = []
        self.t = 0.0

    def _advance(self, t: float) -> None:
        for h in self.active.values():
            if self.state.get(h["agent"]) not in CMD:
                h["unattended_s"] += t - self.t
        self.t = max(self.t, t)

    def _close(self, key: tuple[str, str]) -> None:
        h = self.active.pop(key)
        self.episodes.append(dict(h, end=self.t, active_s=self.t - h["start"]))

    def on_event(self, e: Event) -> None:
        self._advance(float(e["t"]))
        kind, agent = e["event"], str(e.get("agent", ""))
        if kind == "request":
            self.state[agent] = "initComm"
        elif kind == "transition":
            self.state[agent] = e["to"]
            if e["to"] == "wait":
                own = [h for h in self.active.values() if h["agent"] == agent]
                self.at_switch.append({"t": self.t, "agent": agent, "own": [(h["hazard"], h["subject"]) for h in own],
                                       "all": len(self.active)})
        elif kind == "stage":
            rule = _RULES.get((e["action"], e["status"]))
            if rule is not None:
                key = (rule.hazard, _subject(e))
                if rule.starts and key not in self.active:
                    self.active[key] = {"hazard": rule.hazard, "subject": key[1], "agent": agent,
                                        "start": self.t, "unattended_s": 0.0}
                elif not rule.starts and key in self.active:
                    self._close(key)
        elif kind == "end":
            for key in [k for k, h in self.active.items() if h["agent"] == agent and h["hazard"] in PERSON_HAZARDS]:
                self._close(key)

    def result(self) -> dict[str, Any]:
        open_now = [dict(h, end=None, active_s=self.t - h["start"]) for h in self.active.values()]
        episodes = sorted(self.episodes + open_now, key=lambda h: (h["start"], h["hazard"], h["subject"]))
        kinds = {}
        for k in HAZARD_KINDS:
            mine = [h for h in episodes if h["hazard"] == k]
            kinds[k] = {"episodes": len(mine), "active_s": math.fsum(h["active_s"] for h in mine),
                        "unattended_s": math.fsum(h["unattended_s"] for h in mine),
                        "at_switch": sum(1 for s in self.at_switch for hz, _ in s["own"] if hz == k),
                        "active_at_end": sum(1 for h in open_now if h["hazard"] == k)}
        switches = [{"t": s["t"], "agent": s["agent"], "hazards": [f"{hz}({subj})" for hz, subj in s["own"]]}
                    for s in self.at_switch]
        return {
            "hazards": kinds, "episodes": episodes, "switches_into_wait": switches,
            "violations_at_switch": sum(len(s["own"]) for s in self.at_switch),
            "hazards_active_at_switch": sum(s["all"] for s in self.at_switch),
            "cooker_unattended_s": kinds["cooker_on"]["unattended_s"],
            "objects_held_at_switch": kinds["object_held"]["at_switch"],
            "doors_open_at_switch": kinds["door_open"]["at_switch"],
            "people_following_at_switch": kinds["person_following"]["at_switch"],
        }


class PeopleCollector:
    """Time people spend waiting for the robot and following it (per agent of a person task)."""

    def __init__(self) -> None:
        self.people: dict[str, dict[str, Any]] = {}
        self._waiting: dict[str, float] = {}
        self._following: dict[str, float] = {}
        self.t = 0.0

    def on_event(self, e: Event) -> None:
        t, kind, agent = float(e["t"]), e["event"], e.get("agent", "")
        self.t = max(self.t, t)
        if kind == "request" and e["task_type"] in WAITING_TASKS:
            person = str((e.get("args") or {}).get("person", agent))
            self.people[agent] = {"person": person, "task_type": e["task_type"], "waiting_s": 0.0, "following_s": 0.0}
            self._waiting[agent] = t
        if agent not in self.people:
            return
        p = self.people[agent]
        if kind == "stage":
            rule = _RULES.get((e["action"], e["status"]))
            if rule is not None and rule.hazard == "person_following":
                if rule.starts:
                    self._following.setdefault(agent, t)
                elif agent in self._following:
                    p["following_s"] += t - self._following.pop(agent)
            if e["status"] == "done" and e["action"] in WAIT_ENDS and agent in self._waiting:
                p["waiting_s"] += t - self._waiting.pop(agent)
            elif e["status"] == "done" and e["action"] in WAIT_STARTS:
                self._waiting.setdefault(agent, t)
        elif kind == "end":
            self._flush(agent, t)

    def _flush(self, agent: str, t: float) -> None:
        p = self.people[agent]
        if agent in self._waiting:
            p["waiting_s"] += t - self._waiting.pop(agent)
        if agent in self._following:
            p["following_s"] += t - self._following.pop(agent)

    def result(self) -> dict[str, Any]:
        for agent in sorted(set(self._waiting) | set(self._following)):  # still open when the run stopped
            self._flush(agent, self.t)
        return {"people": self.people, "people_waiting_s": math.fsum(p["waiting_s"] for p in self.people.values()),
                "people_following_s": math.fsum(p["following_s"] for p in self.people.values())}


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
            "decisions": DecisionCollector(), "safety": HazardCollector(), "people": PeopleCollector()}


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

