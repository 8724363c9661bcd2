"""The trace's typed events: ``emit`` takes only them, and every event reads back as it was written."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from tasker import events as ev
from tasker.trace import Trace, encode, read_events

EXAMPLES: list[ev.Event] = [
    ev.RunStarted(0.0, 3, "alg2", "IT", 1.0, 1.0, 10.0, 1.0, "planned", "static"),
    ev.RunStopped(9.0, "aborted", "World.advance raised RuntimeError: x", ["d1"]),
    ev.RunStopped(9.0, "horizon reached", None, []),
    ev.TaskRequested(0.0, "d1", "cook", {"dish": "soup"}, "user"),
    ev.TaskRequested(1.0, "d2", "cook", {}, "day", renews="d1"),
    ev.Transition(0.5, "d1", "start", "compSP", "upTsk"),
    ev.CommandSent(1.0, "d1", "susp", by="d2", expected_s=math.inf),
    ev.CommandSent(1.0, "d2", "start", predicted_s=12.5),
    ev.CommandSent(1.0, "d2", "start", secure=True),
    ev.RolesChanged(1.0, "d1", None, ["d2"]),
    ev.Decision(2.0, {"algorithm": "alg2", "dac": "d2", "exeDA": "d1", "rule": "cost", "switch": True,
                      "c_switch": 1.5, "c_wait": 2.0}),
    ev.PlanMade(2.0, "d1", "genSusp", "planned", [{"action": "turn_off", "args": ["cooker"], "kind": "blocking"}],
                note="planned ahead", info={"planner": "tasker-fd"}),
    ev.PlanMade(2.0, "d1", "upTsk", "static", []),
    ev.PlanMade(2.0, "d1", "genSusp", "fallback", [], note="fallback: the tree's branch runs",
                goal=[["hand_empty", "robot"], ["not", "cooker_on", "cooker"]]),
    ev.StageChanged(3.0, "d1", "exeTsk", 0, "navigate", ["robot", "kitchen"], "suspendable", "begin"),
    ev.StageChanged(3.5, "d1", "exeTsk", 0, "navigate", ["robot", "kitchen"], "suspendable", "failed",
                    reason="blocked"),
    ev.StageChanged(3.5, "d1", "exeSusp", 0, "turn_off", ["robot", "cooker"], "suspendable", "already_done",
                    reason="already done: (not (cooker_on cooker)) holds"),
    ev.ModeChanged(4.0, "CT"),
    ev.ArgsChanged(4.0, "d1", {"deadline": 9.0}, "user"),
    ev.ArgsChanged(4.0, "d9", {"deadline": 9.0}, ignored="the task has ended"),
    ev.WorldChanged(5.0, "posture", ["peter", "fallen"], "world file"),
    ev.HazardChanged(5.0, None, "door_open", ["door1"], ["door_open", "door1"], "on", 60.0, 1.0),
    ev.HazardChanged(5.0, "d1", "hot_pan_held", ["robot", "pan"], ["holding", "robot", "pan"], "on", 0.0, 1.0,
                     carried=True),
    ev.GoalChecked(6.0, "d1", [["hand_empty", "robot"], ["not", "cooker_on", "cooker"]],
                   [["not", "cooker_on", "cooker"]]),
    ev.SecureChanged(6.0, "d1", "start", [{"hazard": "cooker_on", "args": ["cooker"]}]),
    ev.SecureChanged(7.0, "d1", "done"),
    ev.RoleChanged(7.0, "d1", "following", "john", "on"),
    ev.TaskEnded(8.0, "d1", "cook", "finished", "finished"),
]


def test_every_type_has_an_example_here() -> None:
    assert {type(e) for e in EXAMPLES} == set(ev.TYPES)


@pytest.mark.parametrize("event", EXAMPLES, ids=lambda e: type(e).__name__)
def test_an_event_reads_back_as_it_was_written(event: ev.Event) -> None:
    back = ev.parse(json.loads(encode(event.record())))
    assert type(back) is type(event)
    assert encode(back.record()) == encode(event.record())


def test_emit_takes_only_typed_events() -> None:
    trace = Trace()
    with pytest.raises(TypeError, match="tasker.events"):
        trace.emit({"t": 0.0, "event": "mode", "mode": "IT"})  # type: ignore[arg-type]
    with pytest.raises(TypeError):
        trace.emit(0.5, "mode", mode="IT")  # type: ignore[call-arg]


def test_observers_get_the_typed_event_and_records_keep_the_written_order() -> None:
    trace = Trace()
    seen: list[ev.Event] = []
    trace.subscribe(seen.append)
    trace.emit(ev.Transition(0.0010000000000000002, "d1", "start", "compSP", "upTsk"))
    assert seen == [ev.Transition(0.001, "d1", "start", "compSP", "upTsk")]
    assert list(trace.events[0]) == ["t", "event", "agent", "trigger", "from", "to"]
    assert trace.typed == seen


@pytest.mark.parametrize(("record", "message"), [
    ({"t": 1.0, "event": "end", "agent": "d1", "task_type": "x", "reason": "finished"}, "end: missing 'cause'"),
    ({"t": 1.0, "event": "transition", "agent": 3, "trigger": "a", "from": "b", "to": "c"},
     "'agent' must be a string"),
    ({"t": 1.0, "event": "teleport"}, "unknown event 'teleport'"),
    ({"t": 1.0, "event": "mode", "mode": "IT", "colour": "red"}, "unexpected field 'colour'"),
    ({"t": 10 ** 400, "event": "mode", "mode": "IT"}, "too large"),
    ({"t": -1, "event": "mode", "mode": "IT"}, "finite number >= 0"),
    ({"t": 1.0, "event": "decision", "algorithm": "alg2"}, "'switch' must be true or false"),
    ({"t": 1.0, "event": "stage", "agent": "d1", "fsm": "exeTsk", "index": 1.5, "action": "a", "args": [],
      "kind": "blocking", "status": "begin"}, "'index' must be an integer"),
])
def test_a_damaged_event_names_its_field(record: dict[str, object], message: str) -> None:
    with pytest.raises(ev.TraceError, match=message):
        ev.parse(record)


def test_a_damaged_trace_file_names_the_line(tmp_path: Path) -> None:
    path = tmp_path / "trace.jsonl"
    path.write_text(encode(EXAMPLES[0].record()) + "\n\n" + '{"t": 1, "event": "end", "agent": "d1"}\n')
    with pytest.raises(ValueError, match=r"trace.jsonl:3: end: missing 'task_type'"):
        read_events(path)
    path.write_text("[" * 100_000 + "\n")
    with pytest.raises(ValueError, match="trace.jsonl:1"):
        read_events(path)
