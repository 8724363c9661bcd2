"""The base's time profile (robot.drive), against times worked out by hand.

The expected values are kinematics, not calls of the code under test: a rest-to-rest move of
``d`` with top speed ``v`` and acceleration ``a`` takes ``d/v + v/a`` when it reaches ``v``
(``d·a >= v²``: two ramps of ``v/a`` s covering ``v²/a`` together, the rest at ``v``), else
``2·sqrt(d/a)`` (accelerate over half the way, brake over the other).
"""

from __future__ import annotations

import math

import pytest

from robot.drive import DriveLimits, profile_time

LIMITS = DriveLimits(v_max=0.5, w_max=1.0, accel=0.5, turn_accel=2.0)


@pytest.mark.parametrize(("distance", "v_max", "accel", "seconds"), [
    (2.0, 0.5, 0.5, 5.0),                # 1 s up (0.25 m), 3 s at 0.5 m/s (1.5 m), 1 s down (0.25 m)
    (0.1, 0.5, 0.5, 2 * math.sqrt(0.2)),  # never reaches 0.5 m/s: 0.05 m up, 0.05 m down
    (0.5, 0.5, 0.5, 2.0),                # just reaches it: 1 s up, 1 s down
    (-2.0, 0.5, 0.5, 5.0),               # backwards takes as long
    (math.pi / 2, 1.0, 2.0, math.pi / 2 + 0.5),  # a quarter turn: 0.5 s up, pi/2 - 0.5 s at 1 rad/s, 0.5 s down
])
def test_a_rest_to_rest_move_takes_what_kinematics_says(distance: float, v_max: float, accel: float,
                                                       seconds: float) -> None:
    assert profile_time(distance, v_max, accel) == pytest.approx(seconds, rel=1e-12)


def test_a_path_is_stop_turn_drive_at_each_corner() -> None:
    path = [(0.0, 0.0), (2.0, 0.0), (2.0, 0.1)]
    first = 5.0                               # 2 m east, already facing east: no turn
    corner = math.pi / 2 + 0.5                # a quarter turn to face north
    last = 2 * math.sqrt(0.2)                 # 0.1 m north: too short to reach top speed
    assert LIMITS.travel_time(path, 0.0, math.pi / 2) == pytest.approx(first + corner + last, rel=1e-12)
    # facing west at the end: another quarter turn; facing west at the start: half a turn first
    assert LIMITS.travel_time(path, 0.0, math.pi) == pytest.approx(first + 2 * corner + last, rel=1e-12)
    half = math.pi + 0.5                      # half a turn: 0.5 s up, pi - 0.5 s at 1 rad/s, 0.5 s down
    assert LIMITS.travel_time(path, math.pi, math.pi / 2) == pytest.approx(half + first + corner + last, rel=1e-12)


def test_a_turn_within_the_tolerance_and_a_zero_length_step_take_no_time() -> None:
    assert LIMITS.turn_time(0.01) == 0.0 and LIMITS.turn_time(2 * math.pi) == 0.0
    assert LIMITS.drive_time(0.0) == 0.0
    assert LIMITS.travel_time([(1.0, 1.0), (1.0, 1.0)], 0.0, None) == 0.0
