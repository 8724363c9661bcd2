"""A scenario's timed actions carry a typed payload beside the fields a file writes."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from experiments.inputs import scenario as scenarios
from experiments.inputs import synthetic
from experiments.inputs.actions import Change, ModeSwitch, Renewal, Request, Terminate, TimedAction, WorldEvent

ROOT = Path(__file__).resolve().parents[2]


def test_each_kind_has_its_payload_with_the_files_own_values() -> None:
    req = TimedAction(1.0, "request", {"task": "cook", "args": {"dish": "soup"},
                                       "renew": {"after_s": 30, "until": 600.0}})
    assert req.payload == Request("cook", {"dish": "soup"}, Renewal(30.0, 600.0))
    assert req.payload.args is req.fields["args"]  # the same object: nothing copied on the way to the requester
    assert TimedAction(2.0, "terminate", {"agent": "d1", "reason": "why"}).payload == Terminate("d1", "why")
    assert TimedAction(3.0, "change", {"agent": "d1", "args": {"n": 2}}).payload == Change("d1", {"n": 2})
    assert TimedAction(4.0, "mode", {"mode": "CT"}).payload == ModeSwitch("CT")
    bare = TimedAction(5.0, "world", {"what": "door", "value": ["d", True]})
    noted = TimedAction(5.0, "world", {"what": "door", "value": ["d", True], "note": "", "after": "d2"})
    assert bare.payload == WorldEvent("door", ["d", True])
    assert noted.payload == WorldEvent("door", ["d", True], "", "d2")  # an empty note is kept apart from none


def test_a_shipped_scenarios_actions_and_a_replaced_one_have_payloads() -> None:
    scn = synthetic.load(scenarios.resolve(str(ROOT / "experiments/inputs/scenarios/synthetic_demo.toml")))
    kinds = {a.kind: type(a.payload) for a in scn.actions}
    assert kinds["request"] is Request
    first = next(a for a in scn.actions if a.kind == "request")
    moved = dataclasses.replace(first, t=first.t + 1.0)
    assert isinstance(moved.payload, Request) and moved.payload.task == first.fields["task"]
