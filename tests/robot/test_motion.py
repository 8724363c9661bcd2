"""Base planning: collision-free against the real robot, unreachable is infinite, deterministic."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from robot import roadmap
from robot.drive import DriveLimits
from robot.motion import BasePlanner
from robot.scene import Scene
from robot.tiago import RobotCollision, robot_dimensions
from tasker.world import UNREACHABLE, MotionModel


def _dense(path, step=0.02):
    out = []
    for (x0, y0), (x1, y1) in itertools.pairwise(path):
        n = max(1, math.ceil(math.hypot(x1 - x0, y1 - y0) / step))
        yaw = math.atan2(y1 - y0, x1 - x0)
        out += [(x0 + (x1 - x0) * k / n, y0 + (y1 - y0) * k / n, yaw) for k in range(n + 1)]
    return out


@pytest.mark.slow
def test_paths_are_collision_free_against_the_tiago_mesh_model(paper, paper_motion) -> None:
    assert isinstance(paper_motion, MotionModel)
    boxes = [(*o.box, o.height) for o in paper.obstacles]
    robot = RobotCollision(boxes)
    names = sorted(paper.places)
    checked = 0
    for a, b in itertools.islice(itertools.permutations(names, 2), 0, None, 4):
        est = paper_motion.estimate(paper.places[a], paper.places[b])
        assert est.reachable, (a, b)
        for x, y, yaw in _dense(est.path):
            for turn in (0.0, math.pi / 2):  # the base turns in place at corners: any yaw
                assert not robot.collides(x, y, yaw + turn), (a, b, x, y)
                checked += 1
    assert checked > 1000


def test_walled_off_and_closed_door_goals_are_unreachable(flat, flat_motion) -> None:
    living = flat.places["living"]
    assert flat_motion.estimate(living, flat.places["storage"]) == UNREACHABLE
    behind_door = flat_motion.estimate(living, flat.places["bedroom"])
    assert not behind_door.reachable and math.isinf(behind_door.time_s)
    scene = flat_motion.planner.scene
    version = scene.version
    scene.set_door("bedroom_door", True)
    try:
        assert scene.version != version
        opened = flat_motion.estimate(living, flat.places["bedroom"])
        assert opened.reachable and 0 < opened.time_s < math.inf
    finally:
        scene.set_door("bedroom_door", False)
    assert not flat_motion.estimate(living, flat.places["bedroom"]).reachable


def test_goal_in_collision_or_outside_is_unreachable(paper, paper_motion) -> None:
    hall = paper.places["hall"]
    assert not paper_motion.estimate(hall, (1.5, 2.1, 0.0)).reachable  # on the coffee table
    assert not paper_motion.estimate(hall, (-3.0, 2.0, 0.0)).reachable


def test_estimate_counts_rotation(paper_motion) -> None:
    a = paper_motion.estimate((6.0, 3.0, 0.0), (6.0, 3.0, math.pi / 2))
    # TIAGo turns at 1 rad/s with 2 rad/s²: 0.5 s up, pi/2 - 0.5 s at full rate, 0.5 s down
    assert a.reachable and a.distance_m == 0 and a.time_s == pytest.approx(math.pi / 2 + 0.5)
    straight = paper_motion.estimate((6.0, 3.0, math.pi / 2), (6.0, 5.0, math.pi / 2))
    turning = paper_motion.estimate((6.0, 3.0, -math.pi / 2), (6.0, 5.0, math.pi / 2))
    assert turning.time_s > straight.time_s + 2.0


def test_same_seed_same_roadmap_and_path(paper) -> None:
    radius = robot_dimensions()[2]
    saved = dict(roadmap._CACHE)
    roadmap._CACHE.clear()
    try:
        paths = []
        for _ in range(2):
            roadmap._CACHE.clear()
            planner = BasePlanner(paper, Scene(paper, radius), seed=5, milestones=600)
            paths.append((planner.roadmap.nodes.copy(), planner.plan((6.0, 1.0), (1.0, 6.75))))
        assert np.array_equal(paths[0][0], paths[1][0])
        assert paths[0][1] == paths[1][1] and paths[0][1] is not None
    finally:
        roadmap._CACHE.clear()
        roadmap._CACHE.update(saved)


def test_people_block_and_cache_follows_the_scene(paper) -> None:
    scene = Scene(paper, robot_dimensions()[2])
    planner = BasePlanner(paper, scene)
    clear = planner.plan((6.0, 1.0), (6.0, 7.0))
    assert clear is not None
    scene.set_person("john", 6.0, 4.0, "fallen")  # lying across the hall
    assert planner.plan((6.0, 1.0), (6.0, 7.0)) != clear
    scene.remove_person("john")
    assert planner.plan((6.0, 1.0), (6.0, 7.0)) == clear


def test_drive_limits_reject_nonsense() -> None:
    with pytest.raises(ValueError, match="v_max"):
        DriveLimits(v_max=0)


def test_estimate_to_a_person_is_to_the_pose_navigation_drives_to(paper) -> None:
    from robot.estimator import APPROACH, motion_model

    motion = motion_model(paper)
    scene = motion.planner.scene
    scene.set_person("sara", 9.3, 0.5, "fallen")  # lying against the bathroom's south wall
    start = paper.places["hall"]
    est = motion.estimate(start, (9.3, 0.5, 0.0))
    goal, via_approach = motion.approach(start, "sara")
    assert est.reachable and math.isfinite(est.time_s)  # the centre itself is in collision
    assert goal is not None and est == via_approach and est.end_pose == goal
    assert math.dist(goal[:2], (9.3, 0.5)) == pytest.approx(APPROACH)


def test_approach_tries_a_farther_ring_when_the_near_one_is_shut(paper, monkeypatch) -> None:
    """A person lying between the bed and the wall with people at both ends: no pose 0.9 m
    away is free and reachable (the one ring the day benchmark's falls died of).  The
    farther rings' free poses lie through the wall, so the person stays unreachable until
    one end opens; then estimate and navigation agree on a pose that sees them."""
    import dataclasses

    from robot import estimator as m

    # the paper apartment's bedroom: the bed spans y 5.2-7.4 from x 9.8; p lies south of it
    motion = m.motion_model(dataclasses.replace(paper, people={}))
    scene = motion.planner.scene
    scene.set_person("p", 10.5, 4.6, "fallen")
    scene.set_person("q", 9.6, 4.6, "standing")
    scene.set_person("r", 11.4, 4.6, "standing")
    start = paper.places["hall"]
    monkeypatch.setattr(m, "APPROACH_RINGS", (m.APPROACH,))
    assert motion.approach(start, "p") == (None, UNREACHABLE)
    monkeypatch.undo()
    # every farther-ring pose that is free lies south of the bathroom/bedroom wall (y 3.95-4.05):
    # the person cannot be helped from there, so they are unreachable while both stand by
    assert motion.approach(start, "p") == (None, UNREACHABLE)
    scene.set_person("q", 9.0, 3.0, "standing")  # q goes into the bathroom: the west end, the way in, opens
    goal, est = motion.approach(start, "p")
    assert goal is not None and est.reachable and est.end_pose == goal
    assert scene.sees(goal[:2], (10.5, 4.6))
    assert motion.estimate(start, (10.5, 4.6, 0.0)) == est


def test_travel_matrix_in_one_call(paper) -> None:
    from robot.estimator import travel_matrix
    from tasker.errors import UnknownName

    m = travel_matrix(paper, ["hall", "kitchen", "john", (6.0, 2.0)], seed=1)
    assert m.labels == ("hall", "kitchen", "john", "6,2") and m.time_s.shape == (4, 4)
    assert (np.diag(m.time_s) == 0).all() and np.isfinite(m.time_s).all()
    assert m.to_json()["labels"] == list(m.labels)
    with pytest.raises(UnknownName, match="kitchen"):
        travel_matrix(paper, ["hall", "kitchn"])


def test_table_is_one_search_per_source(paper) -> None:
    from robot.estimator import motion_model

    motion = motion_model(paper)
    poses = [paper.places[n] for n in sorted(paper.places)]
    before = motion.planner.searches
    table = motion.table(poses)
    assert motion.planner.searches - before <= 2 * len(poses)  # door layer, and people where they are in the way
    assert table[0, 1] == motion.estimate(poses[0], poses[1]).time_s


def test_travel_matrix_and_seed_checks_fire() -> None:
    from robot.estimator import TravelMatrix
    from robot.roadmap import ompl_seed

    with pytest.raises(ValueError, match="2 labels need 2 poses"):
        TravelMatrix("paper", 1, ("a", "b"), ((0.0, 0.0, 0.0),), np.zeros((2, 2)), np.zeros((2, 2)))
    with pytest.raises(ValueError, match="seed must be >= 0"):
        ompl_seed(-1)
    assert ompl_seed(0) == 1 and ompl_seed(1) == 2


def test_ignoring_people_keeps_the_doors_as_they_are(flat, flat_motion) -> None:
    """What a plan's connectivity may rely on: walls and closed doors, never where people stand."""
    living, bedroom = flat.places["living"], flat.places["bedroom"]
    assert flat_motion.closed_doors() == ("bedroom_door",)
    assert not flat_motion.estimate_ignoring_people(living, bedroom).reachable  # the door is closed
    assert flat_motion.estimate_ignoring_doors(living, bedroom).reachable
    scene = flat_motion.planner.scene
    kitchen = flat.places["kitchen"]
    free = flat_motion.estimate_ignoring_people(living, kitchen)
    before = dict(scene.people)
    scene.set_person("bob", (living[0] + kitchen[0]) / 2, (living[1] + kitchen[1]) / 2, "fallen")
    try:
        assert flat_motion.estimate_ignoring_people(living, kitchen) == free
        assert flat_motion.estimate(living, kitchen) != free
    finally:
        scene.remove_person("bob")
    assert scene.people == before
