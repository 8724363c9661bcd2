"""What ``tasker run`` says when a run ends: its tasks, and what it left unsafe.

Read from the run's :class:`~experiments.trace.timeline.Timeline` and its metrics (never from raw
trace records): a headline (tasks, how they ended, suspensions and how many were safe), each task's
end, then safety — every declared hazard left unattended, for how long against its budget (and how
much of that after its owner ended), every suspension the judge found unsafe and why, every hazard
the robot carried into another task, and the hazards nobody owns with why.  A run that left nothing
unsafe says so in one line.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping
from typing import Any

from experiments.metrics.exposure import unowned_reason
from experiments.trace.timeline import Timeline


def headline(label: str, tl: Timeline, metrics: Mapping[str, Any], wall_s: float) -> str:
    """``household: 3 tasks, 3 ended (3 finished), 1 suspension (1 safe), 327.3 s simulated in 2.6 s``."""
    ends = [a.end for a in tl.agents.values() if a.end is not None]
    causes = Counter(e.cause for e in ends)
    s = metrics.get("suspensions") or {}
    count, safe = int(s.get("count", 0)), int(s.get("safe", 0))
    return (f"{label}: {len(tl.agents)} tasks, {len(ends)} ended "
            f"({', '.join(f'{n} {c}' for c, n in sorted(causes.items()))}), "
            f"{count} suspension{'' if count == 1 else 's'} ({safe} safe), "
            f"{tl.t_end:.1f} s simulated in {wall_s:.1f} s")


def ends(tl: Timeline) -> list[str]:
    """One line per task that ended: its agent, type, reason and time."""
    done = sorted((a for a in tl.agents.values() if a.end is not None), key=lambda a: (a.end.t if a.end else 0, a.id))
    return [f"  {a.id} {a.task_type}: {a.end.reason} at t={a.end.t:.1f}" for a in done if a.end is not None]


def safety(tl: Timeline, metrics: Mapping[str, Any]) -> list[str]:
    """What the run left unsafe (the module docstring), or one line saying it left nothing."""
    out: list[str] = []
    task_of = {a.id: a.task_type for a in tl.agents.values()}
    for ep in (metrics.get("safety") or {}).get("episodes", []):
        agent = ep.get("agent")
        unattended = float(ep.get("unattended_s") or 0.0)
        if agent is None or unattended <= 0:
            continue
        name = f"{ep['hazard']}({', '.join(ep.get('args', []))})"
        line = (f"  hazard {name} of {agent} {task_of.get(agent, '')}: {unattended:.1f} s unattended against a "
                f"budget of {float(ep['budget_s']):g} s")
        over = float(ep.get("overrun_s") or 0.0)
        line += f", OVER by {over:.1f} s" if over > 0 else ", within it"
        after = float(ep.get("after_end_s") or 0.0)
        if after > 0:
            line += f" ({after:.1f} s of it after {agent} ended)"
        if ep.get("end") is None:
            line += "; still on when the run ended"
        out.append(line)
    for r in (metrics.get("suspensions") or {}).get("episodes", []):
        if r.get("safe"):
            continue
        why = []
        if r.get("no_plan"):
            why.append("genSusp made no plan")
        if r.get("goal_unmet"):
            why.append("its goal unmet: " + ", ".join(f"({g})" for g in r["goal_unmet"]))
        if r.get("left_on"):
            why.append("left on: " + ", ".join(r["left_on"]))
        if r.get("inapplicable"):
            why.append("stages that could not run: " + ", ".join(r["inapplicable"]))
        out.append(f"  unsafe suspension of {r['agent']} {r['task_type']} at t={float(r['start']):.1f} "
                   f"({r.get('strategy') or 'no plan'}): {'; '.join(why) or 'see metrics.json'}")
    for c in (metrics.get("carried") or {}).get("episodes", []):
        out.append(f"  carried: {c['name']} for {float(c['seconds']):.1f} s ({c['hazard']} is {c['owner']}'s)")
    nobody = [h for h in tl.hazards if h.owner is None]
    if nobody:
        reasons = Counter(unowned_reason(tl, h) for h in nobody)
        shown = "; ".join(f"{why} ({n})" if len(reasons) > 1 else why for why, n in sorted(reasons.items()))
        out.append(f"  nobody owns {len(nobody)} hazard episode{'' if len(nobody) == 1 else 's'} "
                   f"(no task is theirs to attend): {shown}")
    if not any(line.startswith(("  hazard", "  unsafe", "  carried")) for line in out):
        out.insert(0, "  safety: every suspension safe, no declared hazard left unattended")
    else:
        out.insert(0, "  safety:")
    return out
