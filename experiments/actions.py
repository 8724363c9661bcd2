"""What happens during a run, read from a scenario file: requests, terminations,
changes, mode switches and world events, each at a time.

Shared by the synthetic and the robot scenario loaders, so both check the same
fields the same way; errors name the file and the field.
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass, field
from typing import Any

from experiments.fields import Fields, ScenarioError

WORLD_EVENT_KINDS = ("posture", "door", "add", "delete")

_TABLES = (("requests", "request"), ("terminations", "terminate"), ("changes", "change"),
           ("mode_changes", "mode"), ("world_events", "world"))


@dataclass(frozen=True)
class TimedAction:
    """One thing that happens at time ``t``: ``kind`` is request, terminate, change, mode or world."""

    t: float
    kind: str
    fields: dict[str, Any] = field(default_factory=dict)


def read_actions(top: Fields, *, task_names: Collection[str] | None = None,
                 world_events: bool = False) -> tuple[TimedAction, ...]:
    """Every timed action of a scenario file, sorted by time (stable).

    ``task_names``, when given, are the only task types a request may name;
    ``world_events`` allows the ``[[world_events]]`` table (robot scenarios).
    """
    out: list[TimedAction] = []
    for key, kind in _TABLES:
        if kind == "world" and not world_events:
            continue
        for i, item in enumerate(top.get(key, list, [])):
            f = Fields(top.source, f"{key}[{i}]", item)
            t = f.get("t", float)
            if t < 0:
                raise f.error("t", f"expected >= 0, got {t}")
            out.append(TimedAction(t, kind, _read(f, kind, task_names)))
            f.done()
    actions = tuple(sorted(out, key=lambda a: a.t))
    if not any(a.kind == "request" for a in actions):
        raise top.error("requests", "a scenario needs at least one request")
    _check_agents(top.source, actions)
    return actions


def _read(f: Fields, kind: str, task_names: Collection[str] | None) -> dict[str, Any]:
    if kind == "request":
        task = f.get("task", str)
        if task_names is not None and task not in task_names:
            raise f.error("task", f"unknown task type {task!r}; defined: {sorted(task_names)}")
        return {"task": task, "args": f.get("args", dict, {})}
    if kind == "terminate":
        return {"agent": f.get("agent", str), "reason": f.get("reason", str, "terminated by the requester")}
    if kind == "change":
        return {"agent": f.get("agent", str), "args": f.get("args", dict)}
    if kind == "mode":
        mode = f.get("mode", str)
        if mode not in ("IT", "CT"):
            raise f.error("mode", f"expected 'IT' or 'CT', got {mode!r}")
        return {"mode": mode}
    given = [k for k in WORLD_EVENT_KINDS if k in f.table]
    if len(given) != 1:
        raise f.error("", f"a world event has exactly one of {list(WORLD_EVENT_KINDS)}, got {given}")
    what = given[0]
    value = f.get(what, list)
    if what == "posture" and (len(value) != 2 or not all(isinstance(v, str) for v in value)):
        raise f.error(what, f"expected [person, posture], got {value!r}")
    if what == "door" and (len(value) != 2 or not isinstance(value[0], str) or not isinstance(value[1], bool)):
        raise f.error(what, f"expected [door, true|false], got {value!r}")
    if what in ("add", "delete") and not all(isinstance(x, list) and all(isinstance(a, str) for a in x)
                                             for x in value):
        raise f.error(what, f"expected a list of facts (lists of strings), got {value!r}")
    return {"what": what, "value": value, "note": f.get("note", str, "")}


def _check_agents(source: str, actions: tuple[TimedAction, ...]) -> None:
    """Agents are ``d1``, ``d2``, … in request order; one can only be changed once requested."""
    request_times = [a.t for a in actions if a.kind == "request"]
    for a in actions:
        if a.kind not in ("terminate", "change"):
            continue
        agent = a.fields["agent"]
        k = int(agent[1:]) if agent[:1] == "d" and agent[1:].isdigit() else 0
        key = "terminations" if a.kind == "terminate" else "changes"
        if not 1 <= k <= len(request_times) or request_times[k - 1] > a.t:
            raise ScenarioError(
                f"{source}: {key}: agent {agent!r} at t={a.t}: agents are d1..d{len(request_times)} "
                "in request order, and must be requested before they are changed or terminated"
            )
