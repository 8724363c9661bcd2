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
The trace is read once, as a :class:`~experiments.trace.timeline.Timeline`.  Decision
values may be ``inf`` (written as the string ``"inf"``): every number is read through
:func:`num`, and a non-finite comparison never counts as a cost-decided step.
``docs/paper.md`` explains each step; ``experiments/paper/report.py`` tabulates them.  The
numbers are in the cost model's units: seconds for ours, metres for the original
(``cost_model = "taskER-2019"``).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from experiments.trace.timeline import Timeline, timeline
from tasker import events as ev

Source = Timeline | Iterable[ev.Event | Mapping[str, Any]]


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


def _start(tl: Timeline, agent: str, after: float) -> ev.CommandSent | None:
    """``agent``'s first ``start`` command at or after ``after``."""
    return next(iter(tl.commands_to(agent, "start", after)), None)


def _switch(tl: Timeline, after: float, dac: str, exe: str, rule: str) -> tuple[ev.Decision | None,
                                                                                ev.CommandSent | None]:
    """The first switching decision ``dac`` over ``exe`` by ``rule`` at or after ``after``, and ``dac``'s start."""
    d = next(iter(tl.decisions_by(rule=rule, dac=dac, exe=exe, switched=True, after=after)), None)
    if d is None:
        return None, None
    return d, _start(tl, dac, d.t)


def _closest(tl: Timeline, after: float, dac: str, exe: str) -> ev.Decision | None:
    """The finite cost comparison of ``dac`` over ``exe`` at or after ``after`` with the lowest
    ``c_switch / c_wait`` (the one that came closest to switching), or None."""
    best: tuple[float, float] | None = None
    found = None
    for d in tl.decisions_by(rule="cost", dac=dac, exe=exe, after=after):
        cs, cw = num(d.get("c_switch")), num(d.get("c_wait"))
        if math.isfinite(cs) and math.isfinite(cw) and cw > 0 and (best is None or (cs / cw, d.t) < best):
            best, found = (cs / cw, d.t), d
    return found


def _compared(d: ev.Decision | None) -> tuple[bool, float | None, float | None, str]:
    """Is ``d`` a finite cost comparison that switched, and its numbers."""
    if d is None:
        return False, None, None, "no such decision"
    cs, cw, h = num(d.get("c_switch")), num(d.get("c_wait")), num(d.get("hysteresis", 1.0))
    finite = math.isfinite(cs) and math.isfinite(cw)
    ok = finite and cs < (h if math.isfinite(h) else 1.0) * cw
    return ok, cs, cw, f"c_switch={_fmt(cs)} < {_fmt(h)}·c_wait={_fmt(cw)}" if ok else \
        f"not a finite comparison won: c_switch={_fmt(cs)}, c_wait={_fmt(cw)}"


def _last_stage(tl: Timeline, agent: str, before: float) -> tuple[str, str] | None:
    """``agent``'s last ``exeTsk`` stage event at or before ``before``: (action, begin or how it closed)."""
    a = tl.agents.get(agent)
    last: tuple[float, str, str] | None = None
    for r in (a.stages if a else []):
        if r.fsm != "exeTsk":
            continue
        if r.begin <= before:
            last = (r.begin, r.action, "begin")
        if r.end is not None and r.end <= before:
            last = (r.end, r.action, r.status)
    return (last[1], last[2]) if last else None


def _role_at(tl: Timeline, t: float, agent: str, role: str) -> bool:
    """Whether ``agent``'s person had ``role`` at time ``t`` (the last role edge at or before it)."""
    a = tl.agents.get(agent)
    return a is not None and a.person_role_at(role, t)


def _apologies(tl: Timeline, agent: str) -> frozenset[str]:
    """The actions ``agent``'s task folder runs instead of a stage after a suspension (Alg. 3).

    Read from the folder the trace's ``request`` names (``[static] update``'s ``suspended``),
    so no action is named here.
    """
    from planners.bundled import task_types
    from planners.pddl_task import PddlTaskType

    a = tl.agents.get(agent)
    if a is None:
        return frozenset()
    for tt in task_types():
        if isinstance(tt, PddlTaskType) and tt.name == a.task_type:
            return frozenset(st.suspended for st in tt.spec.static_update if st.suspended)
    return frozenset()


def _plan_after(tl: Timeline, agent: str, purpose: str, after: float) -> ev.PlanMade | None:
    a = tl.agents.get(agent)
    return next((p for p in (a.plans if a else []) if p.purpose == purpose and p.t >= after), None)


def check(source: Source) -> list[Step]:
    """The steps of Appendix B in order; each later step is searched after the one before."""
    tl = timeline(source)
    steps: list[Step] = []
    t = 0.0

    start = next((c for c in tl.commands if c.flag == "start"), None)
    ok = start is not None and start.agent == "d1"
    steps.append(Step("guide John (d1) starts", ok, start.t if start else None,
                      f"first start goes to {start.agent if start else 'nobody'}"))

    # 2. guide Alice takes over on cost; d1 (John not greeted) suspends with `save`
    d2_dec, s = _switch(tl, t, "d2", "d1", "cost")
    won, cs, cw, why = _compared(d2_dec)
    saved = _plan_after(tl, "d1", "genSusp", d2_dec.t) if d2_dec is not None else None
    # eq. 47's save: nothing to do to suspend (John was not greeted, so he is not told to wait)
    is_save = saved is not None and not saved.stages and d2_dec is not None and not _role_at(
        tl, d2_dec.t, "d1", "told_to_wait") and not _role_at(tl, d2_dec.t, "d1", "following")
    steps.append(Step("guide Alice (d2) takes over: c_switch < c_wait; guide John suspends with save",
                      s is not None and won and is_save, s.t if s else None,
                      f"{why}; d1 genSusp stages: {list(saved.stages) if saved else None} "
                      f"({saved.note if saved else None})",
                      cs, cw))
    t = s.t if s else t

    # 3. John walked: d1's cTime fell since it lost the robot, and that wins the comparison
    d, s = _switch(tl, t, "d1", "d2", "cost")
    if d is None:  # it did not happen: show the comparison that came closest, and how far it was
        d = _closest(tl, t, "d1", "d2")
    won, cs, cw, why = _compared(d)
    before = num(d2_dec.get("cTime_exeDA")) if d2_dec else math.nan
    after = num(d.get("cTime_dac")) if d else math.nan
    cheaper = math.isfinite(before) and math.isfinite(after) and after < before
    resumed = _plan_after(tl, "d1", "upTsk", s.t) if s is not None else None
    apologies = _apologies(tl, "d1")
    apologises = resumed is not None and any(st.get("action") in apologies for st in resumed.stages)
    where = "" if s is not None or d is None else f"no switch; closest at t={_fmt(d.t)}: "
    steps.append(Step("John walked toward his destination: guide John (d1) takes back over",
                      s is not None and won and cheaper and apologises, s.t if s else None,
                      f"{where}{why}; d1 cTime {_fmt(before)} when suspended, {_fmt(after)} at this decision; "
                      f"resumes with the apology {sorted(apologies)}: {apologises}", cs, cw))
    t = s.t if s else t

    # 4. Peter fell preempts by class while John follows the robot; John is asked to wait
    d, s = _switch(tl, t, "d3", "d1", "priority class")
    following = False
    told: float | None = None
    if d is not None:
        # read from the trace's role edges, which the task folder declares: no task or action names here
        following = _role_at(tl, d.t, "d1", "following")
        john = tl.agents.get("d1")
        told = min((r.start for r in (john.person_roles if john else []) if r.role == "told_to_wait"
                    and r.start >= d.t), default=None)
    stage = _last_stage(tl, "d1", d.t) if d is not None else None
    ok = s is not None and following and told is not None and told <= s.t
    steps.append(Step("Peter fell (d3) preempts guide John at once while John is guided; John is asked to wait",
                      ok, s.t if s else None,
                      f"John following d1 at the decision: {following} (d1's stage: "
                      f"{stage[0] if stage else None} {stage[1] if stage else None}); "
                      f"told to wait at {told}"))
    t = s.t if s else t

    # 5. Sara fell wins the comparison: her task is the shorter one
    d, s = _switch(tl, t, "d4", "d3", "cost")
    won, cs, cw, why = _compared(d)
    shorter = d is not None and num(d.get("cTime_dac")) < num(d.get("cTime_exeDA"))
    steps.append(Step("Sara fell (d4) takes over from Peter fell after comparing costs", s is not None and won
                      and shorter, s.t if s else None,
                      f"{why}; cTime d4 {_fmt(num(d.get('cTime_dac')))} vs d3 {_fmt(num(d.get('cTime_exeDA')))}"
                      if d else why, cs, cw))
    t = s.t if s else t

    # 6. Peter gets up while d3 waits: d3 ends itself from wait
    up = next((w for w in tl.world if w.value == ["peter", "standing"] and w.t >= t), None)
    peter = tl.agents.get("d3")
    w = next((x for x in (peter.transitions if peter else []) if x.target == "end"), None)
    end = peter.end if peter else None
    restarted = any(c.t > t for c in tl.commands_to("d3", "start"))
    ok = (up is not None and w is not None and w.source == "wait" and w.t >= up.t
          and end is not None and "fine" in end.reason and end.cause == "self" and not restarted)
    steps.append(Step("Peter fell (d3) ends while waiting: Peter is fine", ok, w.t if w else None,
                      f"Peter up at {up.t if up else None}; d3 ended from {w.source if w else None}: "
                      f"{end.reason if end else None} ({end.cause if end else None})"))

    ends = {a: (tl.agents[a].end if a in tl.agents else None) for a in ("d1", "d2", "d4")}
    rest = {a: (e.reason if e is not None else None) for a, e in ends.items()}
    steps.append(Step("the rest complete", all(r == "finished" for r in rest.values()),
                      max((e.t for e in ends.values() if e is not None), default=None), f"end reasons: {rest}"))
    return steps
