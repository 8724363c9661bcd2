"""The trace over time as plotly figures: the Fig. 11 timeline and the Gantt of FSM states and stages.

Drawn from the run's timeline only (STYLE principle 10: plots read what was saved, never the
model); the spans they draw are those of the PNGs (:mod:`experiments.report.plots`).

* :func:`timeline_figure`: Alg. 2's costs and its cost rates on separate axes, the roles
  ``exeDA``/``irrDA``/``idleDA`` per agent with a row per hazard, ``susp``/``start`` commands;
* :func:`gantt_figure`: each agent's FSM states, under them its named stages.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import plotly.graph_objects as go
from plotly.subplots import make_subplots

from experiments.metrics.exposure import KINDS, Stretch
from experiments.report.plots import (
    COSTS,
    HAZARD_COLOURS,
    LABEL_FONT,
    RATES,
    ROLE_COLOURS,
    STATE_COLOURS,
    STATES,
    Source,
    _agents,
    _label_lanes,
    _value,
    _with_gaps,
    role_spans,
    state_spans,
)
from experiments.trace.timeline import Timeline
from experiments.trace.timeline import timeline as timeline_of


def _roles_bars(fig: go.Figure, tl: Timeline, hazards: Sequence[Stretch], row: int) -> None:
    spans = role_spans(tl)
    order = list(_agents(tl))
    for role, colour in ROLE_COLOURS.items():
        mine = [s for s in spans if s[1] == role]
        fig.add_trace(go.Bar(
            orientation="h", base=[s[2] for s in mine], x=[s[3] - s[2] for s in mine], y=[s[0] for s in mine],
            name=role, marker_color=colour, legendgroup="roles", legendgrouptitle_text="roles",
            hovertemplate=f"%{{y}} {role}<br>%{{base:.1f}} s – +%{{x:.1f}} s<extra></extra>"), row=row, col=1)
    # one row per owned hazard (never overlapping), its stretches coloured by what they were: attended,
    # unattended, over budget; every hazard nobody owns (a door open in the world file, say) on one row
    # of its own, grey, why in the hover: they are not any task's to attend to
    hazard_rows = {(h.owner, h.label): f"{h.owner} hazard: {h.label}" if h.owner else "nobody's hazards"
                   for h in hazards}
    for kind in KINDS:
        mine_h = [h for h in hazards if h.kind == kind]
        if not mine_h:
            continue
        fig.add_trace(go.Bar(
            orientation="h", base=[h.start for h in mine_h], x=[max(h.end - h.start, 1e-3) for h in mine_h],
            y=[hazard_rows[(h.owner, h.label)] for h in mine_h], name=f"hazard {kind}",
            marker_color=HAZARD_COLOURS[kind], customdata=[f"{h.label}" + (f" ({h.why})" if h.why else "")
                                                           for h in mine_h], legendgroup="hazards",
            legendgrouptitle_text="hazards",
            hovertemplate=f"%{{y}}: %{{customdata}}<br>{kind} %{{base:.1f}} s – +%{{x:.1f}} s<extra></extra>"),
            row=row, col=1)
    rows = [a for a in order] + sorted({s[0] for s in spans} - set(order))
    cats = [c for a in rows for c in [a, *sorted({v for k, v in hazard_rows.items() if k[0] == a})]]
    if any(h.owner is None for h in hazards):
        cats.append("nobody's hazards")
    fig.update_yaxes(categoryorder="array", categoryarray=cats[::-1], row=row, col=1)


def _mark_commands(tl: Timeline, panels: int = 1) -> list[dict[str, Any]]:
    """Vertical lines on every panel: ``susp`` red dashed, ``start`` green dotted, a switch decided
    by priority class (or a baseline) purple.  Built as plain shapes, set once (fast)."""
    lines = [(c.t, "#c0392b" if c.flag == "susp" else "#2e8b57", "dash" if c.flag == "susp" else "dot")
             for c in tl.commands if c.flag in ("susp", "start")]
    lines += [(d.t, "#8e44ad", "solid") for d in tl.decisions if d.rule != "cost" and d.switch]
    lines.sort(key=lambda x: x[0])
    shapes = []
    for i in range(1, panels + 1):
        axis = "" if i == 1 else str(i)
        shapes += [{"type": "line", "x0": t, "x1": t, "y0": 0, "y1": 1, "xref": f"x{axis}", "yref": f"y{axis} domain",
                    "line": {"color": colour, "dash": dash, "width": 1}, "opacity": 0.6} for t, colour, dash in lines]
    return shapes


def timeline_figure(events: Source, hazards: Sequence[Stretch] = ()) -> go.Figure:
    """Fig. 11: costs (row 1), cost rates (row 2, own axis), roles and hazards (row 3)."""
    tl = timeline_of(events)
    t_end = max(tl.t_end, 1.0)
    costs = [d for d in tl.decisions if d.rule == "cost"]
    fig = make_subplots(rows=3, cols=1, shared_xaxes=True, vertical_spacing=0.04, row_heights=[0.5, 0.18, 0.32],
                        subplot_titles=("Alg. 2 costs" if costs else "decisions (no cost decisions in this run)",
                                        "cost rates [cost/s]", "harmoniser roles and hazards"))
    if costs:
        ts, points = _with_gaps(costs)
        for row, keys in ((1, COSTS), (2, RATES)):
            for key in keys:
                if any(key in e.data for e in costs):
                    ys = [None if p is None or math.isnan(_value(p, key)) else _value(p, key) for p in points]
                    fig.add_trace(go.Scatter(x=ts, y=ys, name=key, mode="lines", legendgroup=f"r{row}",
                                             line={"dash": "dash" if key.startswith("cc") else "solid", "width": 1.5},
                                             hovertemplate=f"{key}: %{{y:.4g}} at %{{x:.1f}} s<extra></extra>"),
                                  row=row, col=1)
    decisions = [d for d in tl.decisions if d.rule != "cost"]
    if decisions:
        fig.add_trace(go.Scatter(
            x=[d.t for d in decisions], y=[str(d.rule or d.algorithm) for d in decisions]
            if not costs else [None] * len(decisions), mode="markers", name="other decisions",
            marker={"symbol": ["diamond" if d.switch else "line-ns-open" for d in decisions], "size": 9,
                    "color": "#8e44ad"},
            text=[f"{d.rule}: dac={d.dac}, exeDA={d.exe_da}, switch={d.switch}" for d in decisions],
            hovertemplate="%{text} at %{x:.1f} s<extra></extra>"), row=1, col=1)
    _roles_bars(fig, tl, hazards, 3)
    fig.update_layout(shapes=_mark_commands(tl, panels=3), barmode="overlay", height=720,
                      template="plotly_white", hovermode="closest",
                      legend={"groupclick": "toggleitem"}, margin={"t": 40, "r": 10})
    fig.update_xaxes(range=[0, t_end * 1.01])
    fig.update_xaxes(title_text="time [s] (red dashed: susp, green dotted: start, purple: decision by priority)",
                     row=3, col=1)
    return fig


# ----------------------------------------------------------------------------------------- gantt


def _stage_spans(tl: Timeline) -> dict[str, list[dict[str, Any]]]:
    """Agent -> stages with begin, end and how they ended."""
    out: dict[str, list[dict[str, Any]]] = {}
    for a in tl.agents.values():
        for r in a.stages:
            status = "running at end" if r.status == "running" else r.status + (f": {r.reason}" if r.reason else "")
            out.setdefault(a.id, []).append({"action": r.action, "args": list(r.args), "fsm": r.fsm, "kind": r.kind,
                                             "t0": r.begin, "t1": r.end if r.end is not None else tl.t_end,
                                             "status": status})
    return out


def gantt_figure(events: Source) -> go.Figure:
    """Per agent: its FSM states, under them its stages, under those the stage names in lanes
    that never overlap (at the page's default width; zooming only adds room)."""
    tl = timeline_of(events)
    t_end = max(tl.t_end, 1.0)
    kinds = _agents(tl)
    spans = state_spans(tl)
    stages = _stage_spans(tl)
    seconds_per_point = t_end * 1.02 / (900 * 0.75)  # ≈ 900 px of plot area, 0.75 pt a px
    lane_h = 0.42
    y, ticks, rows = 0.0, [], {}
    names: list[tuple[float, float, str, str]] = []  # (t, y, name, colour)
    for agent in spans:
        mine = stages.get(agent, [])
        lanes = _label_lanes([(s["t0"], s["action"]) for s in mine], seconds_per_point)
        rows[agent] = (y, y + 1.0)
        ticks += [(y, f"{agent} {kinds.get(agent, '?')}"), (y + 1.0, f"{agent} stages")]
        for s, lane in zip(mine, lanes, strict=True):
            names.append((s["t0"], y + 1.55 + lane_h * lane, s["action"],
                          STATE_COLOURS["exeSusp"] if s["fsm"] == "exeSusp" else "#222"))
        y += 2.4 + lane_h * (max(lanes, default=-1) + 1)
    fig = go.Figure()
    for state in STATES:
        bars = [(a, t0, t1) for a, ss in spans.items() for (st, t0, t1) in ss if st == state]
        fig.add_trace(go.Bar(orientation="h", base=[m[1] for m in bars], x=[max(m[2] - m[1], 1e-3) for m in bars],
                             y=[rows[m[0]][0] for m in bars], width=0.8, name=state, marker_color=STATE_COLOURS[state],
                             legendgroup="states", legendgrouptitle_text="FSM",
                             customdata=[f"{m[0]} {kinds.get(m[0], '?')}" for m in bars],
                             hovertemplate=f"%{{customdata}}: {state}<br>%{{base:.2f}} s, %{{x:.2f}} s long"
                                           "<extra></extra>"))
    for fsm in ("exeTsk", "exeSusp"):
        stage_bars = [(a, st) for a, ss in stages.items() for st in ss if st["fsm"] == fsm]
        fig.add_trace(go.Bar(
            orientation="h", base=[st["t0"] for _, st in stage_bars],
            x=[max(st["t1"] - st["t0"], 1e-3) for _, st in stage_bars],
            y=[rows[a][1] for a, _ in stage_bars], width=0.6, name=f"{fsm} stage",
            marker={"color": STATE_COLOURS[fsm], "opacity": 0.6, "line": {"color": "#fff", "width": 1}},
            legendgroup="stages", legendgrouptitle_text="stages",
            customdata=[[st["action"], " ".join(map(str, st["args"])), st["kind"], st["status"]]
                        for _, st in stage_bars],
            hovertemplate="%{customdata[0]}(%{customdata[1]}) [%{customdata[2]}]<br>%{base:.2f} s, %{x:.2f} s long, "
                          "%{customdata[3]}<extra></extra>"))
        stopped = [(a, st) for a, st in stage_bars if not str(st["status"]).startswith(("done", "running"))]
        if stopped:
            fig.add_trace(go.Scatter(x=[st["t1"] for _, st in stopped], y=[rows[a][1] for a, _ in stopped],
                                     mode="markers", marker={"symbol": "x", "size": 10, "color": "#000"},
                                     name=f"{fsm} stage stopped/failed", text=[st["status"] for _, st in stopped],
                                     hovertemplate="%{text} at %{x:.2f} s<extra></extra>"))
    if names:
        fig.add_trace(go.Scatter(x=[n[0] for n in names], y=[n[1] for n in names], text=[n[2] for n in names],
                                 mode="text", textposition="middle right", textfont={"size": 10,
                                                                                     "color": [n[3] for n in names]},
                                 name="stage names", hoverinfo="skip"))
    fig.update_layout(shapes=_mark_commands(tl), barmode="overlay", height=140 + 34 * max(y, 2.0),
                      template="plotly_white",
                      margin={"t": 30, "r": 10}, legend={"groupclick": "toggleitem"},
                      xaxis_title="time [s] (hover a stage for its arguments)")
    fig.update_yaxes(tickvals=[t[0] for t in ticks], ticktext=[t[1] for t in ticks], autorange="reversed",
                     zeroline=False, showgrid=False)
    right = max([t_end * 1.01, *(n[0] + (len(n[2]) * 0.6 + 1) * LABEL_FONT * seconds_per_point for n in names)])
    fig.update_xaxes(range=[0, right])
    return fig
