"""The sequence of the paper's Appendix B, checked on a trace: order *and* causes.

:func:`check` walks a trace of the paper scenario (``tasker run paper``) and returns
one :class:`Step` per step of Appendix B, each with the time it happened, what shows
it, and — for the steps Alg. 2 decides by comparing costs — the decision's ``c_switch``
and ``c_wait`` and its margin ``1 - c_switch / c_wait``.  A step holds only when its
cause shows in the trace too:

* guide Alice takes over by a finite cost comparison, and guide John is suspended with
  eq. 47's *save* (John was not greeted yet);
* guide John takes back over by a finite cost comparison *because his task got
  cheaper*: its ``cTime`` at that decision is below its ``cTime`` when it lost the
  robot (John walked toward his destination), and its new plan greets him again with
  the apology its task folder declares for a suspended task (Alg. 3: the ``suspended``
  variant of a ``[static] update`` stage);
* Peter fell preempts by priority class while John follows the robot, and the
  suspension asks John to wait (eq. 47's *apologise*);
* Sara fell wins a finite cost comparison because her task is the shorter one;
* Peter fell ends from ``wait`` after the world says Peter got up, by itself
  (``cause: "self"``), without ever having been started again.

What a person does (follows the robot, is told to wait, waits) is read from the
trace's ``role`` events, which the task folders declare, never from action names.
Trace values may be ``inf`` (written as the string ``"inf"``): every number is read
through :func:`num`, and a non-finite comparison never counts as a cost-decided step.
``docs/paper.md`` explains each step; ``experiments/paper/report.py`` tabulates them.
"""

from __future__ import annotations

import math
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
    c_switch: float | None = None
    c_wait: float | None = None

    @property
    def margin(self) -> float | None:
        """``1 - c_switch / c_wait`` of the deciding comparison (None without one, or if not finite)."""
        if self.c_switch is None or self.c_wait is None or not (math.isfinite(self.c_switch)
                                                               and math.isfinite(self.c_wait)) or self.c_wait <= 0:
            return None
        return 1.0 - self.c_switch / self.c_wait


def num(value: Any) -> float:
    """A trace number: floats, ints, and the strings ``"inf"``/``"-inf"``/``"nan"``; anything else is NaN."""
    if isinstance(value, bool):
        return math.nan
    if isinstance(value, int | float):
        return float(value)
    if isinstance(value, str):
        try:
            return float(value)
        except ValueError:
            return math.nan
    return math.nan


def _fmt(x: float) -> str:
    return f"{x:.1f}" if math.isfinite(x) else str(x)


def _first(events: Sequence[Event], after: float, **match: Any) -> Event | None:
    for e in events:
        if num(e.get("t")) >= after and all(e.get(k) == v for k, v in match.items()):
            return e
    return None


def _switch(events: Sequence[Event], after: float, dac: str, exe: str, rule: str) -> tuple[Event | None, Event | None]:
    """The first switching decision ``dac`` over ``exe`` by ``rule`` at or after ``after``, and ``dac``'s start."""
    d = next((e for e in events if e.get("event") == "decision" and num(e.get("t")) >= after
              and e.get("dac") == dac and e.get("exeDA") == exe and e.get("rule") == rule and e.get("switch")), None)
    if d is None:
        return None, None
    return d, _first(events, num(d["t"]), event="command", agent=dac, flag="start")


def _closest(events: Sequence[Event], after: float, dac: str, exe: str) -> Event | None:
    """The finite cost comparison of ``dac`` over ``exe`` at or after ``after`` with the lowest
    ``c_switch / c_wait`` (the one that came closest to switching), or None."""
    best: tuple[float, float] | None = None
    found = None
    for e in events:
        if (e.get("event") == "decision" and e.get("rule") == "cost" and e.get("dac") == dac
                and e.get("exeDA") == exe and num(e.get("t")) >= after):
            cs, cw = num(e.get("c_switch")), num(e.get("c_wait"))
            if math.isfinite(cs) and math.isfinite(cw) and cw > 0 and (best is None or (cs / cw, num(e["t"])) < best):
                best, found = (cs / cw, num(e["t"])), e
    return found


def _compared(d: Event | None) -> tuple[bool, float | None, float | None, str]:
    """Is ``d`` a finite cost comparison that switched, and its numbers."""
    if d is None:
        return False, None, None, "no such decision"
    cs, cw, h = num(d.get("c_switch")), num(d.get("c_wait")), num(d.get("hysteresis", 1.0))
    finite = math.isfinite(cs) and math.isfinite(cw)
    ok = finite and cs < (h if math.isfinite(h) else 1.0) * cw
    return ok, cs, cw, f"c_switch={_fmt(cs)} < {_fmt(h)}·c_wait={_fmt(cw)}" if ok else \
        f"not a finite comparison won: c_switch={_fmt(cs)}, c_wait={_fmt(cw)}"


def _last_stage(events: Sequence[Event], agent: str, before: float) -> Event | None:
    """``agent``'s last ``exeTsk`` stage event at or before ``before``."""
    return next((e for e in reversed(events) if e.get("event") == "stage" and e.get("agent") == agent
                 and e.get("fsm") == "exeTsk" and num(e.get("t")) <= before), None)


def _role_at(events: Sequence[Event], t: float, agent: str, role: str) -> bool:
    """Whether ``agent``'s person had ``role`` at time ``t`` (the last role edge at or before it)."""
    edges = [e for e in events if e.get("event") == "role" and num(e.get("t")) <= t and e.get("agent") == agent
             and e.get("role") == role]
    return bool(edges) and edges[-1].get("status") == "on"


def _apologies(events: Sequence[Event], agent: str) -> frozenset[str]:
    """The actions ``agent``'s task folder runs instead of a stage after a suspension (Alg. 3).

    Read from the folder the trace's ``request`` names (``[static] update``'s ``suspended``),
    so no action is named here.
    """
    from planners.bundled import task_types
    from planners.pddl_task import PddlTaskType

    req = next((e for e in events if e.get("event") == "request" and e.get("agent") == agent), None)
    if req is None:
        return frozenset()
    for tt in task_types():
        if isinstance(tt, PddlTaskType) and tt.name == req.get("task_type"):
            return frozenset(st.suspended for st in tt.spec.static_update if st.suspended)
    return frozenset()


def check(events: Sequence[Event]) -> list[Step]:
    """The steps of Appendix B in order; each later step is searched after the one before."""
    steps: list[Step] = []
    t = 0.0

    start = _first(events, 0.0, event="command", flag="start")
    ok = start is not None and start.get("agent") == "d1"
    steps.append(Step("guide John (d1) starts", ok, num(start["t"]) if start else None,
                      f"first start goes to {start.get('agent') if start else 'nobody'}"))

    # 2. guide Alice takes over on cost; d1 (John not greeted) suspends with `save`
    d2_dec, s = _switch(events, t, "d2", "d1", "cost")
    won, cs, cw, why = _compared(d2_dec)
    saved = None
    if d2_dec is not None:
        saved = next((e for e in events if e.get("event") == "plan" and e.get("agent") == "d1"
                      and e.get("purpose") == "genSusp" and num(e["t"]) >= num(d2_dec["t"])), None)
    # eq. 47's save: nothing to do to suspend (John was not greeted, so he is not told to wait)
    is_save = saved is not None and not saved.get("stages") and d2_dec is not None and not _role_at(
        events, num(d2_dec["t"]), "d1", "told_to_wait") and not _role_at(events, num(d2_dec["t"]), "d1", "following")
    steps.append(Step("guide Alice (d2) takes over: c_switch < c_wait; guide John suspends with save",
                      s is not None and won and is_save, num(s["t"]) if s else None,
                      f"{why}; d1 genSusp stages: {saved.get('stages') if saved else None} "
                      f"({saved.get('note') if saved else None})",
                      cs, cw))
    t = num(s["t"]) if s else t

    # 3. John walked: d1's cTime fell since it lost the robot, and that wins the comparison
    d, s = _switch(events, t, "d1", "d2", "cost")
    if d is None:  # it did not happen: show the comparison that came closest, and how far it was
        d = _closest(events, t, "d1", "d2")
    won, cs, cw, why = _compared(d)
    before = num(d2_dec.get("cTime_exeDA")) if d2_dec else math.nan
    after = num(d.get("cTime_dac")) if d else math.nan
    cheaper = math.isfinite(before) and math.isfinite(after) and after < before
    resumed = None
    if s is not None:
        resumed = next((e for e in events if e.get("event") == "plan" and e.get("agent") == "d1"
                        and e.get("purpose") == "upTsk" and num(e["t"]) >= num(s["t"])), None)
    apologies = _apologies(events, "d1")
    apologises = resumed is not None and any(st.get("action") in apologies for st in resumed.get("stages", ()))
    where = "" if s is not None or d is None else f"no switch; closest at t={_fmt(num(d['t']))}: "
    steps.append(Step("John walked toward his destination: guide John (d1) takes back over",
                      s is not None and won and cheaper and apologises, num(s["t"]) if s else None,
                      f"{where}{why}; d1 cTime {_fmt(before)} s when suspended, {_fmt(after)} s at this decision; "
                      f"resumes with the apology {sorted(apologies)}: {apologises}", cs, cw))
    t = num(s["t"]) if s else t

    # 4. Peter fell preempts by class while John follows the robot; John is asked to wait
    d, s = _switch(events, t, "d3", "d1", "priority class")
    following = False
    told = None
    if d is not None:
        # read from the trace's role edges, which the task folder declares: no task or action names here
        following = _role_at(events, num(d["t"]), "d1", "following")
        told = next((e for e in events if e.get("event") == "role" and num(e["t"]) >= num(d["t"])
                     and e.get("agent") == "d1" and e.get("role") == "told_to_wait" and e.get("status") == "on"), None)
    stage = _last_stage(events, "d1", num(d["t"])) if d is not None else None
    ok = s is not None and following and told is not None and num(told["t"]) <= num(s["t"])
    steps.append(Step("Peter fell (d3) preempts guide John at once while John is guided; John is asked to wait",
                      ok, num(s["t"]) if s else None,
                      f"John following d1 at the decision: {following} (d1's stage: "
                      f"{stage.get('action') if stage else None} {stage.get('status') if stage else None}); "
                      f"told to wait at {told['t'] if told else None}"))
    t = num(s["t"]) if s else t

    # 5. Sara fell wins the comparison: her task is the shorter one
    d, s = _switch(events, t, "d4", "d3", "cost")
    won, cs, cw, why = _compared(d)
    shorter = d is not None and num(d.get("cTime_dac")) < num(d.get("cTime_exeDA"))
    steps.append(Step("Sara fell (d4) takes over from Peter fell after comparing costs", s is not None and won
                      and shorter, num(s["t"]) if s else None,
                      f"{why}; cTime d4 {_fmt(num(d.get('cTime_dac')))} vs d3 {_fmt(num(d.get('cTime_exeDA')))}"
                      if d else why, cs, cw))
    t = num(s["t"]) if s else t

    # 6. Peter gets up while d3 waits: d3 ends itself from wait
    up = next((e for e in events if e.get("event") == "world" and e.get("value") == ["peter", "standing"]
               and num(e["t"]) >= t), None)
    w = next((e for e in events if e.get("event") == "transition" and e.get("agent") == "d3" and e.get("to") == "end"),
             None)
    end = _first(events, 0.0, event="end", agent="d3")
    restarted = any(e.get("event") == "command" and e.get("agent") == "d3" and e.get("flag") == "start"
                    and num(e["t"]) > t for e in events)
    ok = (up is not None and w is not None and w.get("from") == "wait" and num(w["t"]) >= num(up["t"])
          and end is not None and "fine" in str(end.get("reason")) and end.get("cause") == "self" and not restarted)
    steps.append(Step("Peter fell (d3) ends while waiting: Peter is fine", ok, num(w["t"]) if w else None,
                      f"Peter up at {up['t'] if up else None}; d3 ended from {w.get('from') if w else None}: "
                      f"{end.get('reason') if end else None} ({end.get('cause') if end else None})"))

    ends = {e["agent"]: e for e in events if e.get("event") == "end"}
    rest = {a: ends.get(a, {}).get("reason") for a in ("d1", "d2", "d4")}
    steps.append(Step("the rest complete", all(r == "finished" for r in rest.values()),
                      max((num(ends[a]["t"]) for a in rest if a in ends), default=None), f"end reasons: {rest}"))
    return steps
