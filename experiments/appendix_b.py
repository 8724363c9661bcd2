"""The sequence of the paper's Appendix B, checked on a trace.

:func:`check` walks a trace of the paper scenario (``tasker run paper``) and returns
one :class:`Step` per step of Appendix B, each with the time it happened and the
events that show it, or why it was not found.  What a person does (follows the robot,
is told to wait) is read from the trace's ``role`` events, which the task folders
declare, never from action names.  ``docs/paper.md`` explains each
step; the end-to-end test asserts they all hold, in order.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

Event = Mapping[str, Any]


@dataclass(frozen=True)
class Step:
    name: str
    ok: bool
    t: float | None
    detail: str


def _first(events: Sequence[Event], after: float, **match: Any) -> Event | None:
    for e in events:
        if e["t"] >= after and all(e.get(k) == v for k, v in match.items()):
            return e
    return None


def _switch(events: Sequence[Event], after: float, dac: str, exe: str, rule: str) -> tuple[Event | None, Event | None]:
    d = next((e for e in events if e["event"] == "decision" and e["t"] >= after and e.get("dac") == dac
              and e.get("exeDA") == exe and e.get("rule") == rule and e.get("switch")), None)
    if d is None:
        return None, None
    return d, _first(events, d["t"], event="command", agent=dac, flag="start")


def _role_at(events: Sequence[Event], t: float, agent: str, role: str) -> bool:
    """Whether ``agent``'s person had ``role`` at time ``t`` (the last role edge before it)."""
    edges = [e for e in events if e["event"] == "role" and e["t"] <= t and e.get("agent") == agent
             and e.get("role") == role]
    return bool(edges) and edges[-1].get("status") == "on"


def check(events: Sequence[Event]) -> list[Step]:
    """The steps of Appendix B in order; each later step is searched after the one before."""
    steps: list[Step] = []
    t = 0.0

    start = _first(events, 0.0, event="command", flag="start")
    ok = start is not None and start["agent"] == "d1"
    steps.append(Step("guide John (d1) starts", ok, start["t"] if start else None,
                      f"first start goes to {start['agent'] if start else 'nobody'}"))

    d, s = _switch(events, t, "d2", "d1", "cost")
    steps.append(Step("guide Alice (d2) takes over: c_switch < c_wait", s is not None, s["t"] if s else None,
                      f"c_switch={d['c_switch']:.1f} < c_wait={d['c_wait']:.1f}" if d else "no such decision"))
    t = s["t"] if s else t

    d, s = _switch(events, t, "d1", "d2", "cost")
    worked = d is not None and any(e["event"] == "stage" and e.get("agent") == "d2" and e.get("fsm") == "exeTsk"
                                   and e.get("status") == "done" and t <= e["t"] <= d["t"] for e in events)
    steps.append(Step("John walked toward his destination: guide John (d1) takes back over", s is not None and worked,
                      s["t"] if s else None,
                      f"c_switch={d['c_switch']:.1f} < c_wait={d['c_wait']:.1f}" if d else "no such decision"))
    t = s["t"] if s else t

    d, s = _switch(events, t, "d3", "d1", "priority class")
    following = told = None
    if d is not None:
        # read from the trace's role edges, which the task folder declares: no task or action names here
        following = _role_at(events, d["t"], "d1", "following")
        told = next((e for e in events if e["event"] == "role" and e["t"] >= d["t"] and e.get("agent") == "d1"
                     and e.get("role") == "told_to_wait" and e.get("status") == "on"), None)
    ok = s is not None and following is True and told is not None
    steps.append(Step("Peter fell (d3) preempts guide John at once while John is guided; John is asked to wait",
                      ok, s["t"] if s else None,
                      f"John following d1 at the decision: {following}; told to wait at {told['t'] if told else None}"))
    t = s["t"] if s else t

    d, s = _switch(events, t, "d4", "d3", "cost")
    steps.append(Step("Sara fell (d4) takes over from Peter fell after comparing costs", s is not None,
                      s["t"] if s else None,
                      f"c_switch={d['c_switch']:.1f} < c_wait={d['c_wait']:.1f}" if d else "no such decision"))
    t = s["t"] if s else t

    w = next((e for e in events if e["event"] == "transition" and e.get("agent") == "d3" and e.get("to") == "end"),
             None)
    end = _first(events, 0.0, event="end", agent="d3")
    ok = w is not None and w.get("from") == "wait" and end is not None and "fine" in str(end.get("reason"))
    steps.append(Step("Peter fell (d3) ends while waiting: Peter is fine", ok, w["t"] if w else None,
                      f"d3 ended from {w.get('from') if w else None}: {end.get('reason') if end else None}"))

    ends = {e["agent"]: e for e in events if e["event"] == "end"}
    rest = {a: ends.get(a, {}).get("reason") for a in ("d1", "d2", "d4")}
    steps.append(Step("the rest complete", all(r == "finished" for r in rest.values()),
                      max((ends[a]["t"] for a in rest if a in ends), default=None), f"end reasons: {rest}"))
    return steps
