"""Plots write real PNGs from synthetic and hand-built traces, and survive empty ones."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from experiments.inputs import synthetic
from experiments.report import plots
from experiments.trace.timeline import Timeline
from tests.experiments.events import completed

DEMO = Path(__file__).resolve().parents[2] / "experiments" / "inputs" / "scenarios" / "synthetic_demo.toml"
PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def events() -> list[dict[str, Any]]:
    return synthetic.run(synthetic.load(DEMO), seed=1).events


def is_png(path: Path, min_bytes: int = 2000) -> bool:
    data = path.read_bytes()
    return data[:8] == PNG and len(data) >= min_bytes


TINY = completed([
    {"t": 0.0, "event": "run", "seed": 1},
    {"t": 0.0, "event": "request", "agent": "d1", "task_type": "cook", "args": {}, "requester": "x"},
])


@pytest.mark.slow
@pytest.mark.parametrize("plot", [plots.timeline, plots.gantt])
def test_plots_of_the_demo(plot: Any, events: list[dict[str, Any]], tmp_path: Path) -> None:
    out = plot(events, tmp_path / "sub" / "p.png")
    assert out == tmp_path / "sub" / "p.png"
    assert is_png(out, 10_000)


@pytest.mark.parametrize("plot", [plots.timeline, plots.gantt])
@pytest.mark.parametrize("trace", [[], TINY], ids=["empty", "tiny"])
def test_plots_of_empty_and_tiny_traces(plot: Any, trace: list[dict[str, Any]], tmp_path: Path) -> None:
    assert is_png(plot(trace, tmp_path / "p.png"))


@pytest.mark.slow
def test_same_events_same_bytes(events: list[dict[str, Any]], tmp_path: Path) -> None:
    a = plots.timeline(events, tmp_path / "a.png").read_bytes()
    b = plots.timeline(events, tmp_path / "b.png").read_bytes()
    assert a == b


def test_timeline_with_infinite_costs_and_priority_decisions(tmp_path: Path) -> None:
    trace = TINY + [
        {"t": 1.0, "event": "decision", "algorithm": "alg2", "dac": "d2", "exeDA": "d1", "rule": "cost",
         "cost_dac": "inf", "c_switch": 3.0, "c_wait": 2.0, "switch": False},
        {"t": 2.0, "event": "decision", "algorithm": "alg2", "dac": "d2", "exeDA": "d1", "rule": "priority class",
         "switch": True},
        {"t": 2.0, "event": "roles", "exeDA": "d1", "irrDA": "d2", "idleDA": []},
        {"t": 2.0, "event": "command", "agent": "d1", "flag": "susp"},
    ]
    assert is_png(plots.timeline(completed(trace), tmp_path / "t.png"))


def test_role_spans_follow_roles_events() -> None:
    roles = [
        {"t": 0.0, "event": "roles", "exeDA": None, "irrDA": None, "idleDA": ["d1"]},
        {"t": 1.0, "event": "roles", "exeDA": "d1", "irrDA": None, "idleDA": ["d2"]},
        {"t": 4.0, "event": "roles", "exeDA": "d1", "irrDA": "d2", "idleDA": []},
    ]
    requests = [{"t": 0.0, "event": "request", "agent": a} for a in ("d1", "d2")]
    roles.append({"t": 6.0, "event": "mode", "mode": "IT"})  # the trace goes on to t = 6
    assert plots.role_spans(Timeline.of(completed(requests + roles))) == [
        ("d1", "idleDA", 0.0, 1.0), ("d2", "idleDA", 1.0, 4.0), ("d1", "exeDA", 1.0, 6.0), ("d2", "irrDA", 4.0, 6.0),
    ]


def test_state_spans_from_transitions(events: list[dict[str, Any]]) -> None:
    spans = plots.state_spans(Timeline.of(events))
    assert [s[0] for s in spans["d1"]] == ["initComm", "compSP", "upTsk", "exeTsk", "genSusp", "exeSusp", "wait",
                                           "upTsk", "exeTsk"]
    assert spans["d1"][-1][2] == 69.5  # ends at its end transition, not at the given end


@pytest.mark.slow
def test_world_path(tmp_path: Path) -> None:
    trajectory = [(0.0, 4.0, 3.0, 0.0), (1.0, 3.0, 2.5, 0.3), (2.0, 2.0, 2.0, 0.6)]
    assert is_png(plots.world_path("paper", trajectory, tmp_path / "w.png"), 10_000)
    assert is_png(plots.world_path("flat", [], tmp_path / "w0.png"), 10_000)


@pytest.mark.slow
def test_all_plots(events: list[dict[str, Any]], tmp_path: Path) -> None:
    assert [p.name for p in plots.all_plots(events, tmp_path)] == ["timeline.png", "gantt.png"]


def test_world_path_with_trace_and_recording(tmp_path: Path) -> None:
    from robot.recording import PersonState, Recorder

    rec = Recorder("paper")
    for k in range(40):
        rec.record(k * 0.5, (6.0, 1.0 + 0.1 * k, 1.57), [PersonState("sara", 5.4, 3.2, 0.0, "fallen")])
    rec.mark(10.0, "pan", "put_down", 6.0, 3.0)
    events = completed([{"t": 0.0, "event": "request", "agent": "d1", "task_type": "cook"},
                        {"t": 0.0, "event": "roles", "exeDA": "d1"},
                        {"t": 8.0, "event": "command", "agent": "d1", "flag": "susp"},
                        {"t": 9.0, "event": "roles", "exeDA": None},
                        {"t": 19.0, "event": "end", "agent": "d1", "reason": "finished"}])
    traj = [(s.t, *s.robot) for s in rec.samples]
    assert is_png(plots.world_path("paper", traj, tmp_path / "w.png", events=events, recording=rec), 10_000)


def _lines(ax: Any) -> set[str]:
    return {str(line.get_label()) for line in ax.get_lines() if not str(line.get_label()).startswith("_")}


def test_timeline_puts_rates_on_their_own_axis(events: list[dict[str, Any]]) -> None:
    fig = plots.timeline_figure(events)
    costs, rates, roles = fig.axes[:3]
    assert _lines(costs) and _lines(costs) <= set(plots.COSTS)
    assert _lines(rates) and _lines(rates) <= set(plots.RATES)
    assert roles.get_xlabel() == "time [s]"


def test_timeline_keeps_its_time_axis_with_only_priority_decisions(tmp_path: Path) -> None:
    trace = TINY + [
        {"t": float(t), "event": "decision", "algorithm": "priority", "dac": "d2", "exeDA": "d1",
         "rule": "priority", "switch": t == 3}
        for t in range(1, 6)
    ] + [{"t": 1.0, "event": "roles", "exeDA": "d1", "irrDA": None, "idleDA": ["d2"]}]
    fig = plots.timeline_figure(completed(trace))
    FigureCanvasAgg(fig).draw()  # tick labels exist only once drawn
    bottom = fig.axes[1]
    labels = [t.get_text() for t in bottom.get_xticklabels() if t.get_visible() and t.get_text()]
    assert bottom.get_xlabel() == "time [s]" and len(labels) >= 3, labels
    assert _lines(fig.axes[0]) == {"decision", "switch"}


def test_hazard_spans_pair_on_and_off() -> None:
    hz = {"event": "hazard", "agent": "d1", "hazard": "device_on", "args": ["cooker"], "budget_s": 30.0}
    trace = [{"t": 1.0, **hz, "status": "on"}, {"t": 4.0, **hz, "status": "off"}, {"t": 6.0, **hz, "status": "on"},
             {"t": 9.0, "event": "mode", "mode": "IT"}]
    got = plots.hazard_spans(Timeline.of(completed(trace)))  # d1 never held the robot: unattended, then over
    assert [(h.owner, h.label, h.start, h.end, h.kind) for h in got] == [
        ("d1", "device_on cooker", 1.0, 4.0, "unattended"), ("d1", "device_on cooker", 6.0, 9.0, "unattended")]


def test_gantt_stage_names_do_not_overlap(tmp_path: Path) -> None:
    trace: list[dict[str, Any]] = [{"t": 0.0, "event": "request", "agent": "d1", "task_type": "cook", "args": {},
                                    "requester": "x"},
                                   {"t": 0.1, "event": "transition", "agent": "d1", "from": "initComm", "to": "exeTsk"}]
    for i, name in enumerate(["navigate", "pick_pan", "navigate", "turn_on", "put_on_cooker", "cook_food"]):
        trace.append({"t": 1.0 + 2.0 * i, "event": "stage", "agent": "d1", "fsm": "exeTsk", "index": i,
                      "action": name, "args": [], "kind": "suspendable", "status": "begin"})
    trace.append({"t": 300.0, "event": "transition", "agent": "d1", "from": "exeTsk", "to": "end"})
    trace = completed(trace)
    fig = plots.gantt_figure(trace)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    boxes = [t.get_window_extent(renderer) for t in fig.axes[0].texts]
    assert len(boxes) == 6
    for i, a in enumerate(boxes):
        for b in boxes[i + 1:]:
            assert not a.overlaps(b), (a, b)
    assert is_png(plots.gantt(trace, tmp_path / "g.png"))


def test_world_labels_at_one_point_do_not_pile_up() -> None:
    """Before: a suspension, two ends and a time mark at one spot were drawn on top of each other."""
    fig = Figure()
    ax = fig.subplots()
    labels = plots._Labels(metres_per_point=0.02)
    for text in ("susp d1 62s", "susp d3 69s", "d3 peter is fine 78s", "d4 finished 88s", "60s", "90s"):
        labels.place(ax, 6.3, 3.9, text, fontsize=6)
    boxes = labels.boxes
    assert len(boxes) == 6
    for i, a in enumerate(boxes):
        for b in boxes[i + 1:]:
            assert not (a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]), (a, b)
