"""What happens during a run, read from a scenario file: requests, terminations,
changes, mode switches and world events, each at a time.

Shared by the synthetic and the robot scenario loaders, so both check the same
fields the same way, with :mod:`tasker.support.reader`: errors name the file, the line and
the field.  Cross-references to the world and the task store (who is a person, what
a task type takes) are checked by :mod:`experiments.inputs.crossref`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection, Mapping
from dataclasses import dataclass, field
from typing import Any

from experiments.inputs.fields import MODES, ScenarioError
from experiments.inputs.request_fields import FIELD_NAMES
from tasker.errors import ConfigError
from tasker.support.reader import MAX_SECONDS, Table, check_name, suggest

__all__ = ["NO_REQUESTS", "TABLES", "WORLD_EVENT_KINDS", "Change", "ModeSwitch", "Payload", "Renewal", "Request",
           "ScenarioError", "Terminate", "TimedAction", "WorldEvent", "located", "read_actions"]

WORLD_EVENT_KINDS = ("posture", "door", "walk", "add", "delete", "device", "move")
"""What a world event may do: a person's posture, a door, a person walking to a point, facts added or
deleted, a device switched (``[device, state]``), an object moved to a place (``[object, place]``)."""

TABLES = (("requests", "request"), ("terminations", "terminate"), ("changes", "change"),
          ("mode_changes", "mode"), ("world_events", "world"))
"""The array-of-tables keys of a scenario file and the kind of action each holds."""


@dataclass(frozen=True)
class Renewal:
    """A request renewed ``after_s`` seconds after its agent ends, until ``until`` (a day's recurring need)."""

    after_s: float
    until: float


@dataclass(frozen=True)
class Request:
    """``[[requests]]``: a task type and its arguments (``renew``: requested again after it ends)."""

    task: str
    args: dict[str, Any]
    renew: Renewal | None = None


@dataclass(frozen=True)
class Terminate:
    """``[[terminations]]``: the requester ends an agent's task, with a reason."""

    agent: str
    reason: str


@dataclass(frozen=True)
class Change:
    """``[[changes]]``: the requester changes arguments of an agent's task."""

    agent: str
    args: dict[str, Any]


@dataclass(frozen=True)
class ModeSwitch:
    """``[[mode_changes]]``: the harmoniser's mode (``IT`` or ``CT``) from now on."""

    mode: str


@dataclass(frozen=True)
class WorldEvent:
    """``[[world_events]]``: one of :data:`WORLD_EVENT_KINDS` (``what``) with its ``value``; ``note`` says
    why (None: the file gave none), ``after`` waits for that agent's task to end."""

    what: str
    value: Any
    note: str | None = None
    after: str | None = None


Payload = Request | Terminate | Change | ModeSwitch | WorldEvent
"""What a timed action does, typed by its kind."""

_PAYLOADS: dict[str, Callable[[Mapping[str, Any]], Payload]] = {
    "request": lambda f: Request(f["task"], f["args"], None if f.get("renew") is None else Renewal(
        float(f["renew"]["after_s"]), float(f["renew"]["until"]))),
    "terminate": lambda f: Terminate(f["agent"], f["reason"]),
    "change": lambda f: Change(f["agent"], f["args"]),
    "mode": lambda f: ModeSwitch(f["mode"]),
    "world": lambda f: WorldEvent(f["what"], f["value"], f.get("note"), f.get("after")),
}


@dataclass(frozen=True)
class TimedAction:
    """One thing that happens at time ``t``: ``kind`` is request, terminate, change, mode or world.

    ``fields`` is the action as the scenario file (and ``run.json``'s scenario, a saved live session)
    writes it; :attr:`payload` is the same, typed by the kind (:data:`Payload`), for the code that
    acts on it.  ``origin`` is where it was written (``("requests", 2)``), for error messages.
    """

    t: float
    kind: str
    fields: dict[str, Any] = field(default_factory=dict)
    origin: tuple[str, int] = field(default=("", -1), compare=False, repr=False)
    payload: Payload = field(init=False, compare=False, repr=False)

    def __post_init__(self) -> None:
        make = _PAYLOADS.get(self.kind)
        if make is None:
            raise ConfigError(f"TimedAction.kind must be one of {list(_PAYLOADS)}, got {self.kind!r}")
        try:
            payload = make(self.fields)
        except (KeyError, TypeError) as exc:
            raise ConfigError(f"TimedAction({self.kind!r}).fields lacks {exc} (got {sorted(self.fields)})") from None
        object.__setattr__(self, "payload", payload)


def read_actions(top: Table, *, task_names: Collection[str] | None = None,
                 world_events: bool = False) -> tuple[TimedAction, ...]:
    """Every timed action of a scenario file, sorted by time (stable).

    ``task_names``, when given, are the only task types a request may name;
    ``world_events`` allows the ``[[world_events]]`` table (robot scenarios).
    """
    out: list[TimedAction] = []
    for key, kind in TABLES:
        if kind == "world" and not world_events:
            continue
        for i, f in enumerate(top.tables(key, [])):
            t = float(f.number("t", min=0, max=MAX_SECONDS))  # the clock steps to it: 1e300 never came
            out.append(TimedAction(t, kind, _read(f, kind, task_names), (key, i)))
            f.done()
    actions = tuple(sorted(out, key=lambda a: a.t))
    _check_agents(top, actions)
    return actions


NO_REQUESTS = "no [[requests]]: no task runs, and the run ends after the scenario's last other event"
"""The warning for a scenario without requests (valid: a world, its people and its events to watch)."""


def located(top: Table, a: TimedAction) -> Table:
    """The table an action was read from (for errors that name its file, line and field)."""
    key, i = a.origin
    return top.tables(key)[i]


def _args(f: Table, key: str, required: bool) -> dict[str, Any]:
    args = f.table(key) if required else f.table(key, {})
    return dict(args.items())


def _read(f: Table, kind: str, task_names: Collection[str] | None) -> dict[str, Any]:
    if kind == "request":
        task = f.string("task")
        if task_names is not None:
            check_name(f, "task", task, task_names, "task type")
        misplaced = next((k for k in FIELD_NAMES if k in f), None)
        if misplaced is not None:  # docs/scenarios.md: "any request may also give deadline = …" (in its args)
            raise f.error(misplaced, f"{misplaced!r} is one of the request's args: write it as "
                                     f"args = {{ …, {misplaced} = {f.data[misplaced]!r} }}")
        return {"task": task, "args": _args(f, "args", False)}
    if kind == "terminate":
        return {"agent": f.string("agent"), "reason": f.string("reason", "terminated by the requester")}
    if kind == "change":
        return {"agent": f.string("agent"), "args": _args(f, "args", True)}
    if kind == "mode":
        return {"mode": f.string("mode", choices=MODES)}
    given = [k for k in WORLD_EVENT_KINDS if k in f]
    if len(given) != 1:
        others = [k for k in f.keys() if k not in ("t", "note", "after")]
        hint = suggest(others[0], WORLD_EVENT_KINDS) if others and not given else ""
        raise f.error(None, f"a world event has exactly one of {list(WORLD_EVENT_KINDS)}, got "
                            f"{given or others or 'none'}{hint}")
    what = given[0]
    value = f.array(what)
    if what == "posture" and (len(value) != 2 or not all(isinstance(v, str) and v for v in value)):
        raise f.error(what, f"expected [person, posture], got {value!r}")
    if what == "door" and (len(value) != 2 or not isinstance(value[0], str) or not isinstance(value[1], bool)):
        raise f.error(what, f"expected [door, true|false], got {value!r}")
    if what == "walk" and (len(value) != 3 or not isinstance(value[0], str) or not value[0] or not all(
            isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v) for v in value[1:])):
        raise f.error(what, f"expected [person, x, y] (x and y in metres), got {value!r}")
    if what in ("device", "move") and (len(value) != 2 or not all(isinstance(v, str) and v for v in value)):
        raise f.error(what, f"expected [{'device, state' if what == 'device' else 'object, place'}], got {value!r}")
    if what in ("add", "delete") and not (value and all(
            isinstance(x, list) and x and all(isinstance(a, str) and a for a in x) for x in value)):
        raise f.error(what, f"expected a non-empty list of facts (lists of non-empty strings), got {value!r}")
    out = {"what": what, "value": value, "note": f.string("note", "", empty=True)}
    if "after" in f:
        out["after"] = f.string("after")
    return out


def _check_agents(top: Table, actions: tuple[TimedAction, ...]) -> None:
    """Agents are ``d1``, ``d2``, … in request order; one can only be changed once requested."""
    request_times = [a.t for a in actions if a.kind == "request"]
    agents = [f"d{k}" for k in range(1, len(request_times) + 1)]
    for a in actions:
        key = "after" if a.kind == "world" else "agent"
        if a.kind not in ("terminate", "change") and key not in a.fields:
            continue
        agent = a.fields[key]
        f = located(top, a)
        k = int(agent[1:]) if agent[:1] == "d" and agent[1:].isdigit() else 0
        if not 1 <= k <= len(request_times):
            raise f.error(key, f"no agent {agent!r}{suggest(agent, agents)}: agents are d1..d{len(agents)} "
                               "in request order")
        if a.kind == "world":
            continue  # it waits for the agent's task to finish, whenever that is
        if request_times[k - 1] > a.t:
            raise f.error("agent", f"agent {agent!r} at t={a.t:g} is requested only at t={request_times[k - 1]:g}: "
                                   "a task must be requested before it is changed or terminated")
