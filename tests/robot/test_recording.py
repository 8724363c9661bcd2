"""The recorded trajectory: a fixed rate, people and postures, a documented file, reproducible."""

from __future__ import annotations

import pytest

from robot.recording import RECORD_HZ, Recorder, read_trajectory
from robot.sim import Simulation
from tasker.protocols import SkillState
from tasker.stage import Stage


def _drive(sim: Simulation, to: str, until: float) -> float:
    stage = Stage("navigate", ("robot", to), skill="navigate", data={"to": to})
    now = sim.time
    sim.begin("d1", stage, now)
    while sim.poll("d1", stage, now).state is SkillState.RUNNING and now < until:
        now += 0.1
    return now


def test_trajectory_has_robot_and_people_at_a_fixed_rate(paper, tmp_path) -> None:
    sim = Simulation(paper)
    end = _drive(sim, "kitchen", 60.0)
    sim.advance(end + 1.0)
    head, samples, _ = read_trajectory(sim.write_trajectory(tmp_path / "trajectory.jsonl"))
    assert head["world"] == "paper" and head["rate_hz"] == RECORD_HZ
    times = [s.t for s in samples]
    steps = [b - a for a, b in zip(times, times[1:], strict=False)]
    assert times[0] == 0.0 and steps == pytest.approx([1 / RECORD_HZ] * len(steps))
    assert {p.name for p in samples[-1].people} == set(paper.people)
    assert samples[-1].robot[:2] == pytest.approx(sim.robot_pose()[:2], abs=1e-3)
    moved = [p for p in samples[-1].people if p.name == "john"][0]
    assert (moved.x, moved.y) != paper.people["john"].pose[:2]  # John walks his script


def test_postures_are_recorded_as_they_change(paper, tmp_path) -> None:
    sim = Simulation(paper)
    sim.advance(62.0)  # Peter falls at 60 s
    _, samples, _ = read_trajectory(sim.write_trajectory(tmp_path / "t.jsonl"))
    peter = [next(p for p in s.people if p.name == "peter").posture for s in samples]
    assert peter[0] == "standing" and peter[-1] == "fallen"


def test_same_run_same_file(paper, tmp_path) -> None:
    texts = []
    for k in range(2):
        sim = Simulation(paper)
        _drive(sim, "bedroom", 40.0)
        texts.append(sim.write_trajectory(tmp_path / f"{k}.jsonl").read_text())
    assert texts[0] == texts[1]


def test_a_still_robot_costs_no_physics(paper) -> None:
    sim = Simulation(paper)
    sim.advance(10.0)
    assert sim.physics_ticks < 50  # settling only: 500 ticks passed
    x, y, _ = sim.robot_pose()
    assert (x, y) == pytest.approx(paper.robot.pose[:2], abs=1e-3)


def test_bad_files_and_rates_are_refused(tmp_path) -> None:
    with pytest.raises(ValueError, match="rate_hz"):
        Recorder("paper", rate_hz=0)
    bad = tmp_path / "x.jsonl"
    bad.write_text('{"format": "other"}\n')
    with pytest.raises(ValueError, match="x.jsonl:1: format"):
        read_trajectory(bad)


@pytest.mark.slow
def test_skipping_still_ticks_changes_nothing(paper, monkeypatch) -> None:
    """The same drive and waits with and without skipping: identical samples and physics."""
    def scenario(sim: Simulation) -> tuple[list[str], object]:
        sim.advance(12.0)  # still: John waits until 10 s, then walks
        end = _drive(sim, "bedroom", 80.0)
        wait = Stage("wait", (), skill="wait", duration=7.0)
        sim.begin("d1", wait, end)
        sim.advance(end + 30.0)
        return sim.recording.lines(), sim.mj.state().tolist()

    fast = scenario(Simulation(paper))
    monkeypatch.setattr(Simulation, "_fast_forward", lambda self, now: False)
    slow = scenario(Simulation(paper))
    assert fast == slow


def test_a_sample_line_is_what_the_json_encoder_writes() -> None:
    """Sample.line writes the JSON by hand (the encoder was a second of a day's run): the
    same bytes as json.dumps(to_json(), sort_keys=True), whatever the numbers and names."""
    import json
    import random

    from robot.recording import PersonState, Sample

    rng = random.Random(3)
    values = [0.0, -0.0, 1.0, -1e-5, 1e-5, 123456.789012, -3.14159265, 2.00005, 1e16]
    for _ in range(300):
        def v() -> float:
            return rng.choice(values) if rng.random() < 0.3 else rng.uniform(-20, 20)
        names = rng.sample(["zoe", "anna", "b_2", 'odd"name', "\u00e9mile", "x-y"], rng.randint(0, 4))
        people = tuple(PersonState(n, v(), v(), v(), rng.choice(["standing", "sitting", "fallen"])) for n in names)
        s = Sample(round(rng.uniform(0, 4000), 2), (v(), v(), v()), people)
        assert s.line() == json.dumps(s.to_json(), sort_keys=True)


def test_a_remembered_person_keeps_the_sign_of_zero() -> None:
    """Sample.line remembers each person's text; 0.0 == -0.0 must not hand one the other's."""
    import itertools
    import json

    from robot.recording import PersonState, Sample

    for x, y, yaw in itertools.product([0.0, -0.0, 1.5], repeat=3):
        for xs in ([x, -x], [-x, x]):
            for value in xs:
                s = Sample(1.0, (0.0, 0.0, 0.0), (PersonState("ann", value, y, yaw, "standing"),))
                assert s.line() == json.dumps(s.to_json(), sort_keys=True)


def test_samples_kept_in_memory_are_the_samples_read_from_the_file(paper, tmp_path) -> None:
    """A day takes its samples from memory (Recorder.samples_as_read) instead of writing the
    file and reading it back: the two must be the same samples, value for value."""
    import random

    from robot.recording import PersonState, Sample

    sim = Simulation(paper)
    sim.advance(_drive(sim, "kitchen", 60.0) + 2.0)  # people walk, Peter falls on the way
    rec = sim.recording
    rng = random.Random(2)  # and awkward numbers: signed zeros, halves at the 4th place, big ones
    for k in range(200):
        v = [rng.choice([0.0, -0.0, 1.23455, -2.00005, 1e16, rng.uniform(-9, 9)]) for _ in range(9)]
        rec.samples.append(Sample(200.0 + k / 7, (v[0], v[1], v[2]),
                                  (PersonState("zed", v[3], v[4], v[5], "sitting"),
                                   PersonState("amy", v[6], v[7], v[8], "standing"))))
    _, samples, _ = read_trajectory(sim.write_trajectory(tmp_path / "t.jsonl"))
    assert rec.samples_as_read() == samples
    def reprs(s: Sample) -> tuple[str, ...]:  # -0.0 stays -0.0
        return tuple(map(repr, (s.t, *s.robot, *(v for p in s.people for v in (p.x, p.y, p.yaw)))))

    assert [reprs(s) for s in rec.samples_as_read()] == [reprs(s) for s in samples]
