"""The simulation: MuJoCo agrees with the estimates, skills keep their contract, people react."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robot.scene import PERSON_RADIUS
from robot.sim import Simulation
from tasker.meaning import Binding
from tasker.protocols import CoreAgent, SkillState, World
from tasker.stage import Stage
from tasker.world import WorldState


def run(sim: Simulation, stage: Stage, now: float, limit: float = 200.0, dt: float = 0.1):
    sim.begin("d1", stage, now)
    while True:
        now += dt
        status = sim.poll("d1", stage, now)
        if status.state is not SkillState.RUNNING or now > limit:
            return status, now


def nav(to, **data) -> Stage:
    return Stage("navigate", ("robot", str(to)), skill="navigate", data={"to": to, **data})


def test_protocols(paper) -> None:
    sim = Simulation(paper)
    assert isinstance(sim, World) and isinstance(sim, CoreAgent)
    snap = sim.snapshot()
    assert isinstance(snap, WorldState)
    assert snap.holds("at", "robot", "hall") or snap.holds("posture", "john", "standing")
    assert snap.objects["john"] == "person" and snap.objects["cooker"] == "cooker"
    assert "robot" in snap.poses and "kitchen" in snap.poses


@pytest.mark.slow
@pytest.mark.parametrize(("a", "b"), [("hall", "kitchen"), ("kitchen", "bedroom"), ("bedroom", "stove"),
                                      ("stove", "bathroom"), ("bathroom", "alice_destination")])
def test_estimates_match_mujoco_time(paper, a: str, b: str) -> None:
    start = paper.places[a]
    world = type(paper)(**{**{f: getattr(paper, f) for f in paper.__dataclass_fields__},
                           "people": {}, "robot": type(paper.robot)(pose=start)})
    sim = Simulation(world)
    est = sim.motion.estimate(start, paper.places[b])
    status, t = run(sim, nav(b), 0.0, dt=0.02)
    assert status.state is SkillState.SUCCEEDED
    x, y, yaw = sim.robot_pose()
    assert math.hypot(x - paper.places[b][0], y - paper.places[b][1]) < 0.1
    assert abs(t - est.time_s) <= 0.15 * est.time_s, (t, est.time_s)
    assert sim.mj.contacts_with_world() == 0


def test_stop_brings_the_base_to_rest(paper) -> None:
    sim = Simulation(paper)
    stage = nav("bedroom")
    sim.begin("d1", stage, 0.0)
    sim.advance(6.0)
    assert sim.mj.velocity()[0] > 0.1 or abs(sim.mj.velocity()[1]) > 0.1
    sim.stop("d1", stage, 6.0)
    sim.advance(8.0)
    v, w = sim.mj.velocity()
    assert v < 0.01 and abs(w) < 0.01
    parked = sim.robot_pose()
    sim.advance(10.0)
    assert math.dist(parked[:2], sim.robot_pose()[:2]) < 0.005
    assert sim.poll("d1", stage, 10.0).state is SkillState.FAILED


@pytest.mark.slow
def test_person_asked_to_follow_ends_near_the_destination(paper) -> None:
    sim = Simulation(paper)
    status, now = run(sim, nav("john", add=[["met", "robot", "john"]]), 0.0)
    assert status.state is SkillState.SUCCEEDED and sim.snapshot().holds("met", "robot", "john")
    sim.bind([Binding("follower", ("following", "?h"), "?h", ("person",))])
    sim.apply(add=[["following", "john"]])
    status, now = run(sim, nav("john_destination"), now)
    assert status.state is SkillState.SUCCEEDED
    sim.advance(now + 3.0)
    john = sim.people["john"]
    assert math.dist((john.x, john.y), paper.places["john_destination"][:2]) < 1.5


def test_a_sitting_person_asked_to_follow_stands_up(paper) -> None:
    """Alice sits; once she follows the robot she stands, and the scene gives her a standing disc."""
    sim = Simulation(paper)
    assert sim.people["alice"].posture == "sitting"
    status, now = run(sim, nav("alice", add=[["met", "robot", "alice"]]), 0.0)
    assert status.state is SkillState.SUCCEEDED
    sim.bind([Binding("follower", ("following", "?h"), "?h", ("person",))])
    sim.apply(add=[["following", "alice"]])
    sim.advance(now + 0.5)
    assert sim.people["alice"].posture == "standing"
    assert ("posture", "alice", "standing") in sim.snapshot().facts
    assert sim.scene.people["alice"].r == PERSON_RADIUS["standing"]


def test_told_to_wait_stops_a_walking_person(paper) -> None:
    sim = Simulation(paper)
    sim.advance(20.0)
    sim.bind([Binding("waiting", ("told_to_wait", "?h"), "?h")])
    sim.apply(add=[["told_to_wait", "john"]])
    assert sim.people["john"].waiting and ("told_to_wait", "john") not in sim.facts
    here = sim.people["john"].pose
    sim.advance(30.0)
    assert sim.people["john"].pose == here
    sim.apply(delete=[["told_to_wait", "john"]])
    sim.advance(35.0)
    assert sim.people["john"].pose != here


@pytest.mark.slow
@pytest.mark.parametrize("posture", ["standing", "sitting"])
def test_a_person_told_to_wait_in_a_doorway_steps_out_of_it(paper, posture: str) -> None:
    """Nobody waits standing in a doorway: told to wait there, a standing person steps to
    the nearest spot of their room clear of every door (a sitting one stays put)."""
    import dataclasses

    from robot.roadmap import path_length
    from robot.scene import point_box_distance
    from robot.spec import PersonSpec, room_of

    people = {"john": PersonSpec("john", (2.27, 4.96, 0.0), posture, 1.0, (), ())}  # behind the living/kitchen door
    sim = Simulation(dataclasses.replace(paper, people=people))
    sim.bind([Binding("waiting", ("told_to_wait", "?h"), "?h")])
    living, kitchen = paper.places["living"][:2], paper.places["kitchen"][:2]
    before = path_length(sim.planner.plan(living, kitchen))  # round through the hall: he is in the way
    sim.apply(add=[["told_to_wait", "john"]])
    sim.advance(6.0)
    john = sim.people["john"]
    leaves = np.array([d.box for d in paper.doors.values()])
    gap = point_box_distance(np.array([john.x]), np.array([john.y]), leaves).min()
    if posture == "sitting":
        assert (john.x, john.y) == (2.27, 4.96)
        return
    assert gap >= PERSON_RADIUS["standing"] + 2 * sim.scene.radius
    assert room_of(paper, john.x, john.y) == room_of(paper, 2.27, 4.96) and john.waiting
    assert path_length(sim.planner.plan(living, kitchen)) < before - 1.0  # the door is usable again


def test_a_bound_device_has_one_state(paper) -> None:
    """The fact a task folder binds to a device is derived from the device, never stored twice."""
    sim = Simulation(paper)
    sim.bind([Binding("device", ("heating", "?c"), "?c", ("cooker",), state="on", otherwise="off")])
    assert not sim.snapshot().holds("heating", "cooker") and sim.snapshot().holds("state", "cooker", "off")
    sim.apply(add=[["heating", "cooker"]])  # a stage switches it on: the device follows
    assert sim.device_state["cooker"] == "on" and sim.snapshot().holds("heating", "cooker")
    sim.set_device("cooker", "off")  # a person switches it off: the fact follows
    assert not sim.snapshot().holds("heating", "cooker") and sim.snapshot().holds("state", "cooker", "off")
    assert not any(f[0] == "heating" for f in sim.facts)


def test_timed_skills_apply_effects_and_fail_cleanly(flat) -> None:
    sim = Simulation(flat)
    say = Stage("say", ("robot", "anna"), skill="say", duration=2.0,
                data={"text": "hello", "add": [["greeted", "anna"]], "delete": [["at", "robot", "living"]]})
    status, now = run(sim, say, 0.0)
    assert status.state is SkillState.SUCCEEDED and 1.9 <= now <= 2.2
    snap = sim.snapshot()
    assert snap.holds("greeted", "anna")
    # the robot's symbolic place is read off its pose, whatever a stage's effects said
    x, y, _ = sim.robot_pose()
    assert snap.holds("at", "robot", sim.nearest_place(x, y))
    assert len([f for f in snap.facts if f[:2] == ("at", "robot")]) == 1
    gone = Stage("grab", skill="manipulate", duration=1.0, data={"object": "cup"})
    assert run(sim, gone, now)[0].reason == "object 'cup' is gone"
    assert "no path" in run(sim, nav("storage"), now)[0].reason
    assert "unknown skill" in run(sim, Stage("dance", skill="dance"), now)[0].reason
    assert "unknown navigation target" in run(sim, nav("moon"), now)[0].reason


def test_same_seed_same_trajectory(paper) -> None:
    trajectories = []
    for _ in range(2):
        sim = Simulation(paper, seed=1)
        run(sim, nav("kitchen"), 0.0, limit=12.0)
        trajectories.append((np.array(sim.trajectory), sim.mj.state()))
    assert np.array_equal(trajectories[0][0], trajectories[1][0])
    assert np.array_equal(trajectories[0][1], trajectories[1][1])


def test_a_door_closed_from_the_doorway_is_closed_from_the_stage_s_side(flat) -> None:
    """A plan may close a door while the robot stands in it (its symbolic place is already
    one side): the skill steps out to that side first, so the leaf never closes through it."""
    from robot.scene import point_box_distance

    sim = Simulation(flat)
    sim.bind([Binding("door", ("open", "?d"), "?d")])
    sim.set_door("bedroom_door", True)
    status, now = run(sim, nav([6.0, 3.5, 1.5708]), 0.0)
    assert status.state is SkillState.SUCCEEDED
    box = np.asarray([flat.doors["bedroom_door"].box], dtype=float)
    x, y, _ = sim.robot_pose()
    assert point_box_distance(np.asarray([x]), np.asarray([y]), box).min() < sim.scene.radius  # in the doorway
    close = Stage("close_door", ("robot", "bedroom_door", "living"), skill="manipulate", duration=3.0,
                  data={"delete": [["open", "bedroom_door"]]})
    status, now = run(sim, close, now)
    assert status.state is SkillState.SUCCEEDED and not sim.door_open["bedroom_door"]
    x, y, _ = sim.robot_pose()
    assert y < 3.45 and point_box_distance(np.asarray([x]), np.asarray([y]), box).min() >= sim.scene.radius
    assert run(sim, nav("kitchen"), now)[0].state is SkillState.SUCCEEDED  # not walled in


def test_a_person_stepping_aside_is_estimated_where_they_are_going(paper) -> None:
    """Told to wait in the living/kitchen doorway, John steps aside; the very moment he is
    told, the estimate through the door already counts him at his spot (he will be there
    before the robot is), while the planner the robot drives with still sees him in the
    way.  Once he stands there, estimate and plan agree."""
    import dataclasses

    from robot.roadmap import path_length
    from robot.spec import PersonSpec

    people = {"john": PersonSpec("john", (2.27, 4.96, 0.0), "standing", 1.0, (), ())}
    sim = Simulation(dataclasses.replace(paper, people=people))
    sim.bind([Binding("waiting", ("told_to_wait", "?h"), "?h")])
    living, kitchen = paper.places["living"], paper.places["kitchen"]
    blocked = sim.motion.estimate(living, kitchen)
    sim.apply(add=[["told_to_wait", "john"]])  # he has not moved yet
    assert sim.people["john"].pose[:2] == (2.27, 4.96) and sim.scene.stepping_to["john"] is not None
    expected = sim.motion.estimate(living, kitchen)
    assert expected.time_s < blocked.time_s - 1.0  # through the door, not round through the hall
    assert path_length(sim.planner.plan(living[:2], kitchen[:2])) > expected.distance_m + 1.0  # driving: not yet
    assert sim.scene.people["john"].x == 2.27  # the estimate left the scene as it was
    sim.advance(6.0)
    assert "john" not in sim.scene.stepping_to
    assert sim.motion.estimate(living, kitchen).time_s == pytest.approx(expected.time_s, abs=0.5)


def test_equal_facts_keys_mean_equal_facts(paper) -> None:
    """A monitor asks for the facts only when ``facts_key`` changes: along a drive with people
    walking, following, falling and facts applied, equal keys always came with equal facts."""
    sim = Simulation(paper)
    sim.bind([Binding("follower", ("following", "?h"), "?h", ("person",))])
    seen: dict[object, frozenset] = {}
    keys = 0
    poses: dict[object, set[tuple[float, float]]] = {}

    def look() -> None:
        nonlocal keys
        key, facts = sim.facts_key(), sim.snapshot().facts
        keys += key not in seen
        assert seen.setdefault(key, facts) == facts
        poses.setdefault(key, set()).add(sim.robot_pose()[:2])

    stage = nav("john", add=[["met", "robot", "john"]])
    sim.begin("d1", stage, 0.0)
    t = 0.0
    while sim.poll("d1", stage, t).state is SkillState.RUNNING and t < 60.0:
        t = round(t + 0.5, 6)
        sim.advance(t)
        look()
    sim.apply(add=[["following", "john"]])
    look()
    sim.people["peter"].set_posture("sitting")
    look()
    for _ in range(20):
        t = round(t + 0.5, 6)
        sim.advance(t)
        look()
    assert keys >= 4  # the key did change along the way (places reached, a follower, a posture)
    # and it is made of places, not poses: the robot driving within one place keeps it
    assert max(len(p) for p in poses.values()) > 5


@pytest.mark.slow
def test_people_not_stepped_while_still_are_where_stepping_them_puts_them(paper, monkeypatch) -> None:
    """Still people are not stepped (``Person._idle_after``), the world syncs and re-examines
    only people touched since it last looked: the same samples as stepping, syncing and
    re-examining everyone at every tick.  John walks his script (before its start, walking,
    after its end); in the bedroom p falls, q steps aside and r, in a dead end, stays
    (``test_bystanders_make_room_for_help``), John walks up to p later and makes room too, p
    gets up and they go back; w, standing in the living/hall doorway, is told to wait (steps
    aside first), then follows the robot."""
    import dataclasses

    from robot.people import Person
    from robot.spec import PersonSpec

    def person(name: str, x: float, y: float, events=()) -> PersonSpec:
        return PersonSpec(name, (x, y, 0.0), "standing", 0.5, ((0.0, x, y), (100.0, x, y)), tuple(events))

    world = dataclasses.replace(paper, people={
        "john": paper.people["john"], "p": person("p", 10.5, 4.6, [(1.0, "fallen"), (175.0, "standing")]),
        "q": person("q", 9.6, 4.6), "r": person("r", 11.4, 4.6), "w": person("w", 5.0, 2.0)})

    def day() -> list[str]:
        sim = Simulation(world)
        sim.bind([Binding("follower", ("following", "?h"), "?h", ("person",)),
                  Binding("waiting", ("told_to_wait", "?h"), "?h", ("person",))])
        sim.advance(5.0)
        sim.apply(add=[["told_to_wait", "w"]])
        run(sim, nav("living"), 5.0, limit=60.0)
        sim.apply(delete=[["told_to_wait", "w"]], add=[["following", "w"]])
        run(sim, nav("kitchen"), 60.0, limit=120.0)
        sim.people["john"].go_to(120.0, 9.0, 5.4)  # to p, lying in the bedroom: he makes room
        sim.apply(delete=[["following", "w"]])
        sim.advance(190.0)
        return sim.recording.lines()

    fast = day()
    monkeypatch.setattr(Person, "_idle_after", lambda self, t: -math.inf)
    def everyone_every_tick(self: Simulation) -> None:
        self._doors_seen = -1  # as if a door had moved: _give_room looks at everyone
        self._give_room()
        self._sync_people()

    monkeypatch.setattr(Simulation, "_people_react", everyone_every_tick)
    everyone = day()
    assert fast == everyone
    assert len({line.split('"robot"')[0] for line in fast}) > 100  # people did move
