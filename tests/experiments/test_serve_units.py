"""The parts of ``tasker serve`` without a server: injection at a free tick, bodies read as a
scenario's entries, the session saved and renumbered, the live page's drawing."""

from __future__ import annotations

import dataclasses
import json
import warnings
from collections.abc import Callable
from pathlib import Path

import pytest

from experiments.inputs import scenario as scenarios
from experiments.inputs.actions import TimedAction
from experiments.serve import bodies
from experiments.serve.bodies import Refused
from experiments.serve.record import Record
from tasker.loop import SimulationLoop
from tests.tasker.helpers import guide, make_loop


def test_next_free_is_after_now_and_skips_ticks_with_an_action_due() -> None:
    loop = make_loop([guide()])
    loop.at(2.001, lambda: None)
    loop.at(2.002, lambda: None)
    loop.run(until=2.0)
    assert loop.now == 2.0
    assert loop.next_free(loop.now) == 2.003
    assert loop.next_free(1.0) == 2.003  # never in the past
    assert loop.next_free(5.0) == 5.0


def _injected(skip_due: bool) -> tuple[str, str]:
    """A live run in chunks with a change injected after t=7, and the replay of its scenario.

    The scenario switches to CT at 7.001, the first tick after the chunk.  Injected at
    ``next_free`` (7.002) the change runs in a tick of its own; injected at 7.001 it would run
    after the switch (added first), while the scenario's reader puts ``[[changes]]`` before
    ``[[mode_changes]]`` of the same time, as the replay below does: both are traced at once."""
    from tasker.requester import Requester

    def change(loop: SimulationLoop) -> Callable[[], None]:
        return lambda: Requester(loop.store, loop.harmoniser, "user").change("d1", {"weight": 2.0})

    live = make_loop([guide()])
    live.request(0.0, "guide")
    live.at(7.001, lambda: live.harmoniser.set_mode("CT"))
    live.run(until=7.0)
    t = live.next_free(live.now) if skip_due else round(live.now + live.resolution, 9)
    live.at(t, change(live))
    live.run(until=9.0)
    t_term = live.next_free(live.now)
    live.terminate(t_term, "d1")
    live.run()

    replay = make_loop([guide()])
    replay.request(0.0, "guide")
    replay.at(t, change(replay))  # the file's order at one time: changes, then mode changes
    replay.at(7.001, lambda: replay.harmoniser.set_mode("CT"))
    replay.terminate(t_term, "d1")
    replay.run()
    assert any(e["event"] == "end" and e["agent"] == "d1" and e["cause"] == "term" for e in live.trace.events)
    return live.trace.dumps(), replay.trace.dumps()


def test_an_action_injected_between_chunks_at_a_free_tick_gives_the_trace_of_one_scheduled_before() -> None:
    """The ordering argument of experiments.serve.session, on a synthetic system: run in chunks, an
    arrival injected at next_free lands where the same action written in the scenario lands; at
    a tick where another action is due, it would not."""
    live, replay = _injected(skip_due=True)
    assert live == replay
    live, replay = _injected(skip_due=False)
    assert live != replay


@pytest.fixture(scope="module")
def paper() -> scenarios.RobotScenario:
    return dataclasses.replace(scenarios.load(scenarios.resolve("paper")), request_fields=True)


@pytest.fixture(scope="module")
def tasks() -> list:
    from experiments.inputs.request_fields import with_request_fields
    from planners.bundled import task_types

    return [with_request_fields(t) for t in task_types()]


def _refused(call: object, *args: object, **kw: object) -> Refused:
    with pytest.raises(Refused) as caught:
        call(*args, **kw)  # type: ignore[operator]
    return caught.value


def test_a_request_body_is_read_as_a_requests_entry(paper: scenarios.RobotScenario, tasks: list) -> None:
    a, warnings = bodies.read_request({"task": "human_fell", "args": {"person": "peter"}, "priority": 3,
                                       "deadline": 10.0}, t=12.5, scn=paper, tasks=tasks)
    assert (a.t, a.kind, a.fields) == (12.5, "request", {"task": "human_fell",
                                                         "args": {"person": "peter", "priority": 3, "deadline": 10.0}})
    assert warnings == ["args.deadline: deadline=10 is not after the request (t=12.5): it has passed before the "
                        "task is requested (an absolute simulated time, not one relative to the request)"]


@pytest.mark.parametrize(("body", "status", "field", "says"), [
    ({"task": "guide_humn", "args": {}}, 422, "task", "did you mean 'guide_human'?"),
    ({"task": "guide_human", "args": {"person": "jon", "destination": "kitchen"}}, 422, "args.person",
     "no person 'jon' in world 'paper'; did you mean 'john'?"),
    ({"task": "guide_human", "args": {"person": "john"}}, 422, "args.destination", "missing required argument"),
    ({"task": "guide_human", "argz": {}}, 422, "argz", "unknown key 'argz'; did you mean 'args'?"),
    ({"task": "human_fell", "args": {"person": "peter", "priority": "high"}}, 422, "args.priority",
     "expected an integer"),
    ({"task": "human_fell", "args": {"person": "peter", "priority": 1}, "priority": 2}, 422, "priority", "given twice"),
    ({"task": "human_fell", "t": 3.0}, 422, "t", "the session sets its time"),
    (["human_fell"], 422, "", "expected a JSON object"),
])
def test_a_bad_request_body_is_refused_with_the_readers_message(paper: scenarios.RobotScenario, tasks: list,
                                                               body: object, status: int, field: str,
                                                               says: str) -> None:
    err = _refused(bodies.read_request, body, t=1.0, scn=paper, tasks=tasks)
    assert (err.status, err.field) == (status, field)
    assert says in err.message
    assert err.to_json()["detail"] == f"POST /requests: {field}: {err.message}" if field else \
        f"POST /requests: {err.message}"


def test_world_events_are_read_and_checked_against_the_world(paper: scenarios.RobotScenario, tasks: list) -> None:
    a, _ = bodies.read_world({"posture": ["peter", "fallen"], "note": "falls"}, t=3.0, scn=paper, tasks=tasks)
    assert a.fields == {"what": "posture", "value": ["peter", "fallen"], "note": "falls"}
    door = _refused(bodies.read_world, {"door": ["front", False]}, t=1.0, scn=paper, tasks=tasks)
    assert door.field == "door" and "no door of world 'paper' 'front'" in door.message
    assert _refused(bodies.read_world, {"posture": ["peter", "fallen"], "after": "d1"}, t=1.0, scn=paper,
                    tasks=tasks).field == "after"
    assert "exactly one of" in _refused(bodies.read_world, {"postur": ["peter", "fallen"]}, t=1.0, scn=paper,
                                        tasks=tasks).message


def test_a_change_is_checked_whole_by_the_task_type_and_against_the_world(tasks: list) -> None:
    from robot.spec import load_world

    world = load_world("paper")
    guide_type = next(t for t in tasks if t.name == "guide_human")
    now = {"person": "john", "destination": "john_destination", "priority": None, "deadline": None, "death_at": None}
    assert bodies.read_change({"priority": 4}, where="PATCH /requests/d1", task=guide_type, args=now,
                              world=world) == {"priority": 4}
    err = _refused(bodies.read_change, {"args": {"destination": "kitchn"}}, where="PATCH /requests/d1",
                   task=guide_type, args=now, world=world)
    assert err.field == "args.destination" and "did you mean 'kitchen'?" in err.message
    assert "nothing to change" in _refused(bodies.read_change, {}, where="PATCH /requests/d1", task=guide_type,
                                           args=now, world=world).message
    assert _refused(bodies.read_change, {"prio": 4}, where="PATCH /requests/d1", task=guide_type, args=now,
                    world=world).field == "prio"


def test_the_saved_session_renumbers_requests_in_file_order_and_reads_back(tmp_path: Path,
                                                                            paper: scenarios.RobotScenario) -> None:
    """A request that arrived at t=5 comes before the scenario's own at t=8 in the file, so it is d2
    there (the scenario's d2, now d3): every reference follows."""
    base = dataclasses.replace(paper, name="paper-session")
    record = Record(base)
    count = 0
    for a in sorted(base.actions, key=lambda a: a.t):
        count += a.kind == "request"
        record.add(a, f"d{count}" if a.kind == "request" else None)
    arrived = TimedAction(5.0, "request", {"task": "human_fell", "args": {"person": "alice"}})
    record.add(arrived, "d5")
    record.add(TimedAction(6.001, "terminate", {"agent": "d5", "reason": "terminated by the user"}), None)
    record.add(TimedAction(9.002, "change", {"agent": "d2", "args": {"priority": 2}}), None)
    record.add(TimedAction(100.003, "mode", {"mode": "IT"}), None)
    assert record.renumbering() == {"d1": "d1", "d5": "d2", "d2": "d3", "d3": "d4", "d4": "d5"}
    loaded = record.write(tmp_path / "session.toml", 100.003, "a test session")
    assert (tmp_path / "session.toml").read_text(encoding="utf-8").startswith("# a test session\n")
    assert loaded.horizon == 100.003 and loaded.request_fields and loaded.people == base.people
    assert loaded.scheduler_options == base.scheduler_options
    requests = [a for a in loaded.actions if a.kind == "request"]
    assert [a.t for a in requests] == [0.0, 5.0, 8.0, 62.0, 64.0]
    assert [a.fields for a in loaded.actions if a.kind in ("terminate", "change")] == [
        {"agent": "d2", "reason": "terminated by the user"}, {"agent": "d3", "args": {"priority": 2}}]


def test_a_served_scenarios_devices_objects_and_settings_are_saved(tmp_path: Path) -> None:
    """water_plants adds a device (its tap) and objects to the paper world, and a task folder:
    the saved session keeps them, or its replay would run in another world."""
    root = Path(__file__).resolve().parents[2] / "experiments" / "sweep" / "specs"
    paths = (str(root / "tasks"),)
    scn = scenarios.load(root / "scenarios" / "water_plants.toml", task_paths=paths)
    base = dataclasses.replace(scn, name="water_plants-session", request_fields=True)
    record = Record(base, paths)
    for k, a in enumerate(sorted(base.actions, key=lambda a: a.t)):
        record.add(a, f"d{k + 1}" if a.kind == "request" else None)
    loaded = record.write(tmp_path / "session.toml", 50.001, "a test session")  # read back with the checks
    assert loaded.devices == scn.devices == {"tap": {"type": "tap", "place": "bathroom", "state": "off"}}
    assert (loaded.objects, loaded.scheduler_options) == (scn.objects, scn.scheduler_options)
    assert loaded.actions == tuple(a for a in scn.actions)  # the same actions, pending ones after 50 s too


def test_a_world_event_may_name_a_device_the_served_scenario_adds() -> None:
    """``{"device": ["tap", "on"]}`` in water_plants, whose ``[devices.tap]`` the world lacks, was
    a KeyError in the check that stopped the session."""
    from experiments.inputs.request_fields import with_request_fields
    from planners.bundled import task_types

    root = Path(__file__).resolve().parents[2] / "experiments" / "sweep" / "specs"
    paths = [str(root / "tasks")]
    scn = scenarios.load(root / "scenarios" / "water_plants.toml", task_paths=paths)
    tasks = [with_request_fields(t) for t in task_types(paths)]
    a, _ = bodies.read_world({"device": ["tap", "on"]}, t=3.0, scn=scn, tasks=tasks)
    assert (a.fields["what"], a.fields["value"]) == ("device", ["tap", "on"])
    err = _refused(bodies.read_world, {"device": ["tab", "on"]}, t=3.0, scn=scn, tasks=tasks)
    assert err.field == "device" and "did you mean 'tap'?" in err.message


SESSION = """
kind = "robot"
world = "paper"
[settings]
horizon = 2.0
request_fields = {fields}
[[requests]]
t = 0.0
task = "guide_human"
args = {{ person = "john", destination = "bedroom" }}
"""


@pytest.mark.slow
def test_settings_request_fields_makes_every_task_type_take_them_in_the_run(tmp_path: Path) -> None:
    """A session runs with the request fields on (any request may give a priority), none of its
    requests may give one: its saved scenario says so in ``settings``, or the replay's task types
    would differ (its requests' arguments lack ``deadline``, ``priority``, ``death_at``)."""
    from experiments.run.runner import run_scenario
    from tasker.trace import read

    args = {}
    for fields in ("false", "true"):
        path = tmp_path / f"{fields}.toml"
        path.write_text(SESSION.format(fields=fields))
        scn = scenarios.load(path)
        assert scn.request_fields is (fields == "true")
        run_scenario(scn, out=tmp_path / fields, pictures=False)
        args[fields] = next(e["args"] for e in read(tmp_path / fields / "trace.jsonl") if e["event"] == "request")
    assert args["false"] == {"person": "john", "destination": "bedroom"}
    assert args["true"] == {**args["false"], "deadline": None, "priority": None, "death_at": None}


def test_the_live_page_is_offline_and_holds_the_world_figure_and_the_queue() -> None:
    from plotly.offline import get_plotlyjs

    from experiments.serve.page import COLUMNS, live_page
    from robot.spec import load_world

    world = load_world("paper")
    text = live_page(world, title="tasker serve: test")
    assert get_plotlyjs() in text and "<script src=" not in text  # plotly inlined, nothing fetched
    assert 'id="world"' in text and 'id="queue-body"' in text and 'id="request-form"' in text
    assert all(f"<th>{c}</th>" in text for c in COLUMNS if c and "[" not in c)
    doors = {name: len(world.obstacles) + k for k, name in enumerate(world.doors)}
    assert f"const DOORS = {json.dumps(doors)};" in text


def test_a_bug_in_reading_one_request_fails_that_request_not_the_session(
        tmp_path: Path, paper: scenarios.RobotScenario, monkeypatch: pytest.MonkeyPatch) -> None:
    from experiments.serve.app import create_app
    from experiments.serve.session import Ask, Session, _Drive

    def broken(*_: object, **__: object) -> None:
        raise RuntimeError("a bug")

    monkeypatch.setattr(bodies, "read_request", broken)
    session = Session(paper, speed=1.0, out=tmp_path, served="test")
    loop = make_loop([guide()])
    ask = Ask("request", {"task": "guide"})
    drive = _Drive(loop, None, None, Record(paper), 0.0)  # type: ignore[arg-type]
    assert session._take(ask, drive) == loop.now and drive.waiting == []  # nothing scheduled, no raise
    assert isinstance(ask.reply.exception(), RuntimeError)

    class Failing:
        scenario = paper  # create_app reads the served scenario's first request for the schema's example

        def ask(self, ask: Ask) -> object:
            ask.reply.set_exception(RuntimeError("a bug"))
            return ask.reply

    from fastapi.testclient import TestClient

    def client() -> TestClient:
        return TestClient(create_app(Failing(), page=lambda: ""), base_url="http://127.0.0.1:8765")  # type: ignore

    said = client().post("/requests", content=b'{"task": "guide"}', headers={"Content-Type": "application/json"})
    assert said.status_code == 500
    assert "internal error, not a fault of the request (RuntimeError: a bug)" in said.json()["detail"]
    said = client().post("/requests", content=b'{"task": ', headers={"Content-Type": "application/json"})
    assert said.status_code == 400 and "not valid JSON" in said.json()["detail"]
    schema = client().get("/openapi.json").json()
    body = schema["paths"]["/requests"]["post"]["requestBody"]["content"]["application/json"]["schema"]
    first = next(a.fields for a in paper.actions if a.kind == "request")
    assert body["example"] == {"task": first["task"], "args": first["args"]}  # the served scenario's first request


def test_the_first_lines_say_what_the_world_file_does_on_its_own_and_how_to_serve_without_it() -> None:
    from experiments.serve.server import scripted, served

    paper, _ = served("paper")
    [line] = scripted(paper)
    assert "robot/worlds/paper.toml has peter fallen at t=60 s, sara fallen at t=90 s, john walking (t=10 s to " \
           "60 s) (simulated time), in every session" in line
    assert "serve a copy of it without those people's events and walk" in line and "tasker serve flat" in line
    flat, _ = served("flat")
    assert scripted(flat) == ["nothing is scripted: the world changes and tasks come only over HTTP"]
    household, _ = served("household")
    said = scripted(household)
    assert any(s.startswith("the scenario's own ") and "happen at their times" in s for s in said), said


def test_the_request_form_gets_for_each_task_type_a_request_the_world_takes_or_why_not(
        paper: scenarios.RobotScenario, tasks: list) -> None:
    from experiments.serve.examples import task_types
    from experiments.serve.server import served
    from robot.spec import load_world

    world = load_world("paper")
    session, _ = served("paper")
    types = {t["name"]: t for t in task_types(session, tasks, world)}
    assert types["carry_object"]["example"] is None
    assert types["carry_object"]["refused"].startswith("args.item: ")  # the paper world has no item
    assert types["guide_human"]["example"] == {"person": "alice", "destination": "alice_destination"}
    assert types["human_fell"]["example"] == {"person": "alice"} and types["human_fell"]["refused"] is None
    for t in types.values():  # every example is a body the session takes
        if t["example"] is not None:
            bodies.read_request({"task": t["name"], "args": t["example"]}, t=1.0, scn=session, tasks=tasks)
    first = next(a for a in paper.actions if a.kind == "request")  # a scenario's own first request is the example
    assert {t["name"]: t for t in task_types(paper, tasks, world)}[first.fields["task"]]["example"] == \
        first.fields["args"]


class _StillSim:
    """What :func:`experiments.serve.snapshot.snapshot` reads of a simulation, with nothing in it."""

    skill = None
    trajectory: list = []
    people: list = []
    door_open: dict = {}
    device_state: dict = {}
    held: set = set()

    @staticmethod
    def robot_pose() -> tuple[float, float, float]:
        return (1.0, 2.0, 0.0)


def test_the_state_lists_live_agents_first_then_ended_ones_each_in_request_order() -> None:
    from experiments.serve.snapshot import snapshot

    loop = make_loop([guide("short"), guide("long")])
    loop.request(0.0, "long")
    loop.request(0.0, "short")
    loop.request(0.5, "long")
    loop.run(until=1.0)
    loop.terminate(1.001, "d2")
    loop.run(until=10.0)
    ended = {e["agent"]: e for e in loop.trace.events if e["event"] == "end"}
    assert set(ended) == {"d2"}
    state = snapshot(loop, _StillSim(), ended={a: {"t": e["t"]} for a, e in ended.items()}, decision=None,
                     task_types=[{"name": "x"}])
    assert [(a["id"], a["ended"] is not None) for a in state["agents"]] == [("d1", False), ("d3", False),
                                                                          ("d2", True)]
    assert state["task_types"] == [{"name": "x"}]


def test_a_session_that_cannot_write_session_toml_records_the_same_actions_from_memory(
        tmp_path: Path, paper: scenarios.RobotScenario) -> None:
    record = Record(dataclasses.replace(paper, name="paper-session"))
    for k, a in enumerate(sorted(paper.actions, key=lambda a: a.t)):
        record.add(a, f"d{k + 1}" if a.kind == "request" else None)
    record.add(TimedAction(5.0, "request", {"task": "human_fell", "args": {"person": "alice"}}), "d9")
    record.add(TimedAction(6.001, "terminate", {"agent": "d9", "reason": "by hand"}), None)
    in_memory = record.scenario(80.001)
    loaded = record.write(tmp_path / "session.toml", 80.001, "a test session")
    assert in_memory.actions == loaded.actions and in_memory.horizon == loaded.horizon == 80.001
    assert ("terminate", {"agent": "d2", "reason": "by hand"}) in [(a.kind, a.fields) for a in in_memory.actions]


@pytest.mark.parametrize("suspension", __import__("experiments.inputs.strategy", fromlist=["x"]).SUSPENSION_VALUES)
def test_a_session_saves_every_suspension_strategy_the_scenario_reader_knows(
        tmp_path: Path, paper: scenarios.RobotScenario, suspension: str) -> None:
    """serve keeps no list of its own: a strategy added to the shared one (``fallback``) is saved and read back."""
    record = Record(dataclasses.replace(paper, name="paper-session", suspension=suspension, actions=()))
    loaded = record.write(tmp_path / "session.toml", 10.0, "a test session")
    assert loaded.suspension == suspension


@pytest.mark.parametrize(("changed_at", "warned"), [(None, True), (9.0, False), (21.0, True)])
def test_a_replay_warns_of_a_repeated_request_only_while_its_twin_is_that_request(
        tmp_path: Path, paper: scenarios.RobotScenario, changed_at: float | None, warned: bool) -> None:
    """A session whose d1 was changed (PATCH) before the same request came again replays without the
    warning that d1 "may still run" as that request: by then it was another one."""
    from tasker.support.reader import InputWarning

    record = Record(dataclasses.replace(paper, name="paper-session", actions=()))
    john = {"task": "guide_human", "args": {"person": "john", "destination": "john_destination"}}
    record.add(TimedAction(1.0, "request", john), "d1")
    if changed_at is not None:
        record.add(TimedAction(changed_at, "change", {"agent": "d1", "args": {"destination": "kitchen"}}), None)
    record.add(TimedAction(20.0, "request", john), "d2")
    record.write(tmp_path / "session.toml", 30.0, "a test session")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        scenarios.load(tmp_path / "session.toml")
    said = [str(w.message) for w in caught if issubclass(w.category, InputWarning)]
    assert any("the same request as d1" in s for s in said) is warned, said


def test_the_last_line_counts_the_tasks_and_their_ends_from_the_timeline() -> None:
    """``describe`` reads the timeline; the expected line is counted here from the raw events."""
    from collections import Counter

    from experiments.run.runner import run_scenario
    from experiments.serve.server import describe

    result = run_scenario(Path(__file__).resolve().parents[2] / "experiments/inputs/scenarios/synthetic_demo.toml")
    raw = list(result.trace.events)
    causes = Counter(e["cause"] for e in raw if e["event"] == "end")
    requests = sum(1 for e in raw if e["event"] == "request")
    assert requests == 4 and sum(causes.values()) == 4
    how = ", ".join(f"{n} {c}" for c, n in sorted(causes.items()))
    assert describe(result) == f"{requests} tasks, {requests} ended ({how})"
