"""World events that wait for a task (``after``) and people sent walking (``walk``)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from experiments.run.runner import run_scenario

SCENARIO = """\
kind = "robot"
world = "paper"
seed = 1

[settings]
scheduler = "alg2"
horizon = 600.0

[[requests]]
t = 0.0
task = "human_fell"
args = { person = "alice" }

[[requests]]
t = 30.0
task = "guide_human"
args = { person = "john", destination = "kitchen" }

[[world_events]]
t = 0.0
posture = ["alice", "fallen"]

[[world_events]]
t = 0.0
after = "d1"
posture = ["alice", "standing"]
note = "helped up"

[[world_events]]
t = 0.0
after = "d1"
walk = ["alice", 3.0, 6.0]
note = "walks off"
"""


def _run(tmp_path: Path, text: str) -> tuple[list[dict], list[dict]]:
    path = tmp_path / "s.toml"
    path.write_text(text, encoding="utf-8")
    out = tmp_path / "out"
    run_scenario(path, out=out, pictures=False)
    events = [json.loads(line) for line in (out / "trace.jsonl").read_text(encoding="utf-8").splitlines()]
    samples = [json.loads(line) for line in (out / "trajectory.jsonl").read_text(encoding="utf-8").splitlines()[1:]]
    return events, samples


@pytest.mark.slow
def test_a_world_event_after_an_agent_happens_when_its_task_finishes(tmp_path: Path) -> None:
    events, samples = _run(tmp_path, SCENARIO)
    end = next(e for e in events if e["event"] == "end" and e["agent"] == "d1")
    assert end["cause"] == "finished"
    helped = [e for e in events if e["event"] == "world" and e["note"] in ("helped up", "walks off")]
    assert [e["what"] for e in helped] == ["posture", "walk"]
    assert all(e["t"] == end["t"] for e in helped)  # in the tick the task finished, not at t = 0
    # Alice lay still until then, and afterwards walked to (3, 6), standing
    lying = [s["people"]["alice"] for s in samples if 1.0 <= s["t"] < end["t"]]
    assert lying and all(p[:2] == [2.1, 5.05] and p[3] == "fallen" for p in lying)
    last = samples[-1]["people"]["alice"]
    assert samples[-1]["t"] > end["t"] + 10 and last[3] == "standing"
    assert abs(last[0] - 3.0) < 1e-6 and abs(last[1] - 6.0) < 1e-6


@pytest.mark.slow
def test_a_world_event_after_an_agent_that_does_not_finish_never_happens(tmp_path: Path) -> None:
    text = SCENARIO + '\n[[terminations]]\nt = 2.0\nagent = "d1"\n'
    events, samples = _run(tmp_path, text)
    assert next(e for e in events if e["event"] == "end" and e["agent"] == "d1")["cause"] != "finished"
    assert not [e for e in events if e["event"] == "world" and e["note"] in ("helped up", "walks off")]
    assert samples[-1]["people"]["alice"][3] == "fallen"
