"""Hand-made trace events for tests: only what a test is about, the rest filled in.

A test writes the fields it cares about (``{"t": 2, "event": "end", "agent": "d1", "cause":
"failed"}``); :func:`complete` adds every other field an event of that kind must have
(``tasker.events``), with neutral values, so the hand-made trace reads as a real one does.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

from tasker import fsm

_DEFAULTS: dict[str, dict[str, Any]] = {
    "request": {"task_type": "task", "args": {}, "requester": "user"},
    "stage": {"fsm": "exeTsk", "index": 0, "action": "act", "args": [], "kind": "suspendable"},
    "plan": {"purpose": "upTsk", "strategy": "planned", "stages": []},
    "decision": {"algorithm": "alg2", "switch": False},
    "roles": {"exeDA": None, "irrDA": None, "idleDA": []},
    "hazard": {"budget_s": 0.0, "severity": 1.0},
    "role": {"person": "someone"},
    "world": {"value": None, "note": ""},
    "change": {"args": {}},
    "secure": {},
    "mode": {"mode": "IT"},
}


def _trigger(source: str, target: str) -> str:
    return next((t.event for t in fsm.TRANSITIONS if t.source.value == source and t.target.value == target), "error")


def complete(record: Mapping[str, Any]) -> dict[str, Any]:
    """``record`` with every field its kind requires (see the module docstring)."""
    e = dict(record)
    kind = e["event"]
    for key, value in _DEFAULTS.get(kind, {}).items():
        e.setdefault(key, value)
    if kind == "transition":
        e.setdefault("trigger", _trigger(e["from"], e["to"]))
    elif kind == "end":
        e.setdefault("task_type", "task")
        e.setdefault("cause", "finished")
        e.setdefault("reason", "finished" if e["cause"] == "finished" else e["cause"])
    elif kind == "hazard":
        e.setdefault("fact", [e.get("hazard", "h"), *e.get("args", [])])
        e.setdefault("args", list(e["fact"][1:]))
        e.setdefault("agent", None)
    elif kind == "run":
        if "status" in e:
            e.setdefault("active", [])
        else:
            for key, value in (("seed", 0), ("scheduler", "alg2"), ("mode", "IT"), ("sFreq", 1.0), ("repRate", 1.0),
                               ("taskExeRate", 10.0), ("SPupRate", 1.0), ("update", "planned"),
                               ("suspension", "planned")):
                e.setdefault(key, value)
    return e


def completed(records: Iterable[Mapping[str, Any]]) -> list[dict[str, Any]]:
    return [complete(r) for r in records]
