"""``report.html``: one self-contained page that shows what happened in a run (or a sweep).

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
"""

from __future__ import annotations

import csv
import html
import json
import math
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any, TypeVar

import plotly.graph_objects as go
import plotly.io as pio
from plotly.offline import get_plotlyjs
from plotly.subplots import make_subplots

from experiments.plots import (
    COSTS,
    LABEL_FONT,
    RATES,
    ROLE_COLOURS,
    STATE_COLOURS,
    STATES,
    _agents,
    _end_time,
    _label_lanes,
    _role_spans,
    _state_spans,
    _value,
    _with_gaps,
    hazard_spans,
)

Event = Mapping[str, Any]
_S = TypeVar("_S", bound=tuple[Any, ...])
Sample = tuple[float, float, float, float]
HOST_DEPENDENT = ("wall_time_s", "real_time_factor", "planner_wall_time_s", "planner_cache_hits")
"""Metrics that measure the machine, not the strategy: shown, never compared."""
HAZARD_COLOUR = "#c0392b"
MAX_FRAMES = 240
MAX_POINTS = 300
"""At most this many samples of a trajectory are drawn (the file keeps them all)."""
_CONFIG = {"displaylogo": False, "responsive": True}
_CSS = """
body{font-family:system-ui,sans-serif;margin:1.5em auto;max-width:1200px;color:#222;padding:0 1em}
h1{font-size:1.5em} h2{font-size:1.2em;margin-top:2em;border-bottom:1px solid #ddd}
table{border-collapse:collapse;font-size:.85em;margin:.5em 0;display:block;overflow-x:auto}
td,th{border:1px solid #ddd;padding:3px 8px;
text-align:left} th{background:#f4f4f4} .num{text-align:right;font-variant-numeric:tabular-nums}
.note{color:#666;font-size:.9em} .host{color:#888;font-style:italic} code{background:#f4f4f4;padding:0 3px}
"""


# ----------------------------------------------------------------------------------------- page


def page(title: str, sections: Iterable[str]) -> str:
    """A whole HTML document with plotly's JavaScript inlined once."""
    return "\n".join([
        "<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">', f"<title>{html.escape(title)}</title>",
        f"<style>{_CSS}</style>", f'<script type="text/javascript">{get_plotlyjs()}</script>', "</head><body>",
        f"<h1>{html.escape(title)}</h1>", *sections, "</body></html>", ""])


def figure_div(fig: go.Figure | dict[str, Any], div_id: str) -> str:
    """A figure (or a figure dict, already valid: not validated again) as a ``<div>`` and its script."""
    return str(pio.to_html(fig, full_html=False, include_plotlyjs=False, div_id=div_id, config=_CONFIG,
                           validate=not isinstance(fig, dict)))


def table(header: Sequence[str], rows: Iterable[Sequence[Any]], numeric: Sequence[bool] = ()) -> str:
    head = "".join(f"<th>{html.escape(h)}</th>" for h in header)
    body = []
    for row in rows:
        cells = []
        for i, c in enumerate(row):
            cls = ' class="num"' if i < len(numeric) and numeric[i] else ""
            cells.append(f"<td{cls}>{c if isinstance(c, _Raw) else html.escape(str(c))}</td>")
        body.append("<tr>" + "".join(cells) + "</tr>")
    return f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table>"


class _Raw(str):
    """Table cell text that is already HTML."""


def _fmt(v: Any) -> str:
    if isinstance(v, float):
        return f"{v:.4g}" if math.isfinite(v) else str(v)
    return str(v)


# ----------------------------------------------------------------------------------------- timeline


def _roles_bars(fig: go.Figure, events: Sequence[Event], hazards: Sequence[tuple[str, str, float, float]],
                row: int, t_end: float) -> None:
    spans = _role_spans(events, t_end)
    order = list(_agents(events))
    for role, colour in ROLE_COLOURS.items():
        mine = [s for s in spans if s[1] == role]
        fig.add_trace(go.Bar(
            orientation="h", base=[s[2] for s in mine], x=[s[3] - s[2] for s in mine], y=[s[0] for s in mine],
            name=role, marker_color=colour, legendgroup="roles", legendgrouptitle_text="roles",
            hovertemplate=f"%{{y}} {role}<br>%{{base:.1f}} s – +%{{x:.1f}} s<extra></extra>"), row=row, col=1)
    hazard_rows = {h[:2]: f"{h[0]} hazard: {h[1]}" for h in hazards}  # one row per hazard: never overlapping
    if hazards:
        fig.add_trace(go.Bar(
            orientation="h", base=[h[2] for h in hazards], x=[max(h[3] - h[2], 1e-3) for h in hazards],
            y=[hazard_rows[h[:2]] for h in hazards], name="hazard on", marker_color=HAZARD_COLOUR,
            legendgroup="roles", hovertemplate="%{y}<br>on %{base:.1f} s – +%{x:.1f} s<extra></extra>"),
            row=row, col=1)
    rows = [a for a in order] + sorted({s[0] for s in spans} - set(order))
    cats = [c for a in rows for c in [a, *sorted({v for k, v in hazard_rows.items() if k[0] == a})]]
    fig.update_yaxes(categoryorder="array", categoryarray=cats[::-1], row=row, col=1)


def _mark_commands(events: Sequence[Event], panels: int = 1) -> list[dict[str, Any]]:
    """Vertical lines on every panel: ``susp`` red dashed, ``start`` green dotted, a switch decided
    by priority class (or a baseline) purple.  Built as plain shapes, set once (fast)."""
    lines = []
    for e in events:
        if e["event"] == "command" and e["flag"] in ("susp", "start"):
            susp = e["flag"] == "susp"
            lines.append((float(e["t"]), "#c0392b" if susp else "#2e8b57", "dash" if susp else "dot"))
        elif e["event"] == "decision" and e.get("rule") != "cost" and e.get("switch"):
            lines.append((float(e["t"]), "#8e44ad", "solid"))
    shapes = []
    for i in range(1, panels + 1):
        axis = "" if i == 1 else str(i)
        shapes += [{"type": "line", "x0": t, "x1": t, "y0": 0, "y1": 1, "xref": f"x{axis}", "yref": f"y{axis} domain",
                    "line": {"color": colour, "dash": dash, "width": 1}, "opacity": 0.6} for t, colour, dash in lines]
    return shapes


def timeline_figure(events: Sequence[Event], hazards: Sequence[tuple[str, str, float, float]] = ()) -> go.Figure:
    """Fig. 11: costs (row 1), cost rates (row 2, own axis), roles and hazards (row 3)."""
    events = list(events)
    t_end = max(_end_time(events), 1.0)
    costs = [e for e in events if e["event"] == "decision" and e.get("rule") == "cost"]
    fig = make_subplots(rows=3, cols=1, shared_xaxes=True, vertical_spacing=0.04, row_heights=[0.5, 0.18, 0.32],
                        subplot_titles=("Alg. 2 costs" if costs else "decisions (no cost decisions in this run)",
                                        "cost rates [cost/s]", "harmoniser roles and hazards"))
    if costs:
        ts, points = _with_gaps(costs)
        for row, keys in ((1, COSTS), (2, RATES)):
            for key in keys:
                if any(key in e for e in costs):
                    ys = [None if p is None or math.isnan(_value(p, key)) else _value(p, key) for p in points]
                    fig.add_trace(go.Scatter(x=ts, y=ys, name=key, mode="lines", legendgroup=f"r{row}",
                                             line={"dash": "dash" if key.startswith("cc") else "solid", "width": 1.5},
                                             hovertemplate=f"{key}: %{{y:.4g}} at %{{x:.1f}} s<extra></extra>"),
                                  row=row, col=1)
    decisions = [e for e in events if e["event"] == "decision" and e.get("rule") != "cost"]
    if decisions:
        fig.add_trace(go.Scatter(
            x=[float(e["t"]) for e in decisions], y=[str(e.get("rule") or e.get("algorithm")) for e in decisions]
            if not costs else [None] * len(decisions), mode="markers", name="other decisions",
            marker={"symbol": ["diamond" if e.get("switch") else "line-ns-open" for e in decisions], "size": 9,
                    "color": "#8e44ad"},
            text=[f"{e.get('rule')}: dac={e.get('dac')}, exeDA={e.get('exeDA')}, switch={e.get('switch')}"
                  for e in decisions], hovertemplate="%{text} at %{x:.1f} s<extra></extra>"), row=1, col=1)
    _roles_bars(fig, events, hazards, 3, t_end)
    fig.update_layout(shapes=_mark_commands(events, panels=3), barmode="overlay", height=720,
                      template="plotly_white", hovermode="closest",
                      legend={"groupclick": "toggleitem"}, margin={"t": 40, "r": 10})
    fig.update_xaxes(range=[0, t_end * 1.01])
    fig.update_xaxes(title_text="time [s] (red dashed: susp, green dotted: start, purple: decision by priority)",
                     row=3, col=1)
    return fig


# ----------------------------------------------------------------------------------------- gantt


def _stage_spans(events: Sequence[Event], t_end: float) -> dict[str, list[dict[str, Any]]]:
    """Agent -> stages with begin, end and how they ended, from ``stage`` events."""
    out: dict[str, list[dict[str, Any]]] = {}
    open_: dict[tuple[str, str, int], dict[str, Any]] = {}
    for e in events:
        if e["event"] != "stage":
            continue
        key = (e["agent"], str(e.get("fsm")), int(e.get("index", 0)))
        if e["status"] == "begin":
            s = {"action": e["action"], "args": e.get("args", []), "fsm": e.get("fsm"), "kind": e.get("kind"),
                 "t0": float(e["t"]), "t1": t_end, "status": "running at end"}
            open_[key] = s
            out.setdefault(e["agent"], []).append(s)
        elif key in open_:
            s = open_.pop(key)
            s["t1"], s["status"] = float(e["t"]), e["status"] + (f": {e['reason']}" if e.get("reason") else "")
    return out


def gantt_figure(events: Sequence[Event]) -> go.Figure:
    """Per agent: its FSM states, under them its stages, under those the stage names in lanes
    that never overlap (at the page's default width; zooming only adds room)."""
    events = list(events)
    t_end = max(_end_time(events), 1.0)
    kinds = _agents(events)
    spans = _state_spans(events, t_end)
    stages = _stage_spans(events, t_end)
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
    fig.update_layout(shapes=_mark_commands(events), barmode="overlay", height=140 + 34 * max(y, 2.0),
                      template="plotly_white",
                      margin={"t": 30, "r": 10}, legend={"groupclick": "toggleitem"},
                      xaxis_title="time [s] (hover a stage for its arguments)")
    fig.update_yaxes(tickvals=[t[0] for t in ticks], ticktext=[t[1] for t in ticks], autorange="reversed",
                     zeroline=False, showgrid=False)
    right = max([t_end * 1.01, *(n[0] + (len(n[2]) * 0.6 + 1) * LABEL_FONT * seconds_per_point for n in names)])
    fig.update_xaxes(range=[0, right])
    return fig


# ----------------------------------------------------------------------------------------- world


def read_trajectory(run_dir: Path) -> tuple[list[Sample], dict[str, list[tuple[float, float, float, str]]]] | None:
    """The robot's samples ``(t, x, y, yaw)`` and people's ``name -> (t, x, y, posture)`` from a
    recorded trajectory file of the run (``trajectory.jsonl`` or ``trajectory.csv``), or None.

    Rows are read tolerantly: ``t`` and the robot as ``x``/``y``/``yaw`` or ``robot``
    (``[x, y, yaw]`` or ``{"x", "y", "yaw"}``/``{"pose"}``); people under ``people`` as
    ``name -> [x, y, yaw, posture]`` or ``{"pose"|"x","y", "posture"}``; rows without ``t``
    (a header) and ``mark`` rows are skipped (``tasker-trajectory/1`` of ``robot.recording``)."""
    jsonl, csv_path = run_dir / "trajectory.jsonl", run_dir / "trajectory.csv"
    rows: list[Mapping[str, Any]] = []
    try:
        if jsonl.is_file():
            rows = [json.loads(line) for line in jsonl.read_text(encoding="utf-8").splitlines() if line.strip()]
        elif csv_path.is_file():
            with csv_path.open(encoding="utf-8", newline="") as f:
                rows = list(csv.DictReader(f))
        else:
            return None
        robot: list[Sample] = []
        people: dict[str, list[tuple[float, float, float, str]]] = {}
        for r in rows:
            if "t" not in r or "mark" in r:  # a header line (format, fields) or an event mark
                continue
            t = float(r["t"])
            pose = _pose(r.get("robot", r))
            if pose is not None:
                robot.append((t, *pose))
            for name, p in (r.get("people") or {}).items():
                pp = _pose(p)
                if pp is not None:
                    posture = str(p.get("posture", "")) if isinstance(p, Mapping) else (
                        p[3] if isinstance(p, list | tuple) and len(p) > 3 and isinstance(p[3], str) else "")
                    people.setdefault(name, []).append((t, pp[0], pp[1], posture))
    except (ValueError, KeyError, TypeError, AttributeError):
        return None  # a format this page does not know: fall back to the run's own trajectory
    return (robot, people) if robot else None


def _pose(v: Any) -> tuple[float, float, float] | None:
    if isinstance(v, Mapping):
        if "pose" in v:
            v = v["pose"]
        elif "x" in v and "y" in v and v["x"] not in ("", None):
            return float(v["x"]), float(v["y"]), float(v.get("yaw") or 0.0)
        else:
            return None
    if isinstance(v, list | tuple) and len(v) >= 2:
        return float(v[0]), float(v[1]), float(v[2]) if len(v) > 2 else 0.0
    return None


def _thin(samples: Sequence[Any], n: int) -> list[Any]:
    """At most ``n`` samples, evenly by index, first and last kept."""
    if len(samples) <= n:
        return list(samples)
    return [samples[round(i * (len(samples) - 1) / (n - 1))] for i in range(n)]


def _at(samples: Sequence[_S], t: float) -> _S | None:
    """The last sample at or before ``t`` (the first one before it starts)."""
    if not samples:
        return None
    lo, hi = 0, len(samples)
    while lo < hi:
        mid = (lo + hi) // 2
        if samples[mid][0] <= t:
            lo = mid + 1
        else:
            hi = mid
    return samples[max(lo - 1, 0)]


_FILL = {"wall": "#444", "furniture": "#c8b48a", "door": "#7a4f2a"}


def world_figure(world: Any, robot: Sequence[Sample], people: Mapping[str, Sequence[tuple[float, float, float, str]]],
                 events: Sequence[Event], hazards: Sequence[tuple[str, str, float, float]]) -> dict[str, Any]:
    """The world from above, a time slider over the trajectory: the robot, its path so far,
    people, the hazards on and the agent executing at that moment; red crosses where the robot
    was at each ``susp`` command.  A figure dict: its
    frames are built as plain data (validating hundreds of frames would cost seconds)."""
    robot = _thin(robot, MAX_POINTS)
    people = {n: _thin(track, MAX_POINTS) for n, track in people.items()} or _people_from_trace(world, events)
    fig = go.Figure()
    shapes: list[dict[str, Any]] = []
    for o in world.obstacles:
        x0, y0, x1, y1 = o.box
        shapes.append({"type": "rect", "x0": x0, "y0": y0, "x1": x1, "y1": y1, "line": {"width": 0},
                       "fillcolor": _FILL.get(o.kind, "#999"), "layer": "below"})
    for d in world.doors.values():
        x0, y0, x1, y1 = d.box
        shapes.append({"type": "rect", "x0": x0, "y0": y0, "x1": x1, "y1": y1, "layer": "below",
                       "line": {"color": _FILL["door"], "dash": "dash" if d.open else "solid"},
                       "fillcolor": "rgba(0,0,0,0)" if d.open else _FILL["door"]})
    annotations = [{"x": (b[0] + b[2]) / 2, "y": b[3] - 0.3, "text": name, "showarrow": False,
                    "font": {"color": "#777", "size": 11}} for name, b in world.rooms.items()]
    fig.add_trace(go.Scatter(x=[p[0] for p in world.places.values()], y=[p[1] for p in world.places.values()],
                             text=list(world.places), mode="markers+text", textposition="bottom center",
                             marker={"symbol": "triangle-up", "color": "#2a7a2a", "size": 7}, name="places",
                             textfont={"size": 9, "color": "#2a7a2a"}, hoverinfo="text"))
    fig.add_trace(go.Scatter(x=[s[1] for s in robot], y=[s[2] for s in robot], mode="lines", name="robot path",
                             line={"color": "#1f5fbf", "width": 1}, opacity=0.25, hoverinfo="skip"))
    susp_at = [(float(e["t"]), e["agent"], _at(robot, float(e["t"]))) for e in events
               if e["event"] == "command" and e["flag"] == "susp"]
    fig.add_trace(go.Scatter(x=[p[1] for _, _, p in susp_at if p], y=[p[2] for _, _, p in susp_at if p],
                             text=[f"susp {a} at {t:.1f} s" for t, a, p in susp_at if p], mode="markers",
                             marker={"symbol": "x-thin-open", "size": 14, "color": "#c0392b", "line": {"width": 3}},
                             name="robot at susp", hoverinfo="text"))
    t_end = max(robot[-1][0] if robot else 0.0, _end_time(events))
    n = min(MAX_FRAMES, max(2, len(robot)))
    times = [round(t_end * i / (n - 1), 3) for i in range(n)]
    suspended = _suspension_spans(events, t_end)
    roles = [(float(e["t"]), e.get("exeDA")) for e in events if e["event"] == "roles"]
    frames = [{"name": f"{t:g}", "data": _world_state(t, robot, people), "traces": [3, 4, 5],
               "layout": {"title": {"text": _world_title(t, hazards, suspended, roles, t_end)}}} for t in times]
    for trace in _world_state(times[0], robot, people):
        fig.add_trace(go.Scatter(**{k: v for k, v in trace.items() if k != "type"}))
    (x0, y0), (x1, y1) = world.bounds
    steps = [{"method": "animate", "label": f"{t:.0f}", "args": [[f"{t:g}"], {"mode": "immediate",
             "frame": {"duration": 0, "redraw": True}, "transition": {"duration": 0}}]} for t in times]
    fig.update_layout(
        shapes=shapes, annotations=annotations, template="plotly_white", height=680,
        margin={"t": 60, "r": 10, "b": 130},
        title={"text": _world_title(times[0], hazards, suspended, roles, t_end), "font": {"size": 13}},
        xaxis={"range": [x0, x1], "title": "x [m]"}, yaxis={"range": [y0, y1], "scaleanchor": "x", "title": "y [m]"},
        sliders=[{"active": 0, "steps": steps, "currentvalue": {"prefix": "t = ", "suffix": " s"},
                  "x": 0.12, "len": 0.88, "y": 0, "yanchor": "top", "pad": {"t": 50}}],
        updatemenus=[{"type": "buttons", "showactive": False, "x": 0.11, "y": 0, "xanchor": "right",
                      "yanchor": "top", "direction": "left", "pad": {"t": 60, "r": 10},
                      "buttons": [{"label": "▶ play", "method": "animate",
                                   "args": [None, {"frame": {"duration": 60, "redraw": True}, "fromcurrent": True,
                                                   "transition": {"duration": 0}}]},
                                  {"label": "❚❚ pause", "method": "animate",
                                   "args": [[None], {"mode": "immediate", "frame": {"duration": 0}}]}]}])
    out: dict[str, Any] = fig.to_dict()
    out["frames"] = frames
    return out


def _people_from_trace(world: Any, events: Sequence[Event]) -> dict[str, list[tuple[float, float, float, str]]]:
    """Without recorded people: each at the world's initial pose, postures from ``world`` events."""
    out = {n: [(0.0, p.pose[0], p.pose[1], p.posture)] for n, p in world.people.items()}
    for e in events:
        value = e.get("value")
        if e["event"] == "world" and e.get("what") == "posture" and isinstance(value, list) and len(value) == 2 \
                and value[0] in out:
            last = out[value[0]][-1]
            out[value[0]].append((float(e["t"]), last[1], last[2], str(value[1])))
    return out


def _world_state(t: float, robot: Sequence[Sample], people: Mapping[str, Sequence[tuple[float, float, float, str]]]
                 ) -> list[dict[str, Any]]:
    """Traces 3–5 of the world figure at time ``t`` (plain dicts): path so far, robot, people."""
    done = [s for s in robot if s[0] <= t] or list(robot[:1])
    r = _at(robot, t)
    heading = ([r[1], r[1] + 0.45 * math.cos(r[3])], [r[2], r[2] + 0.45 * math.sin(r[3])]) if r else ([], [])
    now = {name: _at(track, t) for name, track in people.items()}
    return [
        {"type": "scatter", "x": [s[1] for s in done] + [None] + heading[0],
         "y": [s[2] for s in done] + [None] + heading[1], "mode": "lines", "name": "path so far",
         "line": {"color": "#1f5fbf", "width": 2.5}, "hoverinfo": "skip"},
        {"type": "scatter", "x": [r[1]] if r else [], "y": [r[2]] if r else [], "mode": "markers", "name": "robot",
         "marker": {"symbol": "pentagon", "size": 16, "color": "#1f5fbf"},
         "hovertemplate": "robot %{x:.2f}, %{y:.2f}<extra></extra>"},
        {"type": "scatter", "x": [p[1] for p in now.values() if p], "y": [p[2] for p in now.values() if p],
         "text": [f"{n} ({p[3]})" if p[3] else n for n, p in now.items() if p], "mode": "markers+text",
         "textposition": "top center", "name": "people", "marker": {"size": 13, "color": "#c0392b"},
         "hoverinfo": "text"},
    ]


def _suspension_spans(events: Sequence[Event], t_end: float) -> list[tuple[str, float, float]]:
    """(agent, from, to) for every stretch from a ``susp`` command to the agent's next ``start``."""
    out: list[tuple[str, float, float]] = []
    since: dict[str, float] = {}
    for e in events:
        if e["event"] == "command" and e["flag"] == "susp":
            since.setdefault(e["agent"], float(e["t"]))
        elif e["event"] in ("command", "end") and e.get("agent") in since and e.get("flag", "start") == "start":
            out.append((e["agent"], since.pop(e["agent"]), float(e["t"])))
    return out + [(a, t0, t_end) for a, t0 in since.items()]


def _world_title(t: float, hazards: Sequence[tuple[str, str, float, float]],
                 suspended: Sequence[tuple[str, float, float]], roles: Sequence[tuple[float, Any]],
                 t_end: float) -> str:
    """The world's title at ``t``; a stretch still open at ``t_end`` (the end of the run) includes it."""
    exe = next((a for tt, a in reversed(roles) if tt <= t), None)
    on = [f"{h[1]} ({h[0]})" for h in hazards if h[2] <= t and (t < h[3] or h[3] >= t_end)]
    susp = sorted({a for a, t0, t1 in suspended if t0 <= t and (t < t1 or t1 >= t_end)})
    parts = [f"t = {t:.1f} s", f"exeDA: {exe or '–'}"]
    parts.append("suspended: " + (", ".join(susp) if susp else "–"))
    parts.append("<span style='color:#c0392b'>hazards on: " + (", ".join(on) if on else "none") + "</span>")
    return " · ".join(parts)


# ----------------------------------------------------------------------------------------- run page


def hazards_of(events: Sequence[Event], metrics: Mapping[str, Any] | None) -> list[tuple[str, str, float, float]]:
    """Hazard stretches: from ``hazard`` events if the trace has them, else from the metrics'
    ``safety.episodes`` (``agent``, ``hazard``, ``subject``, ``start``, ``end``) if present."""
    t_end = _end_time(events)
    spans = hazard_spans(events, t_end)
    if spans or not metrics:
        return spans
    episodes = (metrics.get("safety") or {}).get("episodes") if isinstance(metrics.get("safety"), Mapping) else None
    out = []
    for ep in episodes or []:
        try:
            label = " ".join(str(x) for x in (ep["hazard"], ep.get("subject", "")) if x)
            out.append((str(ep["agent"]), label, float(ep["start"]), float(ep["end"])))
        except (KeyError, TypeError, ValueError):
            continue
    return sorted(out, key=lambda s: (s[2], s[0], s[1]))


def _flatten(m: Mapping[str, Any], prefix: str = "") -> list[tuple[str, Any]]:
    out: list[tuple[str, Any]] = []
    for k, v in sorted(m.items()):
        name = f"{prefix}{k}"
        if isinstance(v, Mapping):
            out += _flatten(v, name + ".")
        elif isinstance(v, bool | int | float | str) or v is None:
            out.append((name, v))
    return out


def run_page(events: Sequence[Event], *, record: Mapping[str, Any] | None = None,
             metrics: Mapping[str, Any] | None = None, world: Any = None, trajectory: Sequence[Sample] = (),
             people: Mapping[str, Sequence[tuple[float, float, float, str]]] | None = None,
             problems: Sequence[Mapping[str, Any]] = ()) -> str:
    """The HTML of a run's report (see the module docstring)."""
    events = list(events)
    record = record or {}
    scenario = record.get("scenario") or {}
    name = str(scenario.get("name") or "run")
    hazards = hazards_of(events, metrics)
    sections = [_summary(events, record)]
    sections += ["<h2>Timeline (cf. Fig. 11)</h2>", figure_div(timeline_figure(events, hazards), "timeline")]
    sections += ["<h2>FSM states and stages</h2>", figure_div(gantt_figure(events), "gantt")]
    sections.append("<h2>World</h2>")
    if world is None:
        sections.append('<p class="note">This run has no world (a synthetic scenario, or run without a '
                        'robot): nothing to show here.</p>')
    else:
        robot = list(trajectory)
        if not robot:
            sections.append('<p class="note">No trajectory was recorded: the world at its start.</p>')
        sections.append(figure_div(world_figure(world, robot, people or {}, events, hazards), "world"))
    sections.append(_details(metrics, problems))
    return page(f"tasker run: {name}", sections)


def _summary(events: Sequence[Event], record: Mapping[str, Any]) -> str:
    settings = record.get("settings") or {}
    scenario = record.get("scenario") or {}
    facts = [("scenario", scenario.get("name", "?")), ("source", scenario.get("source", "")),
             ("seed", record.get("seed", "?")), *sorted(settings.items()),
             ("tasker", record.get("tasker_version", "?"))]
    out = [table(["", ""], [(k, _fmt(v)) for k, v in facts])]
    kinds = _agents(events)
    ends = {e["agent"]: e for e in events if e["event"] == "end"}
    out.append("<h2>Tasks</h2>")
    out.append(table(["agent", "task type", "requested at [s]", "ended at [s]", "cause", "reason"],
                     [(a, kinds[a], _fmt(next(float(e["t"]) for e in events if e["event"] == "request"
                                              and e["agent"] == a)),
                       _fmt(float(ends[a]["t"])) if a in ends else "–", ends[a].get("cause", "") if a in ends else
                       "still running", ends[a].get("reason", "") if a in ends else "") for a in kinds],
                     numeric=(False, False, True, True)))
    return "\n".join(out)


def _details(metrics: Mapping[str, Any] | None, problems: Sequence[Mapping[str, Any]]) -> str:
    out = []
    if problems:
        out.append("<h2>Planning calls (<code>problems/</code>)</h2>")
        out.append('<p class="note">Every planned upTsk and genSusp, as PDDL any planner reads; '
                   "<code>tasker explain RUN_DIR --agent dN --at T</code> shows one with the decisions around it.</p>")
        out.append(table(["t [s]", "agent", "task type", "purpose", "status", "problem", "plan"],
                         [(_fmt(float(p["t"])), p["agent"], p["task_type"], p["purpose"], p["status"],
                           _Raw(f'<a href="problems/{html.escape(p["problem"])}">{html.escape(p["problem"])}</a>'),
                           " ".join(f"({' '.join(s)})" for s in p.get("plan") or [])) for p in problems],
                         numeric=(True,)))
    if metrics:
        rows = []
        for k, v in _flatten(metrics):
            host = k in HOST_DEPENDENT
            rows.append((_Raw(f'<span class="host">{html.escape(k)} (host-dependent)</span>') if host else k,
                         _fmt(v)))
        out.append("<h2>Metrics</h2>")
        out.append('<details><summary>every value of <code>metrics.json</code> (host-dependent values measure '
                   "this machine, not the strategy)</summary>")
        out.append(table(["metric", "value"], rows, numeric=(False, True)))
        out.append("</details>")
    return "\n".join(out)


def write_run(out: Path, events: Sequence[Event], *, record: Mapping[str, Any] | None = None,
              metrics: Mapping[str, Any] | None = None, world: Any = None, trajectory: Sequence[Sample] = ()) -> Path:
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


# ----------------------------------------------------------------------------------------- sweep page


def markdown_html(text: str) -> str:
    """The sweep report's Markdown (headings, paragraphs, pipe tables, `code`) as HTML."""
    out: list[str] = []
    lines = text.splitlines()
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("|"):
            block = []
            while i < len(lines) and lines[i].startswith("|"):
                block.append([c.strip().replace("\\|", "|") for c in _split_row(lines[i])])
                i += 1
            header, body = block[0], [r for r in block[2:]]
            numeric = [False] + [True] * (len(header) - 1)
            out.append(table(header, ([_Raw(_inline(c)) for c in r] for r in body), numeric))
            continue
        if line.startswith("#"):
            level = min(len(line) - len(line.lstrip("#")) + 1, 4)  # the page's <h1> is the title
            if level > 2 or out:
                out.append(f"<h{level}>{_inline(line.lstrip('#').strip())}</h{level}>")
        elif line.strip():
            out.append(f"<p>{_inline(line)}</p>")
        i += 1
    return "\n".join(out)


def _split_row(line: str) -> list[str]:
    cells, cur, esc = [], "", False
    for ch in line.strip()[1:-1]:
        if ch == "|" and not esc:
            cells.append(cur)
            cur = ""
        else:
            cur += ch
        esc = ch == "\\"
    return [*cells, cur]


def _inline(text: str) -> str:
    parts = html.escape(text).split("`")
    return "".join(f"<code>{p}</code>" if i % 2 else p for i, p in enumerate(parts)).replace("*", "")


def sweep_page(markdown_text: str, summaries: Sequence[Any], pairs: Sequence[Any]) -> str:
    """The sweep report as one page: its tables, then a chart per headline metric (mean and 95 %
    CI per strategy and scenario) and the wins/ties/losses of each paired comparison (host-dependent
    metrics are shown, never counted as wins or losses)."""
    from experiments.report import ALL, headline, host_dependent

    title = markdown_text.splitlines()[0].lstrip("# ").strip() if markdown_text else "Sweep report"
    sections = [markdown_html(markdown_text), "<h2>Charts</h2>"]
    scenarios = sorted({s.scenario for s in summaries if s.scenario != ALL})
    groups = scenarios if len(scenarios) > 1 else [ALL]
    strategies = sorted({s.strategy for s in summaries})
    cells = {(s.scenario, s.strategy, s.metric): s.estimate for s in summaries}
    for n, metric in enumerate(headline({s.metric for s in summaries})):
        fig = go.Figure()
        for st in strategies:
            est = [cells.get((g, st, metric)) for g in groups]
            fig.add_trace(go.Bar(
                name=st, x=["all scenarios" if g == ALL else Path(g).stem for g in groups],
                y=[e.mean if e and math.isfinite(e.mean) else None for e in est],
                error_y={"type": "data", "array": [e.half if e and math.isfinite(e.half) else 0 for e in est]},
                customdata=[e.n if e else 0 for e in est],
                hovertemplate=f"{st}<br>%{{x}}: %{{y:.4g}} ± %{{error_y.array:.3g}} (n=%{{customdata}})"
                              "<extra></extra>"))
        note = " (host-dependent: reported, no verdict)" if host_dependent(metric) else ""
        fig.update_layout(title=metric + note, barmode="group", template="plotly_white", height=380,
                          yaxis_title="mean, 95 % CI", legend={"orientation": "h", "y": -0.2},
                          margin={"t": 50, "r": 10})
        sections.append(figure_div(fig, f"metric-{n}"))
    for n, key in enumerate(sorted({(p.dimension, p.planned, p.static) for p in pairs})):
        shown = headline({p.metric for p in pairs})
        mine = sorted((p for p in pairs if (p.dimension, p.planned, p.static) == key and p.scenario == ALL
                       and p.metric in shown and not host_dependent(p.metric)), key=lambda p: shown.index(p.metric))
        if not mine:
            continue
        fig = go.Figure()
        for label, attr, colour in (("planned better", "wins", "#2ca02c"), ("tie", "ties", "#999"),
                                    ("static better", "losses", "#d62728")):
            fig.add_trace(go.Bar(name=label, orientation="h", y=[p.metric for p in mine],
                                 x=[getattr(p, attr) for p in mine], marker_color=colour))
        fig.update_layout(title=f"{key[0]}: {key[1]} vs {key[2]}, (scenario, seed) pairs", barmode="stack",
                          template="plotly_white", height=160 + 34 * len(mine), legend={"orientation": "h", "y": -0.25},
                          margin={"t": 50, "r": 10})
        sections.append(figure_div(fig, f"paired-{n}"))
    return page(title, sections)
