"""One rule for "a person blocks this segment": the base planner, the ``navigate`` skill's
check of the path ahead and the snapping of a start all use :meth:`Scene.people_clear`, so
a path the planner returns is one the skill drives, and a robot a person walked up to can
always leave.  The doorway case is the one that stranded the robot in ``bring_water``."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from robot.estimator import APPROACH, motion_model
from robot.scene import Scene
from robot.sim import Simulation
from robot.spec import PersonSpec, WorldSpec
from robot.tiago import robot_dimensions
from tasker.protocols import SkillState
from tasker.stage import Stage

# Where bring_water left the robot (static and planned alike): braked in the living/hall
# doorway, its disc grazing the jamb at (4.95, 2.5), while John walked up to stand beside it
# (0.54 m from its centre, inside his 0.6 m clearance), and Peter had fallen in the hall.
ROBOT = (4.8285687905458685, 2.179135191722636, 3.1020022385823802)
JOHN = (4.3, 2.3)


def _doorway_scene(paper: WorldSpec):  # type: ignore[no-untyped-def]
    motion = motion_model(paper)
    scene = motion.planner.scene
    scene.set_person("john", *JOHN, "standing")
    scene.set_person("peter", *paper.people["peter"].pose[:2], "fallen")
    return motion, scene


def _skill_accepts(scene: Scene, start: tuple[float, float], path: tuple[tuple[float, float], ...]) -> bool:
    """What Navigate._path_ahead_blocked asks before the first leg: from the true pose on."""
    return scene.path_clear([start, *path[1:]])


def test_the_doorway_start_is_where_the_old_models_disagreed(paper) -> None:
    motion, scene = _doorway_scene(paper)
    assert not scene.static_free(*ROBOT[:2])  # grazing the jamb: the planner must snap it off
    assert math.dist(ROBOT[:2], JOHN) < scene.clearance(scene.people["john"])  # inside John's disc


@pytest.mark.parametrize("goal", ["living", "hall", "kitchen", "peter"])
def test_stranded_in_the_doorway_beside_john_can_leave(paper, goal: str) -> None:
    motion, scene = _doorway_scene(paper)
    if goal in paper.places:
        est = motion.estimate(ROBOT, paper.places[goal])
    else:
        pose, est = motion.approach(ROBOT, goal)
        person = scene.people[goal]
        assert pose is not None and math.dist(pose[:2], (person.x, person.y)) == pytest.approx(APPROACH)
    assert est.reachable, goal
    assert _skill_accepts(scene, ROBOT[:2], est.path), est.path
    # and the path never takes the robot closer to John than it already is
    dense = np.concatenate([np.linspace(a, b, 50) for a, b in zip(est.path[:-1], est.path[1:], strict=False)])
    assert np.hypot(*(dense - JOHN).T).min() >= math.dist(ROBOT[:2], JOHN) - 1e-3


def test_a_snapped_start_is_free_as_returned(paper) -> None:
    motion, scene = _doorway_scene(paper)
    snapped = motion.planner.snap(ROBOT[:2], tuple(scene.discs()))
    assert snapped is not None and snapped != ROBOT[:2]
    assert scene.static_free(*snapped)  # the old snap rounded its answer back into the jamb


def test_people_rule_enters_never_leaves_always(paper) -> None:
    scene = Scene(paper, robot_dimensions()[2])
    scene.set_person("john", 3.0, 3.0, "standing")  # clearance 0.6
    inside, outside, beyond = (3.5, 3.0), (4.0, 3.0), (2.0, 3.0)
    a, b = np.array([inside, outside, outside, inside]), np.array([outside, inside, beyond, (3.3, 3.3)])
    # leaving from inside: yes; entering: no (unless it is the goal); crossing: no;
    # sliding round inside: only if never closer than the start
    assert scene.people_clear(a, b).tolist() == [True, False, False, False]
    assert scene.people_clear(a[1:2], b[1:2], goal=inside).tolist() == [True]
    assert scene.people_clear(a[:1], b[:1], leaving=False).tolist() == [False]  # roadmap edges


def test_every_planned_path_is_one_the_skill_accepts(paper) -> None:
    """Random people (some right next to the start or goal), random starts and goals."""
    rng = np.random.default_rng(11)
    motion = motion_model(paper, people=False)
    scene = motion.planner.scene
    planned = 0
    for trial in range(40):
        for name in ("a", "b", "c"):
            scene.remove_person(name)
        free = []
        while len(free) < 2:
            p = (float(rng.uniform(0.3, 11.7)), float(rng.uniform(0.3, 7.7)))
            if scene.static_free(*p):
                free.append(p)
        s, g = free
        # one person beside the start (inside its clearance), one beside the goal, one anywhere
        for name, (cx, cy) in zip("abc", (s, g, (rng.uniform(0.5, 11.5), rng.uniform(0.5, 7.5))), strict=True):
            ang = rng.uniform(0, 2 * math.pi)
            d = rng.uniform(0.3, 0.7) if name != "c" else 0.0
            scene.set_person(name, cx + d * math.cos(ang), cy + d * math.sin(ang),
                             ("standing", "sitting", "fallen")[trial % 3])
        path = motion.planner.plan(s, g)
        if path is None:
            continue
        planned += 1
        assert _skill_accepts(scene, s, path), (trial, s, g, path, scene.discs())
    assert planned >= 20


def _world_with_robot_in_the_doorway(paper: WorldSpec) -> WorldSpec:
    people = dict(paper.people)
    people["john"] = dataclasses.replace(paper.people["john"], pose=(*JOHN, 0.0), walk=())
    people["peter"] = PersonSpec("peter", paper.people["peter"].pose, "fallen", 0.0, (), ())
    return dataclasses.replace(paper, people=people, robot=dataclasses.replace(paper.robot, pose=ROBOT))


@pytest.mark.slow
@pytest.mark.parametrize("to", ["living", "peter"])
def test_navigate_leaves_the_doorway_in_mujoco(paper, to: str) -> None:
    sim = Simulation(_world_with_robot_in_the_doorway(paper))
    stage = Stage("navigate", ("robot", to), skill="navigate", data={"to": to})
    sim.begin("d1", stage, 0.0)
    now, status = 0.0, sim.poll("d1", stage, 0.0)
    while status.state is SkillState.RUNNING and now < 120.0:
        now += 0.1
        status = sim.poll("d1", stage, now)
    assert status.state is SkillState.SUCCEEDED, status


@pytest.mark.slow
def test_navigate_retries_a_failed_replan_once_the_doorway_clears(paper) -> None:
    """Peter steps into the only door of the bedroom while the robot drives there (no path:
    it brakes), then walks on: the robot re-plans at the next check and gets there, rather
    than waiting on its braked old path until the stall watchdog fails it."""
    people = {"peter": PersonSpec("peter", (7.6, 7.0, 0.0), "standing", 1.0,
                                  ((0.0, 7.6, 7.0), (2.0, 7.0, 6.0), (4.0, 7.0, 6.0), (5.5, 8.2, 7.3)), ())}
    sim = Simulation(dataclasses.replace(paper, people=people))
    stage = Stage("navigate", ("robot", "bedroom"), skill="navigate", data={"to": "bedroom"})
    sim.begin("d1", stage, 0.0)
    now, status, blocked = 0.0, sim.poll("d1", stage, 0.0), False
    while status.state is SkillState.RUNNING and now < 120.0:
        now += 0.1
        status = sim.poll("d1", stage, now)
        if 3.0 <= now <= 4.0:
            blocked |= sim.planner.plan(sim.robot_pose()[:2], paper.places["bedroom"][:2]) is None
    assert blocked  # the doorway really was shut while Peter stood in it
    assert status.state is SkillState.SUCCEEDED, status


def test_a_start_between_two_people_is_left_by_passing_one(paper) -> None:
    """The hall place with Sara fallen south-west of it and John standing north-east (a
    randomised paper run): no way leaves both without coming closer to one, so the planner
    passes the one the robot is beside — as the skill's check allows — rather than
    calling every place unreachable from there."""
    motion = motion_model(paper, people=False)
    scene = motion.planner.scene
    scene.set_person("sara", 5.473, 3.453, "fallen")
    scene.set_person("john", 6.452, 4.308, "standing")
    start = paper.places["hall"]
    assert set(scene.beside(start[:2])) == {"sara", "john"}
    est = motion.estimate(start, paper.places["john_destination"])
    assert est.reachable and _skill_accepts(scene, start[:2], est.path)


def _blocked_bedroom(paper: WorldSpec, walk: tuple[tuple[float, float, float], ...]):  # type: ignore[no-untyped-def]
    """Peter stands in the bedroom's only door when the robot is sent there."""
    people = {"peter": PersonSpec("peter", (7.0, 6.0, 0.0), "standing", 1.0, walk, ())}
    sim = Simulation(dataclasses.replace(paper, people=people))
    assert sim.planner.plan(sim.robot_pose()[:2], paper.places["bedroom"][:2]) is None  # shut at the start
    stage = Stage("navigate", ("robot", "bedroom"), skill="navigate", data={"to": "bedroom"})
    sim.begin("d1", stage, 0.0)
    now, status = 0.0, sim.poll("d1", stage, 0.0)
    while status.state is SkillState.RUNNING and now < 120.0:
        now += 0.1
        status = sim.poll("d1", stage, now)
    return status, now


@pytest.mark.slow
def test_navigate_blocked_at_its_start_waits_for_the_way_to_clear(paper) -> None:
    """No path when the stage begins (someone in the doorway) is not a failure yet: the skill
    waits as it does when blocked en route, and drives once Peter walks on."""
    status, _ = _blocked_bedroom(paper, ((0.0, 7.0, 6.0), (2.0, 7.0, 6.0), (4.0, 8.2, 7.3)))
    assert status.state is SkillState.SUCCEEDED, status


def test_navigate_blocked_at_its_start_fails_after_the_block_timeout(paper) -> None:
    from robot.skills import BLOCK_TIMEOUT

    status, now = _blocked_bedroom(paper, ())
    assert status.state is SkillState.FAILED and "blocked" in status.reason
    assert BLOCK_TIMEOUT <= now <= BLOCK_TIMEOUT + 1.0


def test_an_unknown_target_fails_at_once(paper) -> None:
    sim = Simulation(paper)
    stage = Stage("navigate", ("robot", "nowhere"), skill="navigate", data={"to": "nowhere"})
    sim.begin("d1", stage, 0.0)
    status = sim.poll("d1", stage, 0.1)
    assert status.state is SkillState.FAILED and "unknown navigation target 'nowhere'" in status.reason


def test_a_person_who_follows_the_robot_never_blocks_its_way(paper) -> None:
    """The person being guided stands in the bathroom doorway, between the robot and the way
    out (paper variant 14, household seed 5): while they are just standing there the robot
    cannot leave the bathroom; once they follow it (the guide's `follower` binding), they
    make way, so the planner and the skill's check of the path ahead both let it through."""
    motion = motion_model(paper, people=False)
    scene = motion.planner.scene
    scene.set_person("alice", 7.0, 2.0, "standing")  # the hall/bathroom doorway's middle
    start, goal = paper.places["bathroom"], paper.places["hall"]
    assert not motion.estimate(start, goal).reachable
    scene.set_making_way("alice", True)
    est = motion.estimate(start, goal)
    assert est.reachable
    assert scene.path_clear(list(est.path))
    scene.set_making_way("alice", False)  # told to stop following: in the way again
    assert not motion.estimate(start, goal).reachable


@pytest.mark.slow
def test_a_person_is_approached_from_their_side_of_a_wall() -> None:
    """Full TaBSA day, seed 2: p13 fell 0.4 m north of the living/kitchen wall; from the
    living room the robot went to a pose 0.9 m from them through the wall (living-room
    side), was walled into that corner by people and failed 4 tasks.  An approach pose must
    see the person: no wall or closed door between them."""
    from pathlib import Path

    from robot.spec import load_world

    world = load_world(Path(__file__).resolve().parents[2] / "experiments" / "days" / "protocols"
                       / "tabsa_apartment.toml")
    motion = motion_model(world, people=False)
    scene = motion.planner.scene
    scene.set_person("p13", 4.21, 4.9, "fallen")
    for start in ((3.0, 3.0, 0.0), (6.0, 3.0, 1.57), (3.0, 6.6, 0.0)):  # living room, hall, kitchen
        pose, est = motion.approach(start, "p13")
        assert pose is not None and est.reachable
        assert pose[1] > 4.55, (start, pose)  # in the kitchen, north of the wall (y 4.45-4.55)
        assert scene.sees(pose[:2], (4.21, 4.9))


@pytest.mark.slow
def test_bystanders_make_room_for_help(paper) -> None:
    """The bedroom case of ``test_approach_tries_a_farther_ring_when_the_near_one_is_shut``:
    p lies between the bed and the wall, q and r stand at both ends, so no pose the robot
    could help from is free.  When p falls, q steps clear of the ring the robot helps from,
    within their own room and off the doorways, and p becomes reachable; r, in the dead end
    between the bed and the walls, has no such spot and stays.  Once p is up, q walks back
    onto their script."""
    from robot.spec import room_of

    def person(name: str, x: float, y: float, events=()) -> PersonSpec:
        return PersonSpec(name, (x, y, 0.0), "standing", 0.5, ((0.0, x, y), (100.0, x, y)), tuple(events))

    world = dataclasses.replace(paper, people={
        "p": person("p", 10.5, 4.6, [(1.0, "fallen")]),
        "q": person("q", 9.6, 4.6),
        "r": person("r", 11.4, 4.6),
    })
    sim = Simulation(world)
    start = paper.places["hall"]
    sim.advance(0.5)
    assert sim.people["q"].giving_room is None and sim.people["r"].giving_room is None  # p standing
    sim.advance(1.1)
    assert sim.people["p"].posture == "fallen"
    assert sim.people["q"].giving_room is not None and sim.people["r"].giving_room is not None
    # p just fell: q still stands at the west end, but is stepping aside, and the estimate
    # counts them where they are going (Scene.as_expected): no transient "unreachable"
    early, _ = sim.motion.approach(start, "p")
    assert early is not None and math.dist(sim.people["q"].pose[:2], (9.6, 4.6)) < 0.1
    sim.advance(8.0)
    q, r = sim.people["q"], sim.people["r"]
    assert math.dist((q.x, q.y), (10.5, 4.6)) >= sim._room_clear() - 1e-9
    assert room_of(world, q.x, q.y) == room_of(world, 10.5, 4.6) == "bedroom"
    assert r.giving_room == ("p", None) and (r.x, r.y) == (11.4, 4.6)
    goal, est = sim.motion.approach(start, "p")
    assert goal is not None and est.reachable and math.dist(goal[:2], (10.5, 4.6)) == pytest.approx(0.9)
    sim.people["p"].set_posture("standing")  # helped up: the bystanders go back to their scripts
    sim.advance(20.0)
    assert sim.people["q"].giving_room is None
    assert math.dist((sim.people["q"].x, sim.people["q"].y), (9.6, 4.6)) < 1e-6


@pytest.mark.slow
def test_nobody_makes_room_by_stepping_into_a_dead_end() -> None:
    """Full day, seed 8: people making room for someone fallen at the entrance of the
    corridor between the bed and the bathroom wall stepped to the nearest free spot — in
    the corridor's dead end, where the robot could no longer reach them.  An aside spot must
    be one the robot can drive to."""
    import dataclasses
    from pathlib import Path

    from robot.spec import load_world

    world = load_world(Path(__file__).resolve().parents[2] / "experiments" / "days" / "protocols"
                       / "tabsa_apartment.toml")

    def person(name: str, x: float, y: float, posture: str = "standing") -> PersonSpec:
        return PersonSpec(name, (x, y, 0.0), posture, 0.5, (), ())

    sim = Simulation(dataclasses.replace(world, people={"f": person("f", 9.18, 4.62, "fallen"),
                                                       "b": person("b", 10.2, 4.6)}))
    sim.advance(0.5)
    spot = sim.people["b"].giving_room
    assert spot is not None and spot[0] == "f"
    if spot[1] is not None:
        bedroom = world.places["bedroom"]
        sim.scene.set_making_way("b", True)
        assert sim.planner.plan(bedroom[:2], spot[1]) is not None, spot
        assert spot[1][0] < 11.0, spot  # not in the dead end east of the bed
