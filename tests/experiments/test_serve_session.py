"""A real live session (the paper world, MuJoCo, Fast Downward) driven in this process through
FastAPI's TestClient: a fuzz of bodies never gets a 5xx and the session still saves and replays
byte for byte; the record survives a ``session.toml`` or a report that cannot be written; the
trace is on disk as the session goes; a repeated request warns only while its twin lives; the
request form's first task is one the world takes."""

from __future__ import annotations

import json
import threading
import time
import tomllib
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from experiments.serve.app import create_app
from experiments.serve.server import served
from experiments.serve.session import Session
from tasker.errors import RunAborted

pytestmark = pytest.mark.slow

BASE = "http://127.0.0.1:8765"
JOHN = {"task": "guide_human", "args": {"person": "john", "destination": "john_destination"}}


@dataclass
class Live:
    session: Session
    client: TestClient
    thread: threading.Thread
    failure: list[BaseException]

    def state(self) -> dict[str, Any]:
        return dict(self.client.get("/state").json())

    def until(self, what: str, check: Callable[[dict[str, Any]], bool], timeout: float = 90.0) -> dict[str, Any]:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            s = self.state()
            if s.get("status") != "starting" and check(s):
                return s
            time.sleep(0.05)
        raise AssertionError(f"the session never got to {what}: {json.dumps(self.state())[:600]}")

    def stop(self) -> None:
        r = self.client.post("/stop")
        assert r.status_code == 202, r.text
        self.thread.join(timeout=120)
        assert not self.thread.is_alive()


def start(out: Path, *, pictures: bool = False, speed: float = 20.0) -> Live:
    scn, what = served("paper")
    session = Session(scn, speed=speed, out=out, served=what, pictures=pictures)
    failure: list[BaseException] = []

    def run() -> None:
        try:
            session.run()
        except BaseException as exc:  # noqa: BLE001 - the test reads it
            failure.append(exc)

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    live = Live(session, TestClient(create_app(session, page=lambda: "<html>"), base_url=BASE), thread, failure)
    live.until("running", lambda s: s["status"] == "running")
    return live


@pytest.fixture
def live(tmp_path: Path) -> Iterator[Live]:
    s = start(tmp_path / "live")
    yield s
    if s.thread.is_alive():
        s.session.stop("the test ended")
        s.thread.join(timeout=120)


def replayed_trace(session_toml: Path, out: Path) -> bytes:
    from experiments.inputs import scenario as scenarios
    from experiments.run.runner import run_scenario

    run_scenario(scenarios.load(session_toml), out=out, pictures=False)
    return (out / "trace.jsonl").read_bytes()


# -- the fuzz -------------------------------------------------------------------------------

NAMES = ["john", "alice", "peter", "sara", "kitchen", "bedroom", "john_destination", "hall_bedroom", "cooker",
         "jon", "", "\u2028", "d1"]
SCALARS = (st.sampled_from(NAMES) | st.none() | st.booleans() | st.integers(-2**65, 2**65)
           | st.floats(allow_nan=True, allow_infinity=True) | st.text(max_size=6)
           | st.sampled_from(["\ud800", "x" * 1500, "standing", "fallen", "sitting", "on", "off"]))
VALUES = st.recursive(SCALARS, lambda inner: st.lists(inner, max_size=3), max_leaves=5)
ARGS = st.dictionaries(st.sampled_from(["person", "destination", "priority", "deadline", "death_at", "cost_model",
                                        "f_walk", "item", "pan", "x"]), VALUES, max_size=4)
REQUEST = st.fixed_dictionaries({"task": st.sampled_from(["guide_human", "human_fell", "carry_object", "cook",
                                                          "nope"]) | VALUES},
                                optional={"args": ARGS | VALUES, "priority": VALUES, "deadline": VALUES,
                                          "t": VALUES})
WORLD = st.dictionaries(st.sampled_from(["posture", "door", "walk", "device", "move", "add", "delete", "note",
                                         "after", "x"]), VALUES, min_size=1, max_size=3)
CHANGE = st.fixed_dictionaries({}, optional={"priority": VALUES, "deadline": VALUES, "args": ARGS | VALUES})
GOOD = st.sampled_from([
    ("POST", "/requests", JOHN), ("POST", "/requests", {"task": "human_fell", "args": {"person": "sara"}}),
    ("POST", "/requests", {"task": "guide_human", "args": {"person": "alice", "destination": "kitchen"},
                           "priority": 3, "deadline": 1e9}),
    ("POST", "/world", {"posture": ["peter", "fallen"], "note": "Peter falls \u2028 (a note of any text)"}),
    ("POST", "/world", {"door": ["hall_bedroom", False]}), ("POST", "/world", {"door": ["hall_bedroom", True]}),
    ("PATCH", "/requests/d1", {"priority": 9_223_372_036_854_775_807}),
    ("PATCH", "/requests/d2", {"deadline": 0.1 + 0.2})])
PEOPLE = st.sampled_from(["john", "alice", "peter", "sara"])
TAKEN = (  # bodies the session takes, with values of every kind it keeps: any text, 64-bit integers, any float
    st.fixed_dictionaries({"task": st.just("human_fell"), "args": st.fixed_dictionaries({"person": PEOPLE})},
                          optional={"priority": st.integers(-2**63, 2**63 - 1),
                                    "deadline": st.floats(0, 1e300, allow_nan=False)}).map(
        lambda b: ("POST", "/requests", b))
    | st.fixed_dictionaries({"posture": st.tuples(PEOPLE, st.sampled_from(["standing", "sitting", "fallen"]))},
                            optional={"note": st.text(max_size=30)}).map(lambda b: ("POST", "/world", b)))
CALLS = (TAKEN | TAKEN | GOOD
         | st.tuples(st.just("POST"), st.just("/requests"), REQUEST)
         | st.tuples(st.just("POST"), st.just("/world"), WORLD)
         | st.tuples(st.just("PATCH"), st.sampled_from(["/requests/d1", "/requests/d2", "/requests/d9"]), CHANGE)
         | GOOD)


def test_fuzz_a_live_session_never_answers_5xx_and_still_saves_and_replays(live: Live, tmp_path: Path) -> None:
    statuses: dict[int, int] = {}

    @settings(max_examples=120, derandomize=True, deadline=None, database=None,
              suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
    @given(call=CALLS)
    def one(call: tuple[str, str, Any]) -> None:
        method, path, body = call
        r = live.client.request(method, path, content=json.dumps(body).encode(),
                                headers={"Content-Type": "application/json"})
        statuses[r.status_code] = statuses.get(r.status_code, 0) + 1
        assert r.status_code < 500, (call, r.text)
        assert r.status_code < 300 or r.json()["detail"], r.text

    one()
    assert statuses.get(201, 0) >= 3 and statuses.get(202, 0) >= 3 and statuses.get(422, 0) >= 10, statuses
    live.stop()
    assert live.failure == [] and live.session.problems == []
    out = live.session.out
    saved = tomllib.loads((out / "session.toml").read_text(encoding="utf-8"))
    assert len(saved["requests"]) == statuses[201]
    assert (out / "trace.jsonl").read_bytes() == "".join(f"{x}\n" for x in live.session.lines).encode()
    assert replayed_trace(out / "session.toml", tmp_path / "replay") == (out / "trace.jsonl").read_bytes()


# -- the record is never lost -----------------------------------------------------------------

def test_the_trace_is_on_disk_as_the_session_goes(live: Live) -> None:
    assert live.client.post("/requests", json=JOHN).status_code == 201
    live.until("a few more trace lines", lambda s: s["events"] >= 10)
    time.sleep(0.3)  # a flush or more
    on_disk = (live.session.out / "trace.jsonl").read_text(encoding="utf-8").splitlines()
    assert len(on_disk) >= 10 and on_disk == live.session.lines[:len(on_disk)]
    assert not (live.session.out / "run.json").exists()  # the run folder proper is written on stop


def test_a_session_toml_that_cannot_be_written_leaves_the_whole_trace_and_says_what_was_kept(live: Live) -> None:
    assert live.client.post("/requests", json=JOHN).status_code == 201
    assert live.client.post("/world", json={"posture": ["sara", "fallen"], "note": "Sara falls"}).status_code == 202
    (live.session.out / "session.toml").mkdir()  # writing it fails: IsADirectoryError
    live.stop()
    [failure] = live.failure
    assert isinstance(failure, RunAborted)
    assert "session.toml was not written (IsADirectoryError" in failure.reason
    assert "run.json holds the session's actions" in failure.reason
    lines = live.session.lines
    assert f"trace.jsonl ({len(lines)} events)" in failure.reason and "run.json" in failure.reason
    trace = (live.session.out / "trace.jsonl").read_text(encoding="utf-8")
    assert len(lines) > 10 and trace == "".join(f"{x}\n" for x in lines)
    assert lines[-1] == trace.splitlines()[-1]
    run = json.loads((live.session.out / "run.json").read_text(encoding="utf-8"))
    kinds = [a["kind"] for a in run["scenario"]["actions"]]
    assert kinds == ["request", "world", "mode"]  # the session's actions, and the stop mark
    assert run["scenario"]["horizon"] == live.session.t_stop


def test_a_report_that_cannot_be_drawn_leaves_the_whole_trace_and_says_so(tmp_path: Path,
                                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    from experiments.report import plots

    def broken(*_: object, **__: object) -> None:
        raise RuntimeError("no room for pictures")

    monkeypatch.setattr(plots, "timeline", broken)
    live = start(tmp_path / "live", pictures=True)
    assert live.client.post("/requests", json=JOHN).status_code == 201
    live.stop()
    [failure] = live.failure
    assert isinstance(failure, RunAborted)
    assert "the run folder was not all written: RuntimeError: no room for pictures" in failure.reason
    assert "session.toml" in failure.reason.split("kept in")[1]
    assert (live.session.out / "trace.jsonl").read_text(encoding="utf-8") == "".join(
        f"{x}\n" for x in live.session.lines)


# -- the session as a new user meets it ---------------------------------------------------------

def test_a_repeated_request_warns_only_while_its_twin_still_runs(live: Live) -> None:
    first = live.client.post("/requests", json=JOHN).json()
    twin = live.client.post("/requests", json=JOHN).json()
    assert len(twin["warnings"]) == 1
    assert twin["warnings"][0].startswith(f"task: the same request as {first['id']} (guide_human ")
    assert "which still runs" in twin["warnings"][0]
    other = live.client.post("/requests", json={**JOHN, "priority": 1}).json()
    assert other["warnings"] == []  # not the same request: another priority
    for agent in (first["id"], twin["id"]):
        assert live.client.delete(f"/requests/{agent}").status_code == 202
    live.until("both terminated", lambda s: all(a["ended"] for a in s["agents"] if a["id"] in (first["id"],
                                                                                                twin["id"])))
    again = live.client.post("/requests", json=JOHN).json()
    assert again["warnings"] == []  # its twins have ended


def test_the_state_lists_live_tasks_first_and_the_form_starts_on_a_task_the_world_takes(live: Live) -> None:
    ended = live.client.post("/requests", json={"task": "human_fell", "args": {"person": "alice"}}).json()["id"]
    running = live.client.post("/requests", json=JOHN).json()["id"]
    s = live.until(f"{ended} ended", lambda s: any(a["id"] == ended and a["ended"] for a in s["agents"]))
    ids = [a["id"] for a in s["agents"]]
    assert ids.index(running) < ids.index(ended)  # requested later, listed first: it still runs
    assert [bool(a["ended"]) for a in s["agents"]] == sorted(bool(a["ended"]) for a in s["agents"])
    types = {t["name"]: t for t in s["task_types"]}
    assert types["carry_object"]["example"] is None and "item" in types["carry_object"]["refused"]
    first = next(t for t in s["task_types"] if t["example"] is not None)
    r = live.client.post("/requests", json={"task": first["name"], "args": first["example"]})
    assert r.status_code == 201, r.text


def test_a_trace_writer_that_fails_part_way_leaves_the_whole_trace_written_from_memory(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """What a lone surrogate once did (the run folder's trace.jsonl left empty): whatever cuts the
    final writer short, the session's own lines are the trace."""
    from tasker.trace import Trace

    def cut_short(self: Trace, path: str | Path) -> None:
        Path(path).write_text("", encoding="utf-8")
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(Trace, "write", cut_short)
    live = start(tmp_path / "live")
    assert live.client.post("/requests", json=JOHN).status_code == 201
    live.stop()
    [failure] = live.failure
    assert isinstance(failure, RunAborted) and "No space left on device" in failure.reason
    trace = (live.session.out / "trace.jsonl").read_text(encoding="utf-8")
    assert len(live.session.lines) > 5 and trace == "".join(f"{x}\n" for x in live.session.lines)
    assert "session.toml" in failure.reason.split("kept in")[1]
