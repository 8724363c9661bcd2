"""Plots of a run, drawn from its saved trace (and, for paths, its saved trajectory).

* :func:`timeline` is the paper's Fig. 11: Alg. 2's costs over time above the
  harmoniser's roles (``exeDA``/``irrDA``/``idleDA``) as coloured bands per agent.
* :func:`gantt` shows every agent's FSM leaf state over time, with stage actions.
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

COST_KEYS = ("cost_dac", "cost_exeDA", "cc_dac", "cc_exeDA", "ccps_dac", "ccps_exeDA", "c_switch", "c_wait")
"""The Alg. 2 parameters of Fig. 11, in its legend order."""

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
    ax.text(0.5, 0.5, text, ha="center", va="center", transform=ax.transAxes, fontsize=11, color="#666")
    ax.set_xticks([])
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


def timeline(events: Sequence[Event], out_png: str | Path, *, title: str | None = None) -> Path:
    """Fig. 11: Alg. 2's cost parameters over time, the roles below; returns the PNG path."""
    events = list(events)
    fig = Figure(figsize=(11, 6), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [3, 1.4]})
    costs = [e for e in events if e["event"] == "decision" and e.get("rule") == "cost"]
    if costs:
        ts, points = _with_gaps(costs)
        for key in COST_KEYS:
            (line,) = top.plot(ts, [_value(e, key) if e else math.nan for e in points], ".-", ms=2.5, lw=1, label=key)
            inf = [float(e["t"]) for e in costs if _is_inf(e, key)]
            if inf:  # infinite costs (no way to do the task from there): triangles along the top edge
                top.plot(inf, [0.98] * len(inf), "^", ms=3, color=line.get_color(), transform=top.get_xaxis_transform())
        top.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.005, 1.0))
        top.set_ylabel("Alg. 2 parameters")
        _mark_commands(top, events)
    else:
        _note(top, "no decisions")
    for e in events:  # decisions without costs (priority class, baselines): a tick on top
        if e["event"] == "decision" and e.get("rule") != "cost" and costs:
            top.axvline(float(e["t"]), color="#8e44ad", lw=0.6, alpha=0.5)
    agents = list(_agents(events))
    spans = _role_spans(events, _end_time(events))
    if spans:
        rows = {a: i for i, a in enumerate(agents + sorted({s[0] for s in spans} - set(agents)))}
        for agent, role, t0, t1 in spans:
            bottom.broken_barh([(t0, t1 - t0)], (rows[agent] - 0.4, 0.8), color=ROLE_COLOURS[role])
        bottom.set_yticks(range(len(rows)), list(rows), fontsize=8)
        bottom.set_ylim(len(rows) - 0.5, -0.5)
        bottom.legend(handles=[Patch(color=c, label=r) for r, c in ROLE_COLOURS.items()], fontsize=7,
                      loc="upper left", bbox_to_anchor=(1.005, 1.0))
        _mark_commands(bottom, events)
        bottom.set_xlabel("time [s]")
    else:
        _note(bottom, "no roles")
    top.set_title(title or "Alg. 2 parameters and harmoniser roles (cf. Fig. 11)", fontsize=10)
    return _save(fig, out_png)


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


def gantt(events: Sequence[Event], out_png: str | Path, *, title: str | None = None) -> Path:
    """Every agent's FSM state over time, one row per agent, stage actions annotated."""
    events = list(events)
    kinds = _agents(events)
    spans = _state_spans(events, _end_time(events))
    fig = Figure(figsize=(10, 1.8 + 0.7 * max(1, len(spans))), layout="constrained")
    ax = fig.subplots()
    if not spans:
        _note(ax, "no agents")
        return _save(fig, out_png)
    rows = {a: i for i, a in enumerate(spans)}
    for agent, stretch in spans.items():
        for state, t0, t1 in stretch:
            colour = STATE_COLOURS.get(state, "#555")
            ax.broken_barh([(t0, max(t1 - t0, 1e-3))], (rows[agent] - 0.35, 0.7), color=colour)
    for e in events:
        if e["event"] == "stage" and e["status"] == "begin" and e["agent"] in rows:
            susp = e.get("fsm") == "exeSusp"  # suspension stages in the exeSusp colour
            ax.annotate(e["action"], (float(e["t"]), rows[e["agent"]] - 0.38), fontsize=6, rotation=30, va="bottom",
                        color=STATE_COLOURS["exeSusp"] if susp else "#222", style="italic" if susp else "normal")
        elif e["event"] == "stage" and e["status"] in ("stopped", "failed") and e["agent"] in rows:
            ax.plot(float(e["t"]), rows[e["agent"]], "x", color="#000", ms=5)
    ax.set_yticks(range(len(rows)), [f"{a} {kinds.get(a, '?')}" for a in rows], fontsize=8)
    ax.set_ylim(len(rows) - 0.2, -0.9)
    ax.set_xlabel("time [s]")
    fig.legend(handles=[Patch(color=STATE_COLOURS[s], label=s) for s in STATES], fontsize=7, ncol=7,
               loc="outside lower center")
    ax.set_title(title or "dynamic agents' FSM states (stage names at their start; x: stopped or failed)",
                 fontsize=10)
    return _save(fig, out_png)


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
