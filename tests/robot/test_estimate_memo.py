"""Remembered motion estimates (``MotionEstimator.memo``) are the answers computed afresh."""

from __future__ import annotations

import random

import pytest

from robot.drive import DriveLimits
from robot.estimator import MotionEstimator
from robot.motion import BasePlanner, open_planner
from robot.scene import Scene
from robot.spec import WorldSpec
from robot.tiago import robot_dimensions


@pytest.mark.slow
def test_remembered_estimates_equal_fresh_ones_as_the_scene_changes(paper: WorldSpec) -> None:
    rng = random.Random(7)
    scene = Scene(paper, robot_dimensions()[2])
    for p in paper.people.values():
        scene.set_person(p.name, p.pose[0], p.pose[1], p.posture)
    planner = BasePlanner(paper, scene, seed=1)
    limits = DriveLimits.of(paper.robot)
    opened = open_planner(paper, scene.radius, 1)
    cached = MotionEstimator(planner, limits, opened)
    fresh = MotionEstimator(planner, limits, opened, memo=False)
    (x0, y0), (x1, y1) = paper.bounds
    starts = [p for p in paper.places.values()]
    while len(starts) < 14:
        x, y = round(rng.uniform(x0, x1), 2), round(rng.uniform(y0, y1), 2)
        if scene.free(x, y):
            starts.append((x, y, round(rng.uniform(-3, 3), 2)))
    def ask(queries: list[tuple[tuple[float, float, float], list[tuple[float, float, float]]]]) -> None:
        for a, goals in queries:
            for b in goals:
                assert cached.estimate(a, b) == fresh.estimate(a, b), (step, a, b)
            for who in sorted(scene.people):
                assert cached.approach(a, who) == fresh.approach(a, who), (step, a, who)

    hits = 0
    for step in range(6):
        people = [(dd.x, dd.y, 0.0) for _, dd in sorted(scene.people.items())]
        queries = [(a, rng.sample(starts, 3) + people) for a in rng.sample(starts, 5)]
        ask(queries)  # remembered now
        # the scene changes under the estimator (people move, fall, step aside; a door
        # shuts): the same questions must get the new answers, then again from memory
        name = sorted(paper.people)[step % len(paper.people)]
        d = scene.people[name]
        if step == 1:
            scene.set_person(name, d.x, d.y, "fallen")
        elif step == 2:  # bumps no version: the spot is part of the memo's state
            scene.set_stepping_to(name, (d.x + 0.5, d.y))
        elif step == 3:
            scene.set_door("living_kitchen", False)
        elif step == 4:
            scene.set_stepping_to(sorted(scene.stepping_to)[0], None)
            scene.set_making_way("john", True)
        else:  # John makes way (no path changes) but is still whom the robot goes to
            scene.set_person(name, d.x + 0.3, d.y, "standing")
            john = scene.people["john"]
            scene.set_person("john", john.x - 0.4, john.y + 0.2, "standing")
        ask(queries)
        ask(queries)
        hits += len(cached._memo)
    assert hits > 0  # the memo was used, not bypassed
