"""The one scenario pipeline: (protocol, seed, backend) → a scenario, on both backends.

Robot days here are tiny (one request of each type in a few minutes) so the suite stays
fast; the shipped protocols' days are run by ``tasker day``.
"""

from __future__ import annotations

import itertools
import json
from pathlib import Path
from typing import Any

import pytest

from experiments.days import draw as day_draw
from experiments.days import pipeline as days
from experiments.days import protocol
from experiments.days import runner as day_runner
from experiments.metrics import day as day_metrics_mod
from robot.estimator import motion_model
from robot.spec import load_world
from tasker import schedulers
from tasker.errors import ConfigError

PROTOCOLS = Path(__file__).resolve().parents[2] / "experiments" / "days" / "protocols"


def tiny(tmp_path: Path) -> Path:
    """tabsa_short with one request of each type called in the first minute, a 10-minute day."""
    text = (PROTOCOLS / "tabsa_short.toml").read_text(encoding="utf-8")
    text = text.replace('name = "tabsa-short"', 'name = "tiny"')
    text = text.replace("length_s = 3600.0", "length_s = 600.0").replace("last_call_s = 2700.0", "last_call_s = 60.0")
    text = text.replace("count = 3", "count = 1")
    text = text.replace('world = "tabsa_apartment_short.toml"', f'world = "{PROTOCOLS / "tabsa_apartment_short.toml"}"')
    p = tmp_path / "tiny.toml"
    p.write_text(text, encoding="utf-8")
    return p


@pytest.fixture(scope="module")
def tiny_protocol(tmp_path_factory: pytest.TempPathFactory) -> protocol.Protocol:
    return protocol.load(tiny(tmp_path_factory.mktemp("tiny")))


def test_protocols_are_registered_by_name() -> None:
    assert {"tabsa", "tabsa-short", "tabsa-rush"} <= set(days.names())
    assert days.load("tabsa").name == "tabsa" and days.load("tabsa-short").name == "tabsa-short"
    with pytest.raises(ConfigError, match="did you mean 'tabsa'"):
        days.make("tabsaa", 1)
    with pytest.raises(ConfigError, match="did you mean 'robot'"):
        days.make("tabsa", 1, backend="robt")
    with pytest.raises(ConfigError, match="did you mean 'alg2'"):
        days.make("tabsa", 1, scheduler="alg")


def test_the_rush_is_the_full_day_called_in_half_an_hour() -> None:
    """tabsa-rush changes one thing of tabsa: when the requests come (and so the day's length)."""
    full, rush = days.load("tabsa"), days.load("tabsa-rush")
    assert (rush.last_call_s, rush.length_s) == (1800.0, 7200.0)
    same = ("step_s", "robot_speed", "start_site", "planning_time_s", "sites", "tasks", "robot")
    assert all(getattr(rush, f) == getattr(full, f) for f in same)
    calls = [r.t for r in day_draw.draw(rush, 3)]
    assert len(calls) == 36 and max(calls) < 1800.0
    assert days.make("tabsa-rush", 3, backend="robot").scenario.horizon == 7200.0


@pytest.mark.parametrize("backend", days.BACKENDS)
def test_same_seed_same_scenario(backend: str) -> None:
    a = days.make("tabsa", 3, backend=backend).scenario
    b = days.make("tabsa", 3, backend=backend).scenario
    c = days.make("tabsa", 4, backend=backend).scenario
    assert a.actions == b.actions and a.actions != c.actions
    if backend == "robot":
        assert a.people == b.people and a.objects == b.objects


def test_both_backends_are_built_from_one_draw() -> None:
    syn = days.make("tabsa", 5).scenario
    rob = days.make("tabsa", 5, backend="robot").scenario
    proto = days.load("tabsa")
    folder = days.task_names(proto, "robot")
    syn_req = [(a.t, a.fields["task"], a.fields["args"]["deadline"]) for a in syn.actions]
    rob_req = [(a.t, a.fields["task"], a.fields["args"]["deadline"]) for a in rob.actions if a.kind == "request"]
    assert [(t, folder[k], d) for t, k, d in syn_req] == rob_req
    # every request carries its deadline and priority; a fall its death time, and its person falls at the call
    falls = [a for a in rob.actions if a.kind == "request" and a.fields["task"] == folder["fall"]]
    assert len(falls) == 12 and all(a.fields["args"]["death_at"] == a.fields["args"]["deadline"] + 900 for a in falls)
    timed = [a for a in rob.actions if a.kind == "world" and "after" not in a.fields]
    postures = {(a.t, a.fields["value"][0]): a.fields["value"][1] for a in timed if a.fields["what"] == "posture"}
    assert all(postures[a.t, a.fields["args"]["person"]] == "fallen" for a in falls)
    # and is taken away (stands up, walks home) once their own request's agent has finished
    agents = {f"d{k}": a for k, a in enumerate((a for a in rob.actions if a.kind == "request"), 1)}
    helped = [a for a in rob.actions if a.kind == "world" and "after" in a.fields]
    assert len(helped) == 2 * len(falls)
    assert proto.robot is not None
    world = load_world(proto.robot.world)
    for a in helped:
        person = a.fields["value"][0]
        assert agents[a.fields["after"]].fields["args"].get("person") == person
        assert a.fields["value"][1:] == (["standing"] if a.fields["what"] == "posture"
                                         else list(world.people[person].pose[:2]))
    people = [v for a in rob.actions if a.kind == "request" for v in a.fields["args"].values() if v in rob.people]
    assert len(people) == len(set(people)) == 24  # one person per escort and per fall
    assert len(rob.objects) == 12


def test_a_protocol_without_a_robot_backend_says_so(tmp_path: Path) -> None:
    text = (PROTOCOLS / "tabsa.toml").read_text(encoding="utf-8").split("[robot_backend]")[0]
    p = tmp_path / "synthetic_only.toml"
    p.write_text(text, encoding="utf-8")
    with pytest.raises(ConfigError, match="no \\[robot_backend\\]"):
        days.make(p, 1, backend="robot")


@pytest.mark.parametrize("name", schedulers.names())
def test_every_scheduler_runs_every_task_type_synthetic(name: str) -> None:
    run = days.make("tabsa-short", 2, scheduler=name).run()
    finished = {e["task_type"] for e in run.events if e["event"] == "end" and e.get("cause") == "finished"}
    assert finished == {"transport", "fall", "pick_place"}


@pytest.mark.slow
@pytest.mark.parametrize("name", schedulers.names())
def test_every_scheduler_runs_every_task_type_robot(tiny_protocol: protocol.Protocol, name: str) -> None:
    m = day_runner.run_day(tiny_protocol.source, 1, name, "robot")
    if schedulers.create(name).work_conserving:
        assert {t: v["completed"] for t, v in m["per_type"].items()} == {"transport": 1, "fall": 1, "pick_place": 1}
    else:  # a time-table (TaBSA's scheduler agent) runs a task in its slot before the deadline: after this short day
        assert m["per_type"]["fall"]["completed"] == 1
    assert m["dead_falls"] == 0 and m["travel_m"] > 0


@pytest.mark.slow
def test_a_robot_day_runs_under_the_strategy_it_is_given(tiny_protocol: protocol.Protocol, tmp_path: Path) -> None:
    from experiments.inputs.strategy import Strategy

    m = day_runner.run_day(tiny_protocol.source, 1, "alg2", "robot", keep=str(tmp_path),
                          strategy=Strategy(update="static", suspension="static"))
    assert m["strategy"] == "update=static,suspension=static"
    run = json.loads((tmp_path / "trace.jsonl").read_text().splitlines()[0])
    assert (run["event"], run["update"], run["suspension"]) == ("run", "static", "static")
    # the day's hazard rows are the run metrics' safety section, one definition
    from experiments.metrics.run import compute_file

    safety = compute_file(tmp_path / "trace.jsonl")["safety"]
    assert m["hazard_unattended_s"] == pytest.approx(safety["unattended_s"], abs=1e-6)
    assert m["hazard_after_end_s"] == pytest.approx(safety["after_end_s"], abs=1e-6)
    assert (m["hazard_overruns"], m["hazards_left_at_switch"]) == (safety["budget_overruns"],
                                                                   safety["violations_at_switch"])
    assert safety["episodes"]  # the carry held its object: the day has hazards to count
    # people walked to their sites and home round walls, not through them (docs/robot.md)
    import numpy as np

    from robot.recording import read_trajectory
    from robot.scene import segments_clear
    from robot.spec import load_world

    world = load_world(tiny_protocol.robot.world)
    walls = np.array([o.box for o in world.obstacles if o.kind == "wall"], dtype=float)
    _, samples, _ = read_trajectory(tmp_path / "trajectory.jsonl")
    steps = [((p.x, p.y), (q.x, q.y)) for s0, s1 in zip(samples, samples[1:], strict=False)
             for p, q in zip(s0.people, s1.people, strict=True) if (p.x, p.y) != (q.x, q.y)]
    assert steps  # people walked
    a, b = np.array([u for u, _ in steps]), np.array([v for _, v in steps])
    assert segments_clear(a, b, walls, 1e-9).all()
    with pytest.raises(ConfigError, match="synthetic backend"):
        days.make("tabsa-short", 1).run(suspension="static")


@pytest.mark.parametrize("name", ["tabsa", "tabsa-short"])
def test_every_spot_and_place_of_the_robot_world_is_clear(name: str) -> None:
    """People stand 0.3 m and the robot's places 0.4 m clear of every wall and piece of furniture."""
    from robot.spec import load_world

    proto = days.load(name)
    assert proto.robot is not None
    world = load_world(proto.robot.world)
    boxes = [o.box for o in world.obstacles]

    def clearance(x: float, y: float) -> float:
        return min(((max(b[0] - x, 0.0, x - b[2])) ** 2 + (max(b[1] - y, 0.0, y - b[3])) ** 2) ** 0.5 for b in boxes)

    assert all(clearance(*s) >= 0.3 for spots in proto.robot.spots.values() for s in spots)
    assert all(clearance(p[0], p[1]) >= 0.4 for p in world.places.values())
    assert set(proto.robot.places.values()) <= set(world.places)


def _spot_world(name: str) -> tuple[Any, Any, list[str], list[tuple[str, int, tuple[float, ...]]]]:
    """A protocol's robot world without people, its motion model, the places the robot can
    reach at all (a protocol may ground where idle people wait in a room it cannot enter),
    and every spot as ``(site, index, xy)``."""
    from robot.spec import load_world

    backend = days.load(name).robot
    assert backend is not None
    spec = load_world(backend.world)
    motion = motion_model(spec, people=False)
    places = [p for p in spec.places
              if any(motion.estimate(spec.places[p], spec.places[q]).reachable for q in spec.places if q != p)]
    spots = [(site, k, tuple(xy)) for site, xys in backend.spots.items() for k, xy in enumerate(xys)]
    return spec, motion, places, spots


def _unreachable(motion, places, spec) -> list[tuple[str, str]]:  # type: ignore[no-untyped-def]
    return [(a, b) for a, b in itertools.permutations(places, 2)
            if not motion.estimate(spec.places[a], spec.places[b]).reachable]


@pytest.mark.slow
@pytest.mark.parametrize("name", ["tabsa", "tabsa-short"])
def test_no_spot_walls_the_robot_in(name: str) -> None:
    """Where the day's people stand must not wall the robot in: they hold their site's spots
    for minutes and may fall there, so with one person at any spot (standing, or fallen, the
    widest posture), and with every spot held by a standing person at once, every place the
    robot can reach in the empty apartment stays reachable from every other.  (Seed 5 of
    the full day stranded the robot: the hall's spots lay on the 2 m hall's centre line.)"""
    spec, motion, places, spots = _spot_world(name)
    scene = motion.planner.scene
    assert len(places) >= 2 and not _unreachable(motion, places, spec)
    walls = []
    for (site, k, xy), posture in itertools.product(spots, ("standing", "fallen")):
        scene.set_person("someone", xy[0], xy[1], posture)
        cut = _unreachable(motion, places, spec)
        scene.remove_person("someone")
        if cut:
            walls.append(f"{site} spot {k} {xy} ({posture}) cuts {cut[:3]}")
    for i, (_, _, xy) in enumerate(spots):
        scene.set_person(f"p{i}", xy[0], xy[1], "standing")
    cut = _unreachable(motion, places, spec)
    if cut:
        walls.append(f"every spot held by a standing person cuts {cut[:3]}")
    assert not walls, "\n".join(walls)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["tabsa", "tabsa-short"])
def test_a_person_at_any_spot_can_be_reached(name: str) -> None:
    """A person at a spot (standing, to be guided; or fallen, to be helped) can be approached
    from every place the robot can reach while every other spot is held by a standing person.
    (Full day, seeds 6 and 8: the bedroom's spots lay along the corridor between the bed and
    the bathroom wall, one in its dead end; a person there, with others at the spots by its
    entrance, could be approached only through the wall, and once approach poses had to see
    the person, guides and a fall failed under every scheduler.)"""
    spec, motion, places, spots = _spot_world(name)
    scene = motion.planner.scene
    shut = []
    for i, (site, k, xy) in enumerate(spots):
        for j, (_, _, other) in enumerate(spots):
            if j != i:
                scene.set_person(f"p{j}", other[0], other[1], "standing")
        for posture in ("standing", "fallen"):
            scene.set_person("target", xy[0], xy[1], posture)
            cut = [p for p in places if motion.approach(spec.places[p], "target")[0] is None]
            if cut:
                shut.append(f"{site} spot {k} {xy} ({posture}): not from {cut[:3]}")
        for j in range(len(spots)):
            scene.remove_person(f"p{j}")
        scene.remove_person("target")
    assert not shut, "\n".join(shut)


@pytest.mark.slow
def test_a_failed_fall_is_requested_again_and_served(tiny_protocol: protocol.Protocol, tmp_path: Path,
                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    """The fall's first help fails (its approach finds no pose, as when people crowd round the
    person); the fall is requested again 30 s later (``renews``), the renewal helps, the person
    is taken away after it, and the day counts one fall, served, none dead."""
    from robot import skills

    real = skills.Navigate._approach

    def first_fails(self: skills.Navigate, name: str) -> Any:  # the approach begun before t = 40 s
        if self.sim.people[name].posture == "fallen" and self.started < 40.0:
            return f"no reachable pose next to {name}"
        return real(self, name)

    monkeypatch.setattr(skills.Navigate, "_approach", first_fails)
    day_runner.run_day(tiny_protocol.source, 1, "alg2", "robot", keep=str(tmp_path))
    events = [json.loads(line) for line in (tmp_path / "trace.jsonl").read_text().splitlines()]
    falls = [e for e in events if e["event"] == "request" and e["task_type"] == "human_fell"]
    assert len(falls) == 2 and falls[1]["renews"] == falls[0]["agent"] and falls[1]["args"] == falls[0]["args"]
    ends = {e["agent"]: e for e in events if e["event"] == "end"}
    failed, renewed = ends[falls[0]["agent"]], ends[falls[1]["agent"]]
    assert failed["cause"] == "failed" and falls[1]["t"] == pytest.approx(failed["t"] + 30.0, abs=1.0)
    assert renewed["cause"] == "finished"
    person = falls[0]["args"]["person"]
    up = next(e for e in events if e["event"] == "world" and e["value"] == [person, "standing"])
    assert up["t"] == renewed["t"] and "help done" in up["note"]  # taken away after the renewal's help
    kinds = {v: k for k, v in days.task_names(tiny_protocol, "robot").items()}
    m = day_metrics_mod.day_metrics(events, day_end=tiny_protocol.length_s, kinds=kinds)
    f = m["per_type"]["fall"]
    assert (f["requested"], f["completed"], f["failed"], f["renewals"]) == (1, 1, 0, 1) and m["dead_falls"] == 0


@pytest.mark.slow
def test_a_terminated_request_is_not_requested_again(tiny_protocol: protocol.Protocol, tmp_path: Path,
                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    """A requester cancels the fall (its scenario id, ``dK``) after its task failed and before
    the renewal is due: nothing is requested again."""
    import dataclasses

    from experiments.inputs.actions import TimedAction
    from robot import skills

    real = skills.Navigate._approach
    monkeypatch.setattr(skills.Navigate, "_approach", lambda self, name: f"no reachable pose next to {name}"
                        if self.sim.people[name].posture == "fallen" else real(self, name))
    day = days.make(tiny_protocol, 1, backend="robot", scheduler="alg2")
    requests = [a for a in day.scenario.actions if a.kind == "request"]
    k = next(i for i, a in enumerate(requests, 1) if a.fields["task"] == "human_fell")
    # its help fails at 57.65 s (the approach's block timeout) and is due again at 87.65 s
    cancel = TimedAction(70.0, "terminate", {"agent": f"d{k}", "reason": "help came from elsewhere"})
    scn = dataclasses.replace(day.scenario, actions=tuple(sorted((*day.scenario.actions, cancel), key=lambda a: a.t)),
                              horizon=200.0)
    events = days.Day(day.protocol, 1, "robot", "alg2", scn).run(out=tmp_path).events
    falls = [e for e in events if e["event"] == "request" and e["task_type"] == "human_fell"]
    ends = {e["agent"]: e for e in events if e["event"] == "end"}
    assert len(falls) == 1 and ends[falls[0]["agent"]]["cause"] == "failed" and ends[falls[0]["agent"]]["t"] < 70.0
