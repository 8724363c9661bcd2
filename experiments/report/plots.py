"""Plots of a run, drawn from its saved trace (and, for paths, its saved trajectory).

* :func:`timeline` is the paper's Fig. 11: Alg. 2's costs over time, its cost rates on
  an axis of their own, above the harmoniser's roles (``exeDA``/``irrDA``/``idleDA``)
  as coloured bands per agent, with hazards marked.
* :func:`gantt` shows every agent's FSM leaf state over time, with stage names in
  lanes that never overlap.
* :func:`world_path` draws the robot's path over a world with :mod:`robot.picture`.

Plots read the run's timeline only (:mod:`experiments.trace.timeline`; STYLE principle 10),
draw on bare :class:`Figure` objects (Agg canvas, no pyplot state, no display), write
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

from experiments.metrics.exposure import KINDS, Stretch, stretches
from experiments.trace.timeline import Timeline
from experiments.trace.timeline import timeline as timeline_of
from tasker import events as ev
from tasker.trace import number

Source = Timeline | Iterable[ev.Event | Mapping[str, Any]]
"""What a plot reads: a run's timeline, or its events (typed, or records as a trace file has them)."""

COSTS = ("cost_dac", "cost_exeDA", "cc_dac", "cc_exeDA", "c_switch", "c_wait")
"""Alg. 2's costs of Fig. 11 (discomfort accumulated by completion; they add up)."""
RATES = ("cps_dac", "cps_exeDA", "ccps_dac", "ccps_exeDA")
"""Alg. 2's cost rates (cost per second): a scale of their own, so they get their own axis."""
COST_KEYS = COSTS + RATES
"""Every Alg. 2 parameter the timeline draws."""
HAZARD_COLOUR = "#c0392b"
HAZARD_COLOURS = {"attended": "#f0b27a", "unattended": "#e74c3c", "over budget": "#78281f", "nobody's": "#95a5a6"}
"""How each kind of hazard stretch is drawn (:mod:`experiments.metrics.exposure`): attended in amber,
unattended in red, over its budget in dark red, nobody's in grey."""

ROLE_COLOURS = {"exeDA": "#2e8b57", "irrDA": "#e67e22", "idleDA": "#b0b0b0"}
STATES = ("initComm", "compSP", "upTsk", "exeTsk", "genSusp", "exeSusp", "wait")
STATE_COLOURS = {"initComm": "#d9d9d9", "compSP": "#a6cee3", "upTsk": "#1f78b4", "exeTsk": "#33a02c",
                 "genSusp": "#fdbf6f", "exeSusp": "#ff7f00", "wait": "#e31a1c"}
_METADATA = {"Software": "tasker"}  # no matplotlib version in the file: same events, same bytes


def _value(e: ev.Decision, key: str) -> float:
    """A decision's number as a float; missing or infinite values become NaN (a gap in the line)."""
    v = e.get(key)
    if v is None:
        return math.nan
    f = number(v)
    return f if math.isfinite(f) else math.nan


def _is_inf(e: ev.Decision, key: str) -> bool:
    v = e.get(key)
    return v is not None and number(v) == math.inf


def _agents(tl: Timeline) -> dict[str, str]:
    """Agent id -> task type, in request order."""
    return {a.id: a.task_type for a in tl.agents.values()}


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


def _mark_commands(ax: Axes, tl: Timeline) -> None:
    """Vertical lines at ``susp`` (red dashed) and ``start`` (green dotted) commands."""
    for c in tl.commands:
        if c.flag in ("susp", "start"):
            style = ("#c0392b", "--") if c.flag == "susp" else ("#2e8b57", ":")
            ax.axvline(c.t, color=style[0], ls=style[1], lw=0.8, alpha=0.7)


def role_spans(tl: Timeline) -> list[tuple[str, str, float, float]]:
    """(agent, role, start, end) for every stretch an agent held a harmoniser role, by end time."""
    spans = [(s.agent, s.role, s.start, s.end) for a in tl.agents.values() for s in a.roles if s.end > s.start]
    return sorted(spans, key=lambda s: (s[3], s[2]))


def _with_gaps(costs: list[ev.Decision]) -> tuple[list[float], list[ev.Decision | None]]:
    """Decision times and events, with a gap (None) wherever no decision was made for a while
    or the compared pair changed: Fig. 11 shows no values while there is no candidate."""
    ts = [e.t for e in costs]
    steps = sorted(b - a for a, b in zip(ts, ts[1:], strict=False) if b > a)
    usual = steps[len(steps) // 2] if steps else 0.0
    out_t: list[float] = []
    out_e: list[ev.Decision | None] = []
    for i, e in enumerate(costs):
        prev = costs[i - 1] if i else None
        if prev is not None and (ts[i] - ts[i - 1] > 3 * usual or (prev.dac, prev.exe_da) != (e.dac, e.exe_da)):
            out_t.append((ts[i - 1] + ts[i]) / 2)
            out_e.append(None)
        out_t.append(ts[i])
        out_e.append(e)
    return out_t, out_e


def hazard_spans(tl: Timeline) -> list[Stretch]:
    """Every hazard episode as stretches attended, unattended, over budget or nobody's
    (:func:`experiments.metrics.exposure.stretches`); one still on at the end lasts until the trace's end."""
    return stretches(tl)


def _mark_other_decisions(axes: Sequence[Axes], tl: Timeline) -> None:
    """Decisions without costs (priority class, baselines) that switched: a purple line on each panel."""
    for d in tl.decisions:
        if d.rule != "cost" and d.switch:
            for ax in axes:
                ax.axvline(d.t, color="#8e44ad", lw=0.8, alpha=0.6)


def _decision_rug(ax: Axes, tl: Timeline) -> None:
    """Without cost decisions: every decision as a tick on a row per rule, switches as diamonds."""
    decisions = tl.decisions
    if not decisions:
        _note(ax, "no decisions")
        return
    rules = sorted({str(d.rule or d.algorithm) for d in decisions})
    row = {r: i for i, r in enumerate(rules)}
    ys = [row[str(d.rule or d.algorithm)] for d in decisions]
    ax.plot([d.t for d in decisions], ys, "|", color="#8e44ad", ms=8, label="decision")
    sw = [(d.t, y) for d, y in zip(decisions, ys, strict=True) if d.switch]
    if sw:
        ax.plot(*zip(*sw, strict=True), "D", color="#c0392b", ms=5, label="switch")
    ax.set_yticks(range(len(rules)), rules, fontsize=8)
    ax.set_ylim(len(rules) - 0.5, -0.5)
    ax.set_ylabel("decisions")
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.005, 1.0))


def _plot_keys(ax: Axes, costs: list[ev.Decision], keys: Sequence[str]) -> None:
    ts, points = _with_gaps(costs)
    for key in keys:
        if not any(key in e.data for e in costs):
            continue
        style = "--" if key.startswith("cc") else "-"  # cc_* often equals cost_*: keep both visible
        (line,) = ax.plot(ts, [_value(e, key) if e else math.nan for e in points], marker=".", ls=style, ms=2.5,
                          lw=1.2 if style == "-" else 1.0, label=key)
        inf = [e.t for e in costs if _is_inf(e, key)]
        if inf:  # infinite costs (no way to do the task from there): triangles along the top edge
            ax.plot(inf, [0.98] * len(inf), "^", ms=3, color=line.get_color(), transform=ax.get_xaxis_transform())
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.005, 1.0))


def timeline(events: Source, out_png: str | Path, *, title: str | None = None) -> Path:
    """Fig. 11: Alg. 2's costs, its cost rates (own axis), and the roles below; returns the PNG path.

    Switches decided by priority class (or by a baseline) are purple lines; ``susp`` commands
    red dashed, ``start`` green dotted; hazards (``hazard`` events) a red strip under their
    agent.  Without cost decisions the top panel shows when each rule decided.
    """
    return _save(timeline_figure(events, title=title), out_png)


def timeline_figure(events: Source, *, title: str | None = None) -> Figure:
    """The figure :func:`timeline` saves (for tests and other outputs)."""
    tl = timeline_of(events)
    t_end = tl.t_end
    costs = [d for d in tl.decisions if d.rule == "cost"]
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
        _decision_rug(top, tl)
        panels = (top,)
    _mark_other_decisions((*panels, bottom), tl)
    for ax in panels:
        _mark_commands(ax, tl)
    agents = list(_agents(tl))
    spans = role_spans(tl)
    hazards = hazard_spans(tl)
    if spans:
        rows = {a: i for i, a in enumerate(agents + sorted({s[0] for s in spans} - set(agents)))}
        for agent, role, t0, t1 in spans:
            bottom.broken_barh([(t0, t1 - t0)], (rows[agent] - 0.4, 0.8), color=ROLE_COLOURS[role])
        for h in hazards:
            if h.owner in rows:
                bottom.broken_barh([(h.start, max(h.end - h.start, 1e-3))], (rows[h.owner] + 0.28, 0.12),
                                   color=HAZARD_COLOURS[h.kind])
        bottom.set_yticks(range(len(rows)), list(rows), fontsize=8)
        bottom.set_ylim(len(rows) - 0.5, -0.5)
        handles = [Patch(color=c, label=r) for r, c in ROLE_COLOURS.items()]
        handles += [Patch(color=HAZARD_COLOURS[k], label=f"hazard {k}") for k in KINDS
                    if any(h.kind == k and h.owner in rows for h in hazards)]
        bottom.legend(handles=handles, fontsize=7, loc="upper left", bbox_to_anchor=(1.005, 1.0))
        _mark_commands(bottom, tl)
    else:
        _note(bottom, "no roles")
    bottom.set_xlabel("time [s]")
    bottom.set_xlim(0.0, max(t_end, 1.0) * 1.01)
    what = "Alg. 2 costs, cost rates" if costs else "decisions"
    top.set_title(title or f"{what} and harmoniser roles (cf. Fig. 11); red dashed: susp, green dotted: start, "
                           "purple: switch by priority class", fontsize=10)
    return fig


def state_spans(tl: Timeline) -> dict[str, list[tuple[str, float, float]]]:
    """Agent -> (state, start, end) from the request to ``end`` (or the end of the trace)."""
    return {a.id: [(s.state, s.start, s.end) for s in a.states] for a in tl.agents.values()}


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


def gantt(events: Source, out_png: str | Path, *, title: str | None = None) -> Path:
    """Every agent's FSM state over time, one row per agent, stage names in lanes above the bars
    (never on top of each other; suspension stages in orange italics; x: stopped or failed)."""
    return _save(gantt_figure(events, title=title), out_png)


def gantt_figure(events: Source, *, title: str | None = None) -> Figure:
    """The figure :func:`gantt` saves."""
    tl = timeline_of(events)
    kinds = _agents(tl)
    t_end = max(tl.t_end, 1.0)
    spans = state_spans(tl)
    width_in = 11.0
    seconds_per_point = t_end * 1.02 / ((width_in - 2.2) * 72)  # axes ≈ figure minus the row labels
    stages = {a: tl.agents[a].stages for a in spans}
    lanes = {a: _label_lanes([(r.begin, r.action) for r in stages[a]], seconds_per_point) for a in spans}
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
        for r, lane in zip(stages[agent], lanes[agent], strict=True):
            susp = r.fsm == "exeSusp"  # suspension stages in the exeSusp colour
            top = base[agent] - 0.32 - lane_h * lane
            ax.plot([r.begin, r.begin], [base[agent] - 0.3, top], color="#999", lw=0.5)
            ax.text(r.begin, top, r.action, fontsize=LABEL_FONT, va="bottom", ha="left",
                    color=STATE_COLOURS["exeSusp"] if susp else "#222", style="italic" if susp else "normal")
        for r in stages[agent]:
            if r.status in ("stopped", "failed") and r.end is not None:
                ax.plot(r.end, base[agent], "x", color="#000", ms=6)
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


class _Labels:
    """Places short labels next to their points so that no two overlap (a greedy search over
    offsets round the point, nearest first; a thin leader line when the label had to move away)."""

    OFFSETS = ((0.1, 0.1), (0.1, -0.3), (-1.0, 0.1), (-1.0, -0.3), (0.1, 0.4), (0.1, -0.6), (-1.0, 0.4),
               (-1.0, -0.6), (0.1, 0.7), (0.1, -0.9), (-1.0, 0.7), (-1.0, -0.9), (0.6, 0.1), (-1.5, 0.1))
    """(dx, dy) in metres; a dx of -1 means 'the label's width to the left'."""

    def __init__(self, metres_per_point: float) -> None:
        self.per_pt = metres_per_point
        self.boxes: list[tuple[float, float, float, float]] = []

    def place(self, ax: Axes, x: float, y: float, text: str, *, fontsize: float, color: str = "#222") -> None:
        w, h = len(text) * 0.55 * fontsize * self.per_pt, 1.2 * fontsize * self.per_pt
        best = None
        for dx, dy in self.OFFSETS:
            bx = x + (dx if dx >= 0 else dx * w - 0.1)
            box = (bx, y + dy, bx + w, y + dy + h)
            if not any(box[0] < b[2] and b[0] < box[2] and box[1] < b[3] and b[1] < box[3] for b in self.boxes):
                best = box
                break
        if best is None:  # crowded everywhere: the first place, as before
            dx, dy = self.OFFSETS[0]
            best = (x + dx, y + dy, x + dx + w, y + dy + h)
        self.boxes.append(best)
        ax.text(best[0], best[1], text, fontsize=fontsize, color=color, va="bottom", ha="left", zorder=6,
                bbox={"boxstyle": "square,pad=0.05", "facecolor": "white", "edgecolor": "none", "alpha": 0.6})
        if math.hypot(best[0] - x, best[1] - y) > 0.45:
            ax.plot([x, best[0]], [y, best[1] + h / 2], "-", color="#999", lw=0.4, zorder=5)


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
               *, title: str | None = None, events: Source | None = None,
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
    tl = timeline_of(events if events is not None else [])
    agents = _agents(tl)
    colour = {a: TASK_COLOURS[k % len(TASK_COLOURS)] for k, a in enumerate(agents)}

    (x0, _), (x1, _) = spec.bounds
    labels = _Labels(metres_per_point=(x1 - x0) / (0.85 * max(4.0, (x1 - x0) * 0.8) * 72))

    def decorate(ax: Axes) -> None:
        changes = tl.exe_changes() or [(0.0, None)]
        handles: dict[str, Any] = {}
        drawn = [k for k, (t0, _) in enumerate(changes)]
        for n, k in enumerate(drawn):  # later stretches on top and thinner: an earlier path under a later one shows
            t0, agent = changes[k]
            t1 = changes[k + 1][0] if k + 1 < len(changes) else math.inf
            seg = [(s[1], s[2]) for s in samples if t0 - 1e-9 <= s[0] <= t1 + 1e-9]
            if len(seg) < 2:
                continue
            c = colour.get(agent, IDLE_COLOUR) if agent else IDLE_COLOUR
            label = f"{agent} {agents.get(agent, '')}" if agent else "no task"
            width = 3.4 - 2.0 * n / max(1, len(drawn) - 1)
            (line,) = ax.plot(*zip(*seg, strict=True), "-", color=c, lw=width, alpha=0.9, label=label,
                              zorder=2 + n / max(1, len(drawn)), solid_capstyle="round")
            handles.setdefault(label, line)
        for s in samples[:: max(1, int(round(30.0 / max(samples[1][0] - samples[0][0], 1e-9))))]\
                if len(samples) > 1 else []:
            ax.plot(s[1], s[2], ".", color="#333", ms=3, zorder=4)
            labels.place(ax, s[1], s[2], f"{s[0]:.0f}s", fontsize=5, color="#333")
        for e in tl.events:
            if isinstance(e, ev.CommandSent) and e.flag == "susp" and (at := _pose_at(samples, e.t)) is not None:
                h = ax.plot(*at, "x", color=colour.get(e.agent, "k"), ms=9, mew=2.2, zorder=5)[0]
                labels.place(ax, at[0], at[1], f"susp {e.agent} {e.t:.0f}s", fontsize=6)
                handles.setdefault("suspension", h)
            elif isinstance(e, ev.TaskEnded) and (at := _pose_at(samples, e.t)) is not None:
                h = ax.plot(*at, "o", mfc="none", color=colour.get(e.agent, "k"), ms=10, mew=1.5, zorder=5)[0]
                labels.place(ax, at[0], at[1], f"{e.agent} {e.reason} {e.t:.0f}s", fontsize=6)
                handles.setdefault("task ends", h)
        for m in getattr(recording, "marks", []):
            h = ax.plot(m.x, m.y, "s", color="#6a3d9a", ms=6, zorder=5)[0]
            labels.place(ax, m.x, m.y, f"{m.action} {m.item} {m.t:.0f}s", fontsize=5, color="#6a3d9a")
            handles.setdefault("object handled", h)
        if handles:
            ax.legend(list(handles.values()), list(handles), fontsize=6, loc="upper right", framealpha=0.8)

    out = Path(out_png)
    out.parent.mkdir(parents=True, exist_ok=True)
    return draw_world(spec, out, robot=robot, people=people, title=title, decorate=decorate,
                      show_walks=recording is None)


def all_plots(events: Source, out_dir: str | Path) -> list[Path]:
    """:func:`timeline` and :func:`gantt` of one run into ``out_dir``; returns the files."""
    out = Path(out_dir)
    tl = timeline_of(events)
    return [timeline(tl, out / "timeline.png"), gantt(tl, out / "gantt.png")]
