"""Plots of a run, drawn from its saved trace (and, for paths, its saved trajectory).

* :func:`timeline` is the paper's Fig. 11: Alg. 2's costs over time, its cost rates on
  an axis of their own, above the harmoniser's roles (``exeDA``/``irrDA``/``idleDA``)
  as coloured bands per agent, with hazards marked.
* :func:`gantt` shows every agent's FSM leaf state over time, with stage names in
  lanes that never overlap.
* :func:`world_path` draws the robot's path over a world with :mod:`robot.picture`.

Plots read events only (STYLE principle 10), draw on bare :class:`Figure` objects
(Agg canvas, no pyplot state, no display), write
PNGs with fixed metadata (same events, same bytes) and never fail on an empty or
tiny trace: they draw a note such as "no decisions" instead.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from tasker.trace import number

Event = Mapping[str, Any]

COSTS = ("cost_dac", "cost_exeDA", "cc_dac", "cc_exeDA", "c_switch", "c_wait")
"""Alg. 2's costs of Fig. 11 (discomfort accumulated by completion; they add up)."""
RATES = ("cps_dac", "cps_exeDA", "ccps_dac", "ccps_exeDA")
"""Alg. 2's cost rates (cost per second): a scale of their own, so they get their own axis."""
COST_KEYS = COSTS + RATES
"""Every Alg. 2 parameter the timeline draws."""
HAZARD_COLOUR = "#c0392b"

ROLE_COLOURS = {"exeDA": "#2e8b57", "irrDA": "#e67e22", "idleDA": "#b0b0b0"}
STATES = ("initComm", "compSP", "upTsk", "exeTsk", "genSusp", "exeSusp", "wait")
STATE_COLOURS = {"initComm": "#d9d9d9", "compSP": "#a6cee3", "upTsk": "#1f78b4", "exeTsk": "#33a02c",
                 "genSusp": "#fdbf6f", "exeSusp": "#ff7f00", "wait": "#e31a1c"}
_METADATA = {"Software": "tasker"}  # no matplotlib version in the file: same events, same bytes


def _value(e: Event, key: str) -> float:
    """A trace number as a float; missing or infinite values become NaN (a gap in the line)."""
    v = e.get(key)
    if v is None:
        return math.nan
    f = number(v)
    return f if math.isfinite(f) else math.nan


def _is_inf(e: Event, key: str) -> bool:
    v = e.get(key)
    return v is not None and number(v) == math.inf


def _end_time(events: Sequence[Event]) -> float:
    return max((float(e["t"]) for e in events), default=0.0)


def _agents(events: Sequence[Event]) -> dict[str, str]:
    """Agent id -> task type, in request order."""
    return {e["agent"]: e.get("task_type", "?") for e in events if e["event"] == "request"}


def _note(ax: Axes, text: str) -> None:
    """A grey note in an empty panel; the x axis is kept (panels share it: clearing it here
    would take the time axis away from the panels below)."""
    ax.text(0.5, 0.5, text, ha="center", va="center", transform=ax.transAxes, fontsize=11, color="#666")
    ax.set_yticks([])


def _save(fig: Figure, out: str | Path) -> Path:
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=100, metadata=_METADATA)
    return out


def _mark_commands(ax: Axes, events: Sequence[Event]) -> None:
    """Vertical lines at ``susp`` (red dashed) and ``start`` (green dotted) commands."""
    for e in events:
        if e["event"] == "command" and e["flag"] in ("susp", "start"):
            style = ("#c0392b", "--") if e["flag"] == "susp" else ("#2e8b57", ":")
            ax.axvline(float(e["t"]), color=style[0], ls=style[1], lw=0.8, alpha=0.7)


def _role_spans(events: Sequence[Event], t_end: float) -> list[tuple[str, str, float, float]]:
    """(agent, role, start, end) for every stretch an agent held a role."""
    spans: list[tuple[str, str, float, float]] = []
    current: dict[str, tuple[str, float]] = {}

    def close(agent: str, t: float) -> None:
        role, t0 = current.pop(agent)
        if t > t0:
            spans.append((agent, role, t0, t))

    for e in events:
        if e["event"] != "roles":
            continue
        t = float(e["t"])
        now = {a: "idleDA" for a in e.get("idleDA") or []}
        for role in ("exeDA", "irrDA"):
            if e.get(role):
                now[e[role]] = role
        for agent in [a for a in current if now.get(a) != current[a][0]]:
            close(agent, t)
        for agent, role in now.items():
            current.setdefault(agent, (role, t))
    for agent in list(current):
        close(agent, t_end)
    return spans


def _with_gaps(costs: list[Event]) -> tuple[list[float], list[Event | None]]:
    """Decision times and events, with a gap (None) wherever no decision was made for a while
    or the compared pair changed: Fig. 11 shows no values while there is no candidate."""
    ts = [float(e["t"]) for e in costs]
    steps = sorted(b - a for a, b in zip(ts, ts[1:], strict=False) if b > a)
    usual = steps[len(steps) // 2] if steps else 0.0
    out_t: list[float] = []
    out_e: list[Event | None] = []
    for i, e in enumerate(costs):
        prev = costs[i - 1] if i else None
        if prev is not None and (ts[i] - ts[i - 1] > 3 * usual or (prev.get("dac"), prev.get("exeDA"))
                                 != (e.get("dac"), e.get("exeDA"))):
            out_t.append((ts[i - 1] + ts[i]) / 2)
            out_e.append(None)
        out_t.append(ts[i])
        out_e.append(e)
    return out_t, out_e


def hazard_spans(events: Sequence[Event], t_end: float) -> list[tuple[str, str, float, float]]:
    """(agent, hazard label, start, end) from ``hazard`` events (``status`` on/off); a hazard
    still on at the end of the trace lasts until ``t_end``; one no agent owns (``agent: null``,
    e.g. a door open in the world file) is labelled ``unowned``."""
    spans: list[tuple[str, str, float, float]] = []
    on: dict[tuple[str, str], float] = {}
    for e in events:
        if e["event"] != "hazard":
            continue
        label = " ".join([str(e.get("hazard", "?")), *(str(a) for a in e.get("args") or [])])
        key = (str(e.get("agent") or "unowned"), label)
        if e.get("status") == "on":
            on.setdefault(key, float(e["t"]))
        elif key in on:
            spans.append((*key, on.pop(key), float(e["t"])))
    spans += [(*key, t0, t_end) for key, t0 in on.items()]
    return sorted(spans, key=lambda s: (s[2], s[0], s[1]))


def _mark_other_decisions(axes: Sequence[Axes], events: Sequence[Event]) -> None:
    """Decisions without costs (priority class, baselines) that switched: a purple line on each panel."""
    for e in events:
        if e["event"] == "decision" and e.get("rule") != "cost" and e.get("switch"):
            for ax in axes:
                ax.axvline(float(e["t"]), color="#8e44ad", lw=0.8, alpha=0.6)


def _decision_rug(ax: Axes, events: Sequence[Event]) -> None:
    """Without cost decisions: every decision as a tick on a row per rule, switches as diamonds."""
    decisions = [e for e in events if e["event"] == "decision"]
    if not decisions:
        _note(ax, "no decisions")
        return
    rules = sorted({str(e.get("rule") or e.get("algorithm", "?")) for e in decisions})
    row = {r: i for i, r in enumerate(rules)}
    ys = [row[str(e.get("rule") or e.get("algorithm", "?"))] for e in decisions]
    ax.plot([float(e["t"]) for e in decisions], ys, "|", color="#8e44ad", ms=8, label="decision")
    sw = [(float(e["t"]), y) for e, y in zip(decisions, ys, strict=True) if e.get("switch")]
    if sw:
        ax.plot(*zip(*sw, strict=True), "D", color="#c0392b", ms=5, label="switch")
    ax.set_yticks(range(len(rules)), rules, fontsize=8)
    ax.set_ylim(len(rules) - 0.5, -0.5)
    ax.set_ylabel("decisions")
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.005, 1.0))


def _plot_keys(ax: Axes, costs: list[Event], keys: Sequence[str]) -> None:
    ts, points = _with_gaps(costs)
    for key in keys:
        if not any(key in e for e in costs):
            continue
        style = "--" if key.startswith("cc") else "-"  # cc_* often equals cost_*: keep both visible
        (line,) = ax.plot(ts, [_value(e, key) if e else math.nan for e in points], marker=".", ls=style, ms=2.5,
                          lw=1.2 if style == "-" else 1.0, label=key)
        inf = [float(e["t"]) for e in costs if _is_inf(e, key)]
        if inf:  # infinite costs (no way to do the task from there): triangles along the top edge
            ax.plot(inf, [0.98] * len(inf), "^", ms=3, color=line.get_color(), transform=ax.get_xaxis_transform())
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.005, 1.0))


def timeline(events: Sequence[Event], out_png: str | Path, *, title: str | None = None) -> Path:
    """Fig. 11: Alg. 2's costs, its cost rates (own axis), and the roles below; returns the PNG path.

    Switches decided by priority class (or by a baseline) are purple lines; ``susp`` commands
    red dashed, ``start`` green dotted; hazards (``hazard`` events) a red strip under their
    agent.  Without cost decisions the top panel shows when each rule decided.
    """
    return _save(timeline_figure(events, title=title), out_png)


def timeline_figure(events: Sequence[Event], *, title: str | None = None) -> Figure:
    """The figure :func:`timeline` saves (for tests and other outputs)."""
    events = list(events)
    t_end = _end_time(events)
    costs = [e for e in events if e["event"] == "decision" and e.get("rule") == "cost"]
    fig = Figure(figsize=(11, 7 if costs else 5), layout="constrained")
    if costs:
        top, mid, bottom = fig.subplots(3, 1, sharex=True, gridspec_kw={"height_ratios": [3, 1.2, 1.6]})
        _plot_keys(top, costs, COSTS)
        _plot_keys(mid, costs, RATES)
        top.set_ylabel("cost")
        mid.set_ylabel("rate [cost/s]")
        panels: tuple[Axes, ...] = (top, mid)
    else:  # priority class or a baseline: no costs to draw, but when it decided and switched
        top, bottom = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [1.2, 1.6]})
        _decision_rug(top, events)
        panels = (top,)
    _mark_other_decisions((*panels, bottom), events)
    for ax in panels:
        _mark_commands(ax, events)
    agents = list(_agents(events))
    spans = _role_spans(events, t_end)
    hazards = hazard_spans(events, t_end)
    if spans:
        rows = {a: i for i, a in enumerate(agents + sorted({s[0] for s in spans} - set(agents)))}
        for agent, role, t0, t1 in spans:
            bottom.broken_barh([(t0, t1 - t0)], (rows[agent] - 0.4, 0.8), color=ROLE_COLOURS[role])
        for agent, _, t0, t1 in hazards:
            if agent in rows:
                bottom.broken_barh([(t0, max(t1 - t0, 1e-3))], (rows[agent] + 0.28, 0.12), color=HAZARD_COLOUR)
        bottom.set_yticks(range(len(rows)), list(rows), fontsize=8)
        bottom.set_ylim(len(rows) - 0.5, -0.5)
        handles = [Patch(color=c, label=r) for r, c in ROLE_COLOURS.items()]
        if hazards:
            handles.append(Patch(color=HAZARD_COLOUR, label="hazard on"))
        bottom.legend(handles=handles, fontsize=7, loc="upper left", bbox_to_anchor=(1.005, 1.0))
        _mark_commands(bottom, events)
    else:
        _note(bottom, "no roles")
    bottom.set_xlabel("time [s]")
    bottom.set_xlim(0.0, max(t_end, 1.0) * 1.01)
    what = "Alg. 2 costs, cost rates" if costs else "decisions"
    top.set_title(title or f"{what} and harmoniser roles (cf. Fig. 11); red dashed: susp, green dotted: start, "
                           "purple: switch by priority class", fontsize=10)
    return fig


def _state_spans(events: Sequence[Event], t_end: float) -> dict[str, list[tuple[str, float, float]]]:
    """Agent -> (state, start, end) from the request to ``end`` (or the end of the trace)."""
    spans: dict[str, list[tuple[str, float, float]]] = {}
    current: dict[str, tuple[str, float]] = {}
    for e in events:
        t = float(e["t"])
        if e["event"] == "request":
            current[e["agent"]] = ("initComm", t)
            spans.setdefault(e["agent"], [])
        elif e["event"] == "transition":
            agent = e["agent"]
            state, t0 = current.pop(agent, (e["from"], t))
            spans.setdefault(agent, []).append((state, t0, t))
            if e["to"] != "end":
                current[agent] = (e["to"], t)
    for agent, (state, t0) in current.items():
        spans[agent].append((state, t0, t_end))
    return spans


LABEL_FONT = 7
MAX_LANES = 6


def _label_lanes(labels: Sequence[tuple[float, str]], seconds_per_point: float) -> list[int]:
    """A lane (0 = nearest the bar) for each ``(t, label)`` so that no two labels in a lane
    overlap; ``seconds_per_point`` converts text width to time.  Labels past
    :data:`MAX_LANES` share the least crowded lane."""
    ends: list[float] = []
    out = []
    for t, label in labels:
        width = (len(label) * 0.6 + 1.0) * LABEL_FONT * seconds_per_point
        lane = next((i for i, end in enumerate(ends) if end <= t), None)
        if lane is None:
            if len(ends) < MAX_LANES:
                ends.append(-math.inf)
                lane = len(ends) - 1
            else:
                lane = min(range(len(ends)), key=lambda i: ends[i])
        ends[lane] = t + width
        out.append(lane)
    return out


def gantt(events: Sequence[Event], out_png: str | Path, *, title: str | None = None) -> Path:
    """Every agent's FSM state over time, one row per agent, stage names in lanes above the bars
    (never on top of each other; suspension stages in orange italics; x: stopped or failed)."""
    return _save(gantt_figure(events, title=title), out_png)


def gantt_figure(events: Sequence[Event], *, title: str | None = None) -> Figure:
    """The figure :func:`gantt` saves."""
    events = list(events)
    kinds = _agents(events)
    t_end = max(_end_time(events), 1.0)
    spans = _state_spans(events, t_end)
    width_in = 11.0
    seconds_per_point = t_end * 1.02 / ((width_in - 2.2) * 72)  # axes ≈ figure minus the row labels
    stages = {a: [e for e in events if e["event"] == "stage" and e.get("agent") == a] for a in spans}
    lanes = {a: _label_lanes([(float(e["t"]), e["action"]) for e in stages[a] if e["status"] == "begin"],
                             seconds_per_point) for a in spans}
    lane_h = 0.32
    heights = {a: 1.0 + lane_h * (max(lanes[a], default=-1) + 1) for a in spans}
    fig = Figure(figsize=(width_in, 1.6 + 0.45 * max(1.0, sum(heights.values()))), layout="constrained")
    ax = fig.subplots()
    if not spans:
        _note(ax, "no agents")
        ax.set_xticks([])
        return fig
    base: dict[str, float] = {}
    y = 0.0
    for agent in spans:  # each row: its label lanes, then the bar
        y += heights[agent]
        base[agent] = y - 0.5
    for agent, stretch in spans.items():
        for state, t0, t1 in stretch:
            ax.broken_barh([(t0, max(t1 - t0, 1e-3))], (base[agent] - 0.3, 0.6), color=STATE_COLOURS.get(state, "#555"))
        begins = [e for e in stages[agent] if e["status"] == "begin"]
        for e, lane in zip(begins, lanes[agent], strict=True):
            susp = e.get("fsm") == "exeSusp"  # suspension stages in the exeSusp colour
            t = float(e["t"])
            top = base[agent] - 0.32 - lane_h * lane
            ax.plot([t, t], [base[agent] - 0.3, top], color="#999", lw=0.5)
            ax.text(t, top, e["action"], fontsize=LABEL_FONT, va="bottom", ha="left",
                    color=STATE_COLOURS["exeSusp"] if susp else "#222", style="italic" if susp else "normal")
        for e in stages[agent]:
            if e["status"] in ("stopped", "failed"):
                ax.plot(float(e["t"]), base[agent], "x", color="#000", ms=6)
    ax.set_yticks([base[a] for a in spans], [f"{a} {kinds.get(a, '?')}" for a in spans], fontsize=8)
    ax.set_ylim(y + 0.1, -0.1)
    ax.set_xlim(0.0, t_end * 1.02)
    ax.set_xlabel("time [s]")
    fig.legend(handles=[Patch(color=STATE_COLOURS[s], label=s) for s in STATES], fontsize=7, ncol=7,
               loc="outside lower center")
    ax.set_title(title or "dynamic agents' FSM states (stage names at their start; x: stopped or failed)",
                 fontsize=10)
    return fig


TASK_COLOURS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22")
IDLE_COLOUR = "#9a9a9a"


def _executing(events: Sequence[Event]) -> list[tuple[float, str | None]]:
    """(time, exeDA) at every change of the harmoniser's executing agent."""
    out: list[tuple[float, str | None]] = []
    for e in events:
        if e["event"] == "roles" and (not out or out[-1][1] != e.get("exeDA")):
            out.append((float(e["t"]), e.get("exeDA")))
    return out


def _pose_at(samples: Sequence[tuple[float, ...]], t: float) -> tuple[float, float] | None:
    """The robot's position at ``t``: the last sample at or before it."""
    best = None
    for s in samples:
        if s[0] > t + 1e-9:
            break
        best = (s[1], s[2])
    return best if best is not None else ((samples[0][1], samples[0][2]) if samples else None)


def world_path(world_name_or_path: Any, trajectory: Iterable[Sequence[float]], out_png: str | Path,
               people: Mapping[str, tuple[tuple[float, float, float], str]] | None = None,
               *, title: str | None = None, events: Sequence[Event] | None = None,
               recording: Any = None) -> Path:
    """The world seen from above with the robot's path (``trajectory``: (t, x, y, yaw) samples).

    ``world_name_or_path`` may also be a loaded :class:`robot.spec.WorldSpec` (a run's
    world with the scenario's changes to people).  With the run's trace ``events`` the
    path is coloured by the task executing (the harmoniser's ``exeDA``, grey when none),
    with a dot and the time every 30 s, an ``x`` where a task was told to suspend
    (``command`` with ``flag = "susp"``) and a marker where each task ended.  With the
    run's ``recording`` (:class:`robot.recording.Recorder`) people are drawn as they were
    at the end, and a square marks where the robot handled an object.  ``people`` (name →
    (pose, posture)) overrides where people are drawn.
    """
    from robot.picture import draw_world
    from robot.spec import load_world

    spec = world_name_or_path if hasattr(world_name_or_path, "places") else load_world(world_name_or_path)
    samples = [tuple(float(v) for v in s) for s in trajectory]
    robot = (samples[-1][1], samples[-1][2], samples[-1][3]) if samples else None
    if people is None and recording is not None and recording.samples:
        people = {p.name: ((p.x, p.y, p.yaw), p.posture) for p in recording.samples[-1].people}
    if title is None:
        title = f"{spec.name}: robot path, {samples[-1][0] - samples[0][0]:.1f} s" if samples else \
            f"{spec.name}: no trajectory"
    evs = list(events or [])
    agents = _agents(evs)
    colour = {a: TASK_COLOURS[k % len(TASK_COLOURS)] for k, a in enumerate(agents)}

    def decorate(ax: Axes) -> None:
        changes = _executing(evs) or [(0.0, None)]
        handles: dict[str, Any] = {}
        for k, (t0, agent) in enumerate(changes):
            t1 = changes[k + 1][0] if k + 1 < len(changes) else math.inf
            seg = [(s[1], s[2]) for s in samples if t0 - 1e-9 <= s[0] <= t1 + 1e-9]
            if len(seg) < 2:
                continue
            c = colour.get(agent, IDLE_COLOUR) if agent else IDLE_COLOUR
            label = f"{agent} {agents.get(agent, '')}" if agent else "no task"
            (line,) = ax.plot(*zip(*seg, strict=True), "-", color=c, lw=1.8, label=label)
            handles.setdefault(label, line)
        for s in samples[:: max(1, int(round(30.0 / max(samples[1][0] - samples[0][0], 1e-9))))]\
                if len(samples) > 1 else []:
            ax.plot(s[1], s[2], ".", color="#333", ms=3)
            ax.text(s[1] + 0.08, s[2] + 0.08, f"{s[0]:.0f}s", fontsize=5, color="#333")
        for e in evs:
            at = _pose_at(samples, float(e["t"]))
            if at is None:
                continue
            if e["event"] == "command" and e.get("flag") == "susp":
                h = ax.plot(*at, "x", color=colour.get(e["agent"], "k"), ms=9, mew=2.2)[0]
                ax.text(at[0] + 0.1, at[1] - 0.25, f"susp {e['agent']} {float(e['t']):.0f}s", fontsize=6)
                handles.setdefault("suspension", h)
            elif e["event"] == "end":
                h = ax.plot(*at, "o", mfc="none", color=colour.get(e["agent"], "k"), ms=10, mew=1.5)[0]
                ax.text(at[0] + 0.1, at[1] + 0.15, f"{e['agent']} {e.get('reason', 'end')} {float(e['t']):.0f}s",
                        fontsize=6)
                handles.setdefault("task ends", h)
        for m in getattr(recording, "marks", []):
            h = ax.plot(m.x, m.y, "s", color="#6a3d9a", ms=6)[0]
            ax.text(m.x + 0.12, m.y - 0.3, f"{m.action} {m.item} {m.t:.0f}s", fontsize=5, color="#6a3d9a")
            handles.setdefault("object handled", h)
        if handles:
            ax.legend(list(handles.values()), list(handles), fontsize=6, loc="upper right", framealpha=0.8)

    out = Path(out_png)
    out.parent.mkdir(parents=True, exist_ok=True)
    return draw_world(spec, out, robot=robot, people=people, title=title, decorate=decorate,
                      show_walks=recording is None)


def all_plots(events: Sequence[Event], out_dir: str | Path) -> list[Path]:
    """:func:`timeline` and :func:`gantt` of one run into ``out_dir``; returns the files."""
    out = Path(out_dir)
    return [timeline(events, out / "timeline.png"), gantt(events, out / "gantt.png")]
