"""``tasker explain RUN_DIR --agent dN [--at T]``: what an agent planned from, and what moved it.

A run's ``problems/`` folder (written by :func:`write_problems` from the journal of
:func:`planners.pddl_task.planning_journal`) holds, for every planned upTsk and
genSusp — solved or not — the domain and the problem as PDDL that any planner, and
unified-planning's default ``PDDLReader``, reads; ``index.json`` lists them by agent,
simulated time and purpose.  :func:`explain` picks the problem in force for an agent
at a time and pairs it with the trace events that moved the agent: ``decision``,
``command``, ``transition`` and ``end``.  "At a time" means the instant the trace shows
there: what happened at ``T`` and what the loop did at once in answer, one tick after
another (:func:`instant_end`) — a request at 40.0, the decision and ``susp`` at 40.001,
``genSusp`` planned at 40.002 are all "at 40".

A run folder is data someone may send: it is read only inside itself.  Every file
``index.json`` names is resolved inside ``problems/`` (an absolute path, ``..`` or a link
leading out is refused, never read or copied), every file is read within the readers'
limits (:mod:`tasker.support.reader`: a regular file, UTF-8, nesting, 64-bit numbers),
and a damaged one is named as damaged.
"""

from __future__ import annotations

import bisect
import difflib
import json
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from experiments.trace.timeline import Timeline
from tasker import events as ev
from tasker.errors import ExplainError as ExplainError  # defined there; re-exported here
from tasker.support import reader

if TYPE_CHECKING:
    from planners.pddl_task import PlanningRecord

PROBLEMS = "problems"
INDEX = "index.json"
MOVING_EVENTS = (ev.Decision, ev.CommandSent, ev.Transition, ev.TaskEnded)
"""The trace events that move an agent, which :func:`explain` lists."""
TICK_S = 0.001
"""The loop's tick (:class:`tasker.loop.SimulationLoop`'s default resolution): a message between the
harmoniser and an agent takes one, so what answers an event at ``T`` happens at ``T`` + 1, 2, … ms."""


# ----------------------------------------------------------------------------------------- writing


def _plan_text(steps: Iterable[Sequence[str]], cost: float | None) -> str:
    """A plan as Fast Downward writes one: ``(action arg …)`` per line, then the cost."""
    lines = [f"({' '.join(s)})" for s in steps]
    if cost is not None and math.isfinite(cost):
        lines.append(f"; cost = {cost:g}")
    return "\n".join(lines) + "\n"


@dataclass(frozen=True)
class ProblemEntry:
    """One planning call of a run, as ``problems/index.json`` lists it: when, by whom, why
    (``purpose``, ``label``), how it ended (``status``, ``message``), the files of its domain, problem
    and plan (names inside ``problems/``), the names the portable PDDL renamed, the plan's steps in
    the task's own names and its cost (``"inf"`` as a string when infinite)."""

    n: int
    t: float
    agent: str
    task_type: str
    purpose: str
    label: str
    status: str
    domain: str
    problem: str
    renamed: Mapping[str, str]
    message: str
    plan: tuple[tuple[str, ...], ...] | None
    cost: float | str | None
    plan_file: str | None = None

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "n": self.n, "t": self.t, "agent": self.agent, "task_type": self.task_type, "purpose": self.purpose,
            "label": self.label, "status": self.status, "domain": self.domain, "problem": self.problem,
            "renamed": dict(sorted(self.renamed.items())), "message": self.message,
            "plan": [list(s) for s in self.plan] if self.plan is not None else None,
            "cost": self.cost,
        }
        if self.plan_file is not None:
            out["plan_file"] = self.plan_file
        return out

    @staticmethod
    def json_cost(cost: float | None) -> float | str | None:
        """A cost as the index holds it: a finite number, None, or ``"inf"`` (JSON has no infinity)."""
        return cost if cost is None or math.isfinite(cost) else str(cost)

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> ProblemEntry:
        """An entry :func:`experiments.report.explain.load_index` has checked (its strings and ``t``)."""
        plan = data.get("plan")
        return cls(n=int(data.get("n", 0)), t=float(data["t"]), agent=data["agent"], task_type=data["task_type"],
                   purpose=data["purpose"], label=data.get("label") or "", status=data["status"],
                   domain=data["domain"], problem=data["problem"], renamed=dict(data.get("renamed") or {}),
                   message=data.get("message") or "",
                   plan=None if plan is None else tuple(tuple(str(a) for a in s) for s in plan),
                   cost=data.get("cost"), plan_file=data.get("plan_file"))


def write_problems(out: Path, journal: Sequence[PlanningRecord]) -> Path | None:
    """Write a run's planning journal (:class:`planners.pddl_task.PlanningRecord`) to ``out``:
    ``<task_type>.domain.pddl``, ``NNN_<agent>_<purpose>.pddl`` (and ``.plan`` when solved)
    and ``index.json``.  Returns ``out``, or None when nothing was planned."""
    if not journal:
        return None
    out.mkdir(parents=True, exist_ok=True)
    index: list[ProblemEntry] = []
    for n, r in enumerate(journal, start=1):
        domain_file = f"{r.task_type}.domain.pddl"
        (out / domain_file).write_text(r.pddl.domain, encoding="utf-8")
        stem = f"{n:03d}_{r.agent}_{r.purpose}"
        (out / f"{stem}.pddl").write_text(r.pddl.problem, encoding="utf-8")
        if r.plan is not None:
            (out / f"{stem}.plan").write_text(_plan_text((r.pddl.written(s) for s in r.plan), r.cost),
                                              encoding="utf-8")
        index.append(ProblemEntry(n, r.t, r.agent, r.task_type, r.purpose, r.label, r.status, domain_file,
                                  f"{stem}.pddl", r.pddl.renamed, r.message, r.plan, ProblemEntry.json_cost(r.cost),
                                  plan_file=None if r.plan is None else f"{stem}.plan"))
    (out / INDEX).write_text(json.dumps([e.to_json() for e in index], indent=1, sort_keys=True) + "\n",
                             encoding="utf-8")
    return out


# ----------------------------------------------------------------------------------------- reading


@dataclass(frozen=True)
class Explanation:
    """What :func:`explain` found: the planning call in force and the events that moved the agent."""

    agent: str
    at: float | None
    entry: ProblemEntry
    domain: str
    problem: str
    plan: str | None
    events: tuple[ev.Event, ...]
    until: float | None = None
    """The end of the instant ``at`` (:func:`instant_end`); None without ``at``."""

    def text(self) -> str:
        """The explanation as one readable text (what ``tasker explain`` prints)."""
        e = self.entry
        plan = self.plan if self.plan is not None else f"; no plan: {e.status}" + (
            f" ({e.message})" if e.message else "") + "\n"
        head = [f"; {self.agent} ({e.task_type}): {e.purpose} at t={e.t:g} s, {e.status}"
                + (f" [{e.label}]" if e.label else ""),
                f"; files: {PROBLEMS}/{e.domain}, {PROBLEMS}/{e.problem}"]
        if self.at is not None and self.until is not None and self.until > self.at:
            head.append(f"; at t={self.at:g} s: with what the loop did at once in answer, up to t={self.until:g} s")
        return "\n".join([*head, "", "; ---- domain", self.domain.rstrip(), "", "; ---- problem",
                          self.problem.rstrip(), "", "; ---- plan", plan.rstrip(), "",
                          "; ---- what moved the agent (trace)", *_event_lines(self.events)]) + "\n"


def _event_lines(events: Sequence[ev.Event]) -> list[str]:
    """One line per event; a run of decisions that kept the same pair and did not switch is
    shown by its first and last line and a count (Alg. 2 decides every period)."""
    out: list[str] = []
    i = 0

    def key(e: ev.Event) -> tuple[Any, ...] | None:
        return (e.dac, e.exe_da, e.rule) if isinstance(e, ev.Decision) and not e.switch else None

    while i < len(events):
        e = events[i]
        j = i
        same = key(e)
        if same is not None:
            while j + 1 < len(events) and key(events[j + 1]) == same:
                j += 1
        out.append(_event_line(e))
        if j > i + 1:
            out.append(f"{'':12} … {j - i - 1} more decisions like it, no switch")
        if j > i:
            out.append(_event_line(events[j]))
        i = j + 1
    return out


def _event_line(e: ev.Event) -> str:
    t = f"t={e.t:10.3f}"
    if isinstance(e, ev.Transition):
        return f"{t} transition {e.source} -> {e.target}"
    if isinstance(e, ev.CommandSent):
        return f"{t} command {e.flag}"
    if isinstance(e, ev.TaskEnded):
        return f"{t} end ({e.cause}): {e.reason}"
    fields = e.fields()
    shown = ", ".join(f"{k}={_short(v)}" for k, v in fields.items() if k != "algorithm")
    return f"{t} {e.KIND} [{fields.get('algorithm', '?')}] {shown}"


def _short(v: Any) -> str:
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


MAX_RECORDS = 100_000
"""The most planning records an ``index.json`` may list (a day of planning is a few thousand)."""


def _inside(root: Path, name: str, what: str) -> Path:
    """``root/name`` for a file of the run folder ``root`` (already resolved), or an :class:`ExplainError`:
    a run folder is data someone may send, so it is read only inside itself — an absolute path, a
    ``..`` or a link that leads out of it is refused, never followed."""
    if not name or "\x00" in name:
        raise ExplainError(root, f"expected a file name of the run folder, got {name!r}", field=what)
    p = Path(name)
    if p.is_absolute():
        raise ExplainError(root, f"{name!r} is an absolute path: a run folder names only its own files, and "
                                 "this one is not read", field=what)
    target = (root / p).resolve()
    if not target.is_relative_to(root):
        raise ExplainError(root, f"{name!r} leads out of the run folder (to {target}): a run folder names only "
                                 "its own files, and this one is not read", field=what)
    return target


def _read(root: Path, name: str, what: str) -> str:
    """A text file of the run folder (inside it, a regular file within the readers' limits, UTF-8)."""
    return reader.read_text(_inside(root, name, what), ExplainError)


def _root(run_dir: Path) -> Path:
    if not run_dir.is_dir():
        raise ExplainError(f"{run_dir}: no such run folder (give the --out folder of `tasker run`)")
    return run_dir.resolve()


def load_index(run_dir: Path) -> list[dict[str, Any]]:
    """The ``problems/index.json`` of a run folder, with clear errors for what is missing or damaged."""
    root = _root(run_dir)
    path = run_dir / PROBLEMS / INDEX
    if not path.exists() and not path.is_symlink():
        raise ExplainError(f"{path}: no planning record: the run planned nothing with the planned strategy "
                           f"(static strategies write no PDDL), or was written before `problems/` existed")
    text = _read(root, f"{PROBLEMS}/{INDEX}", "index")
    index = reader.parse_json(text, path, ExplainError)
    if not isinstance(index, list):
        raise ExplainError(f"{path}: expected a list of planning records, got {_json_kind(index)}")
    if len(index) > MAX_RECORDS:
        raise ExplainError(f"{path}: {len(index)} planning records, more than the {MAX_RECORDS} a run folder may have")
    for i, entry in enumerate(index):
        why = _record_problem(entry)
        if why:
            raise ExplainError(f"{path}: record [{i}]: {why} (the file is damaged: run the scenario again)")
        for key in ("domain", "problem", "plan_file"):
            if entry.get(key) is not None:
                try:
                    _inside(root / PROBLEMS, entry[key], key)
                except ExplainError as exc:
                    raise ExplainError(f"{path}: record [{i}]: {key}: {exc.message}") from None
    return index


_RECORD_STRINGS = ("agent", "task_type", "purpose", "status", "domain", "problem")


def _record_problem(entry: Any) -> str | None:
    """Why ``entry`` is not a planning record :func:`write_problems` writes, or ``None``."""
    if not isinstance(entry, dict):
        return f"expected a planning record (an object), got {_json_kind(entry)}"
    for key in _RECORD_STRINGS:
        if not isinstance(entry.get(key), str):
            return f"{key}: expected a string, got {_json_kind(entry.get(key)) if key in entry else 'nothing'}"
    t = entry.get("t")
    if isinstance(t, bool) or not isinstance(t, int | float) or not math.isfinite(t):
        return f"t: expected a finite number, got {_json_kind(t) if 't' in entry else 'nothing'}"
    for key in ("plan_file", "label", "message"):
        if entry.get(key) is not None and not isinstance(entry[key], str):
            return f"{key}: expected a string, got {_json_kind(entry[key])}"
    return None


def _json_kind(value: Any) -> str:
    """A JSON value as the file shows it: ``null``, ``5``, ``"x"``, an array, an object."""
    if isinstance(value, dict):
        return "an object"
    if isinstance(value, list):
        return "an array"
    return json.dumps(value)[:60]


def load_trace(run_dir: Path) -> Timeline:
    """The run's timeline (empty if it has no trace); a damaged trace — or a ``trace.jsonl`` that is a
    folder, a device or a link out of the run folder — is an :class:`ExplainError`."""
    path = run_dir / "trace.jsonl"
    if not path.exists() and not path.is_symlink():
        return Timeline([])
    inside = _inside(_root(run_dir), "trace.jsonl", "trace")
    try:
        return Timeline.read(inside)
    except ValueError as exc:
        raise ExplainError(str(exc).replace(str(inside), str(path), 1)) from None


def instant_end(tl: Timeline, at: float) -> float:
    """The last time of the instant ``at``.  When something happened at ``at`` (or ``at`` falls inside
    such an instant), the instant goes on over the events that follow tick after tick (:data:`TICK_S`)
    without a pause: a request at 40.0 is decided at 40.001 and the executing agent plans its
    suspension at 40.002, so a user asking about t = 40 means that genSusp, which the trace shows
    there, not the plan the agent had before.  The next pause (here the planning time) ends it.
    When nothing happened at ``at``, the instant is ``at`` alone."""
    gap = TICK_S * 1.5  # more than one tick: a pause (1.5: the float noise of a time in seconds)
    times = [e.t for e in tl.events]
    i = bisect.bisect_right(times, at)
    if i == 0 or at - times[i - 1] > gap:
        return at
    end = at
    for t in times[i:]:
        if t - end > gap:
            break
        end = t
    return end


def moved(tl: Timeline, agent: str, until: float | None = None) -> list[ev.Event]:
    """The decision, command, transition and end events about ``agent`` (up to ``until``)."""
    out: list[ev.Event] = []
    for e in tl.events:
        if until is not None and e.t > until:
            break
        if not isinstance(e, MOVING_EVENTS):
            continue
        if isinstance(e, ev.Decision):
            if agent in (e.dac, e.exe_da):
                out.append(e)
        elif e.agent == agent:
            out.append(e)
    return out


def explain(run_dir: str | Path, agent: str, at: float | None = None) -> Explanation:
    """The problem ``agent`` planned from at time ``at`` (default: its last), its plan and the
    events that moved it; raises :class:`ExplainError` naming what is wrong."""
    run = Path(run_dir)
    index = load_index(run)
    agents = sorted({str(e["agent"]) for e in index}, key=lambda a: (len(a), a))
    mine = [e for e in index if e["agent"] == agent]
    if not mine:
        near = difflib.get_close_matches(agent, agents, n=1)
        hint = f"; did you mean {near[0]!r}?" if near else ""
        raise ExplainError(f"{run / PROBLEMS / INDEX}: agent {agent!r} planned nothing; agents that planned: "
                           f"{', '.join(agents)}{hint}")
    timeline = load_trace(run)
    until = None if at is None else instant_end(timeline, at)
    # the index keeps the loop's float times (0.1 + 0.2 …), the trace rounds to 1 µs: compare as the trace writes
    chosen = [e for e in mine if until is None or round(float(e["t"]), 6) <= round(until, 6)]
    if not chosen:
        times = ", ".join(f"{float(e['t']):g}" for e in mine)
        raise ExplainError(f"{run / PROBLEMS / INDEX}: {agent} had not planned yet at t={at:g} s; it planned at "
                           f"t = {times}")
    entry = ProblemEntry.from_json(chosen[-1])
    folder = _root(run) / PROBLEMS
    domain = _read(folder, entry.domain, "domain")
    problem = _read(folder, entry.problem, "problem")
    plan = _read(folder, entry.plan_file, "plan_file") if entry.plan_file else None
    return Explanation(agent, at, entry, domain, problem, plan, tuple(moved(timeline, agent, until)), until)


def write(ex: Explanation, out: Path) -> list[Path]:
    """``domain.pddl``, ``problem.pddl``, ``plan`` (if any) and ``explain.txt`` in ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    files = [out / "domain.pddl", out / "problem.pddl"]
    files[0].write_text(ex.domain, encoding="utf-8")
    files[1].write_text(ex.problem, encoding="utf-8")
    if ex.plan is not None:
        files.append(out / "plan")
        files[-1].write_text(ex.plan, encoding="utf-8")
    files.append(out / "explain.txt")
    files[-1].write_text(ex.text(), encoding="utf-8")
    return files


# ----------------------------------------------------------------------------------------- command
