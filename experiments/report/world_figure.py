"""The world of a run's page: the apartment from above with a time slider over the trajectory.

Reads a recorded trajectory file of the run (:func:`read_trajectory`) or takes the run's own,
and draws (:func:`world_figure`) the robot, its path so far, people, and in the title the
hazards on, the suspended agents and the agent executing at each moment.  The figure is a
plain dict: its frames are data, never validated one by one (that would cost seconds).
"""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

import plotly.graph_objects as go

from experiments.metrics.exposure import Stretch
from experiments.report.plots import Source
from experiments.trace.timeline import Timeline
from experiments.trace.timeline import timeline as timeline_of
from tasker import events as ev

if TYPE_CHECKING:
    from robot.spec import WorldSpec

_S = TypeVar("_S", bound=tuple[Any, ...])
Sample = tuple[float, float, float, float]
MAX_FRAMES = 240
MAX_POINTS = 300
"""At most this many samples of a trajectory are drawn (the file keeps them all)."""


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


def world_figure(world: WorldSpec, robot: Sequence[Sample],
                 people: Mapping[str, Sequence[tuple[float, float, float, str]]], events: Source,
                 hazards: Sequence[Stretch]) -> dict[str, Any]:
    """The world from above, a time slider over the trajectory: the robot, its path so far,
    people, the hazards on and the agent executing at that moment; red crosses where the robot
    was at each ``susp`` command.  A figure dict: its
    frames are built as plain data (validating hundreds of frames would cost seconds)."""
    tl = timeline_of(events)
    robot = _thin(robot, MAX_POINTS)
    people = {n: _thin(track, MAX_POINTS) for n, track in people.items()} or _people_from_trace(world, tl)
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
    susp_at = [(c.t, c.agent, _at(robot, c.t)) for c in tl.commands if c.flag == "susp"]
    fig.add_trace(go.Scatter(x=[p[1] for _, _, p in susp_at if p], y=[p[2] for _, _, p in susp_at if p],
                             text=[f"susp {a} at {t:.1f} s" for t, a, p in susp_at if p], mode="markers",
                             marker={"symbol": "x-thin-open", "size": 14, "color": "#c0392b", "line": {"width": 3}},
                             name="robot at susp", hoverinfo="text"))
    t_end = max(robot[-1][0] if robot else 0.0, tl.t_end)
    n = min(MAX_FRAMES, max(2, len(robot)))
    times = [round(t_end * i / (n - 1), 3) for i in range(n)]
    suspended = _suspension_spans(tl, t_end)
    roles = [(r.t, r.exe_da) for r in tl.roles]
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


def _people_from_trace(world: WorldSpec, tl: Timeline) -> dict[str, list[tuple[float, float, float, str]]]:
    """Without recorded people: each at the world's initial pose, postures from ``world`` events."""
    out = {n: [(0.0, p.pose[0], p.pose[1], p.posture)] for n, p in world.people.items()}
    for e in tl.world:
        value = e.value
        if e.what == "posture" and isinstance(value, list) and len(value) == 2 and value[0] in out:
            last = out[value[0]][-1]
            out[value[0]].append((e.t, last[1], last[2], str(value[1])))
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


def _suspension_spans(tl: Timeline, t_end: float) -> list[tuple[str, float, float]]:
    """(agent, from, to) for every stretch from a ``susp`` command to the agent's next ``start`` (or end)."""
    out: list[tuple[str, float, float]] = []
    since: dict[str, float] = {}
    for e in tl.events:
        if isinstance(e, ev.CommandSent) and e.flag == "susp":
            since.setdefault(e.agent, e.t)
        elif (isinstance(e, ev.CommandSent) and e.flag == "start" or isinstance(e, ev.TaskEnded)) \
                and e.agent in since:
            out.append((e.agent, since.pop(e.agent), e.t))
    return out + [(a, t0, t_end) for a, t0 in since.items()]


def _world_title(t: float, hazards: Sequence[Stretch],
                 suspended: Sequence[tuple[str, float, float]], roles: Sequence[tuple[float, Any]],
                 t_end: float) -> str:
    """The world's title at ``t``; a stretch still open at ``t_end`` (the end of the run) includes it."""
    exe = next((a for tt, a in reversed(roles) if tt <= t), None)
    now = [h for h in hazards if h.start <= t and (t < h.end or h.end >= t_end)]
    on = [f"{h.label} ({h.owner}, {h.kind})" for h in now if h.owner is not None]
    unowned = sum(1 for h in now if h.owner is None)  # e.g. doors open in the world file: nobody's to attend
    if unowned:
        on.append(f"{unowned} nobody owns")
    susp = sorted({a for a, t0, t1 in suspended if t0 <= t and (t < t1 or t1 >= t_end)})
    parts = [f"t = {t:.1f} s", f"exeDA: {exe or '–'}"]
    parts.append("suspended: " + (", ".join(susp) if susp else "–"))
    parts.append("<span style='color:#c0392b'>hazards on: " + (", ".join(on) if on else "none") + "</span>")
    return " · ".join(parts)
