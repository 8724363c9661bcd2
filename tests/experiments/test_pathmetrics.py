"""Abandonment and travel distance on a small hand-made day, checked against values computed by hand."""

from __future__ import annotations

import pytest

from experiments.metrics.paths import abandonments, path_metrics, travel_m
from robot.recording import PersonState, Sample
from tests.experiments.events import completed

# The robot on the x axis, one sample a second; Ann lies at the origin from t = 0; Bob stands at (0, 5).
XS = [5.0, 3.0, 1.5, 1.0, 2.5, 1.0, 1.0, 1.0, 3.0, 3.0, 3.0]


def samples(ann_up_at: float = 99.0) -> list[Sample]:
    return [Sample(float(t), (x, 0.0, 0.0),
                   (PersonState("ann", 0.0, 0.0, 0.0, "fallen" if t < ann_up_at else "standing"),
                    PersonState("bob", 0.0, 5.0, 0.0, "standing")))
            for t, x in enumerate(XS)]


EVENTS = completed([
    {"t": 1.0, "event": "request", "agent": "d1", "task_type": "help", "args": {"person": "ann", "deadline": 9.0}},
    {"t": 1.0, "event": "request", "agent": "d2", "task_type": "escort", "args": {"person": "bob", "to": "hall"}},
    {"t": 7.5, "event": "end", "agent": "d1", "task_type": "help", "cause": "finished"},
])


def test_travel_is_the_length_of_the_sampled_path() -> None:
    # |5-3| + |3-1.5| + |1.5-1| + |1-2.5| + |2.5-1| + 0 + 0 + |1-3| + 0 + 0
    assert travel_m(samples()) == pytest.approx(2 + 1.5 + 0.5 + 1.5 + 1.5 + 2)


def test_leaving_the_circle_before_helping_is_an_abandonment() -> None:
    # from the request (t=1): 3 out, 1.5 in, 1 in, 2.5 OUT (1), 1 in, 1, 1; t=8 (3 m) is after the end at 7.5
    assert abandonments(EVENTS, samples()) == {"d1": 1}
    assert path_metrics(EVENTS, samples()) == {"abandonments": 1, "abandoned_falls": 1,
                                               "abandonments_other_task": 1, "travel_m": 9.0}


def test_leaving_after_helping_is_not() -> None:
    done_early = [*EVENTS[:2], {**EVENTS[2], "t": 3.5}]  # finished before the robot left at t=4
    assert abandonments(done_early, samples()) == {"d1": 0}


def test_a_person_no_longer_down_ends_the_watch() -> None:
    assert abandonments(EVENTS, samples(ann_up_at=4.0)) == {"d1": 0}  # up before the robot left


def test_a_smaller_circle_changes_the_count() -> None:
    # radius 1.2: in at t=3 (1.0), out at t=4 (2.5): 1; in at t=5..7: no exit before the end
    assert abandonments(EVENTS, samples(), radius=1.2) == {"d1": 1}
    # radius 0.9: the robot is never inside, so it never leaves
    assert abandonments(EVENTS, samples(), radius=0.9) == {"d1": 0}


def _roles(*changes: tuple[float, str | None]) -> list[dict[str, object]]:
    return completed({"t": t, "event": "roles", "exeDA": a, "irrDA": None, "idleDA": []} for t, a in changes)


def test_leaving_while_driving_to_the_person_is_not_for_another_task() -> None:
    # the robot leaves the circle at t=4; who executes then decides
    theirs = sorted(EVENTS + _roles((1.0, "d1")), key=lambda e: e["t"])
    assert abandonments(theirs, samples()) == {"d1": 1}  # TaBSA's count: walls and all
    assert abandonments(theirs, samples(), for_another_task=True) == {"d1": 0}
    assert path_metrics(theirs, samples())["abandonments_other_task"] == 0
    other = sorted(EVENTS + _roles((1.0, "d1"), (3.5, "d2"), (5.0, "d1")), key=lambda e: e["t"])
    assert abandonments(other, samples(), for_another_task=True) == {"d1": 1}  # escort took the robot at 3.5
    back = sorted(EVENTS + _roles((1.0, "d2"), (4.0, "d1")), key=lambda e: e["t"])
    assert abandonments(back, samples(), for_another_task=True) == {"d1": 0}  # d1 executing from t=4 on


def test_a_fall_requested_again_is_watched_until_its_last_task_ends() -> None:
    # d1's help failed at t=2 and was asked again as d3 at t=5, which finished at 7.5: the robot
    # leaving at t=4 (between them) left Ann lying, and it counts once, for the need d1
    renewed = completed([EVENTS[0], EVENTS[1],
                         {"t": 2.0, "event": "end", "agent": "d1", "task_type": "help", "cause": "failed"},
                         {"t": 5.0, "event": "request", "agent": "d3", "task_type": "help",
                          "args": EVENTS[0]["args"], "renews": "d1"},
                         {"t": 7.5, "event": "end", "agent": "d3", "task_type": "help", "cause": "finished"}])
    assert abandonments(renewed, samples()) == {"d1": 1}
    # the renewal executing counts as the fall's own task, not another's
    theirs = sorted(renewed + _roles((1.0, "d2"), (3.5, "d3")), key=lambda e: e["t"])
    assert abandonments(theirs, samples(), for_another_task=True) == {"d1": 0}
    assert path_metrics(renewed, samples())["abandoned_falls"] == 1
