"""``tasker explain RUN_DIR --agent dN [--at T]``: what an agent planned from, and what moved it.

A run's ``problems/`` folder (written by :func:`write_problems` from the journal of
:func:`planners.pddl_task.planning_journal`) holds, for every planned upTsk and
genSusp — solved or not — the domain and the problem as PDDL that any planner, and
unified-planning's default ``PDDLReader``, reads; ``index.json`` lists them by agent,
simulated time and purpose.  :func:`explain` picks the problem in force for an agent
at a time (the last one planned at or before it) and pairs it with the trace events
that moved the agent: ``decision``, ``command``, ``transition`` and ``end``.
"""

from __future__ import annotations

import argparse
import difflib
import json
import math
import sys
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tasker.errors import TaskerError
from tasker.support.cliargs import UsageError, non_negative_seconds
from tasker.trace import number, read

PROBLEMS = "problems"
INDEX = "index.json"
MOVING_EVENTS = ("decision", "command", "transition", "end")
"""The trace events that move an agent, which :func:`explain` lists."""


class ExplainError(TaskerError, ValueError):
    """A run folder, agent or time that ``tasker explain`` cannot explain."""


# ----------------------------------------------------------------------------------------- writing


def _plan_text(steps: Iterable[Sequence[str]], cost: float | None) -> str:
    """A plan as Fast Downward writes one: ``(action arg …)`` per line, then the cost."""
    lines = [f"({' '.join(s)})" for s in steps]
    if cost is not None and math.isfinite(cost):
        lines.append(f"; cost = {cost:g}")
    return "\n".join(lines) + "\n"


def write_problems(out: Path, journal: Sequence[Any]) -> Path | None:
    """Write a run's planning journal (:class:`planners.pddl_task.PlanningRecord`) to ``out``:
    ``<task_type>.domain.pddl``, ``NNN_<agent>_<purpose>.pddl`` (and ``.plan`` when solved)
    and ``index.json``.  Returns ``out``, or None when nothing was planned."""
    if not journal:
        return None
    out.mkdir(parents=True, exist_ok=True)
    index = []
    for n, r in enumerate(journal, start=1):
        domain_file = f"{r.task_type}.domain.pddl"
        (out / domain_file).write_text(r.pddl.domain, encoding="utf-8")
        stem = f"{n:03d}_{r.agent}_{r.purpose}"
        (out / f"{stem}.pddl").write_text(r.pddl.problem, encoding="utf-8")
        entry: dict[str, Any] = {
            "n": n, "t": r.t, "agent": r.agent, "task_type": r.task_type, "purpose": r.purpose,
            "label": r.label, "status": r.status, "domain": domain_file, "problem": f"{stem}.pddl",
            "renamed": dict(sorted(r.pddl.renamed.items())), "message": r.message,
            "plan": [list(s) for s in r.plan] if r.plan is not None else None,
            "cost": r.cost if r.cost is None or math.isfinite(r.cost) else str(r.cost),
        }
        if r.plan is not None:
            (out / f"{stem}.plan").write_text(_plan_text((r.pddl.written(s) for s in r.plan), r.cost),
                                              encoding="utf-8")
            entry["plan_file"] = f"{stem}.plan"
        index.append(entry)
    (out / INDEX).write_text(json.dumps(index, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    return out


# ----------------------------------------------------------------------------------------- reading


@dataclass(frozen=True)
class Explanation:
    """What :func:`explain` found: the planning call in force and the events that moved the agent."""

    agent: str
    at: float | None
    entry: Mapping[str, Any]
    domain: str
    problem: str
    plan: str | None
    events: tuple[Mapping[str, Any], ...]

    def text(self) -> str:
        """The explanation as one readable text (what ``tasker explain`` prints)."""
        e = self.entry
        plan = self.plan if self.plan is not None else f"; no plan: {e['status']}" + (
            f" ({e['message']})" if e.get("message") else "") + "\n"
        head = [f"; {self.agent} ({e['task_type']}): {e['purpose']} at t={e['t']:g} s, {e['status']}"
                + (f" [{e['label']}]" if e.get("label") else ""),
                f"; files: {PROBLEMS}/{e['domain']}, {PROBLEMS}/{e['problem']}"]
        return "\n".join([*head, "", "; ---- domain", self.domain.rstrip(), "", "; ---- problem",
                          self.problem.rstrip(), "", "; ---- plan", plan.rstrip(), "",
                          "; ---- what moved the agent (trace)", *_event_lines(self.events)]) + "\n"


def _event_lines(events: Sequence[Mapping[str, Any]]) -> list[str]:
    """One line per event; a run of decisions that kept the same pair and did not switch is
    shown by its first and last line and a count (Alg. 2 decides every period)."""
    out: list[str] = []
    i = 0
    while i < len(events):
        e = events[i]
        j = i
        if e["event"] == "decision" and not e.get("switch"):
            same = (e.get("dac"), e.get("exeDA"), e.get("rule"))
            while (j + 1 < len(events) and events[j + 1]["event"] == "decision" and not events[j + 1].get("switch")
                   and (events[j + 1].get("dac"), events[j + 1].get("exeDA"), events[j + 1].get("rule")) == same):
                j += 1
        out.append(_event_line(e))
        if j > i + 1:
            out.append(f"{'':12} … {j - i - 1} more decisions like it, no switch")
        if j > i:
            out.append(_event_line(events[j]))
        i = j + 1
    return out


def _event_line(e: Mapping[str, Any]) -> str:
    t = f"t={float(e['t']):10.3f}"
    kind = e["event"]
    if kind == "transition":
        return f"{t} transition {e['from']} -> {e['to']}"
    if kind == "command":
        return f"{t} command {e['flag']}"
    if kind == "end":
        return f"{t} end ({e.get('cause', '?')}): {e.get('reason', '')}"
    keys = [k for k in e if k not in ("t", "event", "algorithm")]
    fields = ", ".join(f"{k}={_short(e[k])}" for k in keys)
    return f"{t} decision [{e.get('algorithm', '?')}] {fields}"


def _short(v: Any) -> str:
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def load_index(run_dir: Path) -> list[dict[str, Any]]:
    """The ``problems/index.json`` of a run folder, with clear errors for what is missing."""
    if not run_dir.is_dir():
        raise ExplainError(f"{run_dir}: no such run folder (give the --out folder of `tasker run`)")
    path = run_dir / PROBLEMS / INDEX
    if not path.is_file():
        raise ExplainError(f"{path}: no planning record: the run planned nothing with the planned strategy "
                           f"(static strategies write no PDDL), or was written before `problems/` existed")
    try:
        index = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise ExplainError(f"{path}:{exc.lineno}: not valid JSON: {exc.msg}") from None
    if not isinstance(index, list):
        raise ExplainError(f"{path}: expected a list of planning records, got {_json_kind(index)}")
    for i, entry in enumerate(index):
        why = _record_problem(entry)
        if why:
            raise ExplainError(f"{path}: record [{i}]: {why} (the file is damaged: run the scenario again)")
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
    if entry.get("plan_file") is not None and not isinstance(entry["plan_file"], str):
        return f"plan_file: expected a string, got {_json_kind(entry['plan_file'])}"
    return None


def _json_kind(value: Any) -> str:
    """A JSON value as the file shows it: ``null``, ``5``, ``"x"``, an array, an object."""
    if isinstance(value, dict):
        return "an object"
    if isinstance(value, list):
        return "an array"
    return json.dumps(value)


def load_trace(run_dir: Path) -> list[dict[str, Any]]:
    path = run_dir / "trace.jsonl"
    if not path.is_file():
        return []
    try:
        return read(path)
    except ValueError as exc:
        raise ExplainError(str(exc)) from None


def moved(events: Iterable[Mapping[str, Any]], agent: str, until: float | None = None) -> list[Mapping[str, Any]]:
    """The ``decision``/``command``/``transition``/``end`` events about ``agent`` (up to ``until``)."""
    out = []
    for e in events:
        if until is not None and number(e["t"]) > until:
            break
        if e["event"] not in MOVING_EVENTS:
            continue
        if e.get("agent") == agent or (e["event"] == "decision" and agent in (e.get("dac"), e.get("exeDA"))):
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
    chosen = [e for e in mine if at is None or float(e["t"]) <= at]
    if not chosen:
        times = ", ".join(f"{float(e['t']):g}" for e in mine)
        raise ExplainError(f"{run / PROBLEMS / INDEX}: {agent} had not planned yet at t={at:g} s; it planned at "
                           f"t = {times}")
    entry = chosen[-1]
    folder = run / PROBLEMS
    try:
        domain = (folder / entry["domain"]).read_text(encoding="utf-8")
        problem = (folder / entry["problem"]).read_text(encoding="utf-8")
        plan = (folder / entry["plan_file"]).read_text(encoding="utf-8") if entry.get("plan_file") else None
    except OSError as exc:
        raise ExplainError(f"{folder}: {exc.strerror}: {exc.filename}") from None
    return Explanation(agent, at, entry, domain, problem, plan, tuple(moved(load_trace(run), agent, at)))


def _planned_in(run_dir: str) -> str:
    """``"; agents that planned in RUN: d1, d2"`` when ``run_dir`` is a run that planned, else ``""``."""
    try:
        index = load_index(Path(run_dir))
    except TaskerError:
        return ""
    agents = sorted({str(e["agent"]) for e in index}, key=lambda a: (len(a), a))
    return f"; agents that planned in {run_dir}: {', '.join(agents)}" if agents else ""


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


EXAMPLES = """\
examples:
  tasker explain out/paper --agent d3                 # d3's last problem, plan and what moved it
  tasker explain out/paper --agent d1 --at 60         # the problem d1 planned from at t = 60 s
  tasker explain out/run --agent d2 --out /tmp/d2     # domain.pddl, problem.pddl, plan, explain.txt"""


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser("explain", help="the PDDL an agent planned from, its plan and what moved it",
                       description="Print (or write with --out) the domain and problem an agent of a run planned "
                                   "from at a time (default: its last planning call), the plan, and the decisions, "
                                   "commands and transitions of the trace that moved it. The PDDL is read by any "
                                   "planner and by unified-planning's PDDLReader.",
                       epilog=EXAMPLES)
    _arguments(p)
    p.set_defaults(func=_command)


def _arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("run_dir", metavar="RUN_DIR", help="the output folder of `tasker run`")
    p.add_argument("--agent", default=None, help="agent id: d1, d2, ... (required; without it the error lists the "
                                                 "run's agents that planned)")
    p.add_argument("--at", type=non_negative_seconds, default=None,
                   help="simulated time in s (default: the agent's last plan)")
    p.add_argument("--out", default=None, help="write domain.pddl, problem.pddl, plan and explain.txt here")


def _command(args: argparse.Namespace) -> int:
    if args.agent is None:
        raise UsageError("--agent", f"which agent? an id such as d1{_planned_in(args.run_dir)}")
    ex = explain(args.run_dir, args.agent, args.at)
    if args.out:
        files = write(ex, Path(args.out))
        print(f"wrote {', '.join(str(f) for f in files)}", file=sys.stderr)
    else:
        sys.stdout.write(ex.text())
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """``tasker explain`` on its own: exit status 0, or 2 with a one-line error."""
    p = argparse.ArgumentParser(prog="tasker explain")
    _arguments(p)
    args = p.parse_args(argv)
    try:
        return _command(args)
    except TaskerError as exc:
        print(f"tasker explain: error: {exc}", file=sys.stderr)
        return 2
