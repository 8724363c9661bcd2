"""``report.html`` of a run: one self-contained page that shows what happened in it.

It works offline: plotly's JavaScript is inlined once in the page (no CDN), and every
figure is a plotly figure drawn from the saved trace and record (STYLE principle 10:
plots read what was saved, never the model).  A run's page holds

* a summary: scenario, seed, settings, how each task ended, the metrics (host-dependent
  ones — wall time, real-time factor — marked as such), and the planning calls of
  ``problems/`` (what ``tasker explain`` reads);
* the Fig. 11 timeline: Alg. 2's costs and its cost rates on separate axes, the roles
  ``exeDA``/``irrDA``/``idleDA`` per agent, ``susp``/``start`` commands and hazards;
* the Gantt of FSM states with a row of named stages under each agent;
* a world view with a time slider over the recorded trajectory (robot and, when
  recorded, people), the hazards on and the agent executing at each moment.

Same inputs, same bytes: figures get fixed ids and no wall-clock value is added.

The page's frame is :mod:`experiments.report.page`, its figures :mod:`experiments.report.timeline_figures`
and :mod:`experiments.report.world_figure`; the sweep's page is :mod:`experiments.report.sweep_page`.
"""

from __future__ import annotations

import html
import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from experiments.metrics.exposure import Stretch
from experiments.metrics.registry import host_dependent
from experiments.report.page import Raw, figure_div, page, table
from experiments.report.plots import Source, hazard_spans
from experiments.report.timeline_figures import gantt_figure, timeline_figure
from experiments.report.world_figure import Sample, read_trajectory, world_figure
from experiments.trace.timeline import Timeline
from experiments.trace.timeline import timeline as timeline_of

if TYPE_CHECKING:
    from robot.spec import WorldSpec


def _fmt(v: Any) -> str:
    if isinstance(v, float):
        return f"{v:.4g}" if math.isfinite(v) else str(v)
    return str(v)


def hazards_of(events: Source, metrics: Mapping[str, Any] | None) -> list[Stretch]:
    """Hazard stretches: from ``hazard`` events if the trace has them, else (an older run folder) from the
    metrics' ``safety.episodes`` (``agent``, ``hazard``, ``subject``, ``start``, ``end``), each then drawn
    whole as unattended (or nobody's), since what attended it is not known there."""
    spans = hazard_spans(timeline_of(events))
    if spans or not metrics:
        return spans
    episodes = (metrics.get("safety") or {}).get("episodes") if isinstance(metrics.get("safety"), Mapping) else None
    out = []
    for ep in episodes or []:
        try:
            label = " ".join(str(x) for x in (ep["hazard"], ep.get("subject", "")) if x)
            owner = None if ep.get("agent") in (None, "unowned") else str(ep["agent"])
            out.append(Stretch(owner, label, float(ep["start"]), float(ep["end"]),
                               "unattended" if owner else "nobody's"))
        except (KeyError, TypeError, ValueError):
            continue
    return sorted(out, key=lambda s: (s.start, s.owner or "", s.label))


def _flatten(m: Mapping[str, Any], prefix: str = "") -> list[tuple[str, Any]]:
    out: list[tuple[str, Any]] = []
    for k, v in sorted(m.items()):
        name = f"{prefix}{k}"
        if isinstance(v, Mapping):
            out += _flatten(v, name + ".")
        elif isinstance(v, bool | int | float | str) or v is None:
            out.append((name, v))
    return out


def run_page(events: Source, *, record: Mapping[str, Any] | None = None,
             metrics: Mapping[str, Any] | None = None, world: WorldSpec | None = None,
             trajectory: Sequence[Sample] = (),
             people: Mapping[str, Sequence[tuple[float, float, float, str]]] | None = None,
             problems: Sequence[Mapping[str, Any]] = ()) -> str:
    """The HTML of a run's report (see the module docstring)."""
    tl = timeline_of(events)
    record = record or {}
    scenario = record.get("scenario") or {}
    name = str(scenario.get("name") or "run")
    hazards = hazards_of(tl, metrics)
    sections = [_summary(tl, record)]
    sections += ["<h2>Timeline (cf. Fig. 11)</h2>", figure_div(timeline_figure(tl, hazards), "timeline")]
    sections += ["<h2>FSM states and stages</h2>", figure_div(gantt_figure(tl), "gantt")]
    sections.append("<h2>World</h2>")
    if world is None:
        sections.append('<p class="note">This run has no world (a synthetic scenario, or run without a '
                        'robot): nothing to show here.</p>')
    else:
        robot = list(trajectory)
        if not robot:
            sections.append('<p class="note">No trajectory was recorded: the world at its start.</p>')
        sections.append(figure_div(world_figure(world, robot, people or {}, tl, hazards), "world"))
    sections.append(_details(metrics, problems))
    return page(f"tasker run: {name}", sections)


def _summary(tl: Timeline, record: Mapping[str, Any]) -> str:
    settings = record.get("settings") or {}
    scenario = record.get("scenario") or {}
    facts = [("scenario", scenario.get("name", "?")), ("source", scenario.get("source", "")),
             ("seed", record.get("seed", "?")), *sorted(settings.items()),
             ("tasker", record.get("tasker_version", "?"))]
    out = [table(["", ""], [(k, _fmt(v)) for k, v in facts])]
    out.append("<h2>Tasks</h2>")
    out.append(table(["agent", "task type", "requested at [s]", "ended at [s]", "cause", "reason"],
                     [(a.id, a.task_type, _fmt(a.request_t), _fmt(a.end.t) if a.end else "–",
                       a.end.cause if a.end else "still running", a.end.reason if a.end else "")
                      for a in tl.agents.values()], numeric=(False, False, True, True)))
    return "\n".join(out)


def _details(metrics: Mapping[str, Any] | None, problems: Sequence[Mapping[str, Any]]) -> str:
    out = []
    if problems:
        out.append("<h2>Planning calls (<code>problems/</code>)</h2>")
        out.append('<p class="note">Every planned upTsk and genSusp, as PDDL any planner reads; '
                   "<code>tasker explain RUN_DIR --agent dN --at T</code> shows one with the decisions around it.</p>")
        out.append(table(["t [s]", "agent", "task type", "purpose", "status", "problem", "plan"],
                         [(_fmt(float(p["t"])), p["agent"], p["task_type"], p["purpose"], p["status"],
                           Raw(f'<a href="problems/{html.escape(p["problem"])}">{html.escape(p["problem"])}</a>'),
                           " ".join(f"({' '.join(s)})" for s in p.get("plan") or [])) for p in problems],
                         numeric=(True,)))
    if metrics:
        rows = []
        for k, v in _flatten(metrics):
            host = host_dependent(k)
            rows.append((Raw(f'<span class="host">{html.escape(k)} (host-dependent)</span>') if host else k,
                         _fmt(v)))
        out.append("<h2>Metrics</h2>")
        out.append('<details><summary>every value of <code>metrics.json</code> (host-dependent values measure '
                   "this machine, not the strategy)</summary>")
        out.append(table(["metric", "value"], rows, numeric=(False, True)))
        out.append("</details>")
    return "\n".join(out)


def write_run(out: Path, events: Source, *, record: Mapping[str, Any] | None = None,
              metrics: Mapping[str, Any] | None = None, world: WorldSpec | None = None,
              trajectory: Sequence[Sample] = ()) -> Path:
    """Write ``out/report.html`` for a run; a recorded trajectory file in ``out`` wins over
    ``trajectory`` (the run's own), and ``out/problems/index.json`` is listed when present."""
    recorded = read_trajectory(out)
    robot, people = recorded if recorded and recorded[0] else (list(trajectory), {})
    index = out / "problems" / "index.json"
    problems = json.loads(index.read_text(encoding="utf-8")) if index.is_file() else []
    path = out / "report.html"
    path.write_text(run_page(events, record=record, metrics=metrics, world=world, trajectory=robot, people=people,
                             problems=problems), encoding="utf-8")
    return path
