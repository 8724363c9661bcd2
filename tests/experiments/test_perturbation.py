"""A world that changes under the robot: exogenous events drawn around a variant's interruption."""

from __future__ import annotations

from pathlib import Path

import pytest

from experiments.inputs import scenario as sc
from experiments.inputs.perturbation import TOGGLE, Perturbation
from experiments.inputs.scenario import InterruptionGrid
from experiments.sweep.spec import load_spec
from tasker.support.reader import InputError

GRID = InterruptionGrid("requests[2]", 0.0, 180.0, 60.0)


@pytest.fixture(scope="module")
def household() -> sc.RobotScenario:
    return sc.load(sc.resolve("household"))


def _drawn(v: sc.RobotScenario) -> list[tuple[float, str, object]]:
    return [(a.t, a.fields["what"], a.fields["value"]) for a in v.actions if a.origin[0] == "perturbation"]


def test_the_same_seed_draws_the_same_events_and_the_control_arm_is_the_same_variant(
        household: sc.RobotScenario) -> None:
    for seed in range(1, 6):
        a = sc.randomize(household, seed, interruption=GRID, perturbation=Perturbation())
        b = sc.randomize(household, seed, interruption=GRID, perturbation=Perturbation())
        control = sc.randomize(household, seed, interruption=GRID)
        assert _drawn(a) == _drawn(b)
        assert [x for x in a.actions if x.origin[0] != "perturbation"] == list(control.actions)
        assert a.people == control.people


def test_events_fall_in_the_window_round_the_interruption_and_toggle_what_they_find(
        household: sc.RobotScenario) -> None:
    p = Perturbation(rate_per_min=20.0, before_s=10.0, after_s=30.0)
    seen = set()
    for seed in range(1, 8):
        v = sc.randomize(household, seed, interruption=GRID, perturbation=p)
        at = next(a.t for a in v.actions if a.origin == ("requests", 2))
        for t, what, value in _drawn(v):
            seen.add(what)
            if what == "walk":
                continue  # a bystander's walk back comes after their stay, possibly past the window
            assert at - 10.0 <= t <= at + 30.0 + 1e-6
            if what in ("door", "device"):  # whichever it is not when it happens: the robot's changes count
                assert value[1] == TOGGLE
    assert {"door", "move", "device", "walk"} <= seen


def test_a_toggle_turns_what_it_finds_when_it_happens(tmp_path: Path) -> None:
    """The robot may have opened or closed the door since the events were drawn: the event toggles
    the door as it finds it, and the trace says what it did."""
    import dataclasses

    from experiments.inputs.actions import TimedAction
    from experiments.run.runner import run_scenario

    scn = sc.load(sc.resolve("carry"))  # the flat's bedroom door starts closed
    shut = [TimedAction(1.0, "world", {"what": "door", "value": ["bedroom_door", TOGGLE], "note": "a"}),
            TimedAction(2.0, "world", {"what": "door", "value": ["bedroom_door", TOGGLE], "note": "b"}),
            TimedAction(3.0, "world", {"what": "device", "value": ["cooker", TOGGLE], "note": "c"})]
    scn = dataclasses.replace(scn, actions=tuple(sorted([*scn.actions, *shut], key=lambda a: a.t)), horizon=4.0)
    world = [(e["t"], e["value"]) for e in run_scenario(scn, pictures=False).trace.events if e["event"] == "world"
             and e["note"] in ("a", "b", "c")]
    assert world == [(1.0, ["bedroom_door", True]), (2.0, ["bedroom_door", False]), (3.0, ["cooker", "off"])]


def test_no_events_at_rate_zero_and_no_window_without_an_interruption(household: sc.RobotScenario) -> None:
    v = sc.randomize(household, 3, interruption=GRID, perturbation=Perturbation(rate_per_min=0.0))
    assert _drawn(v) == []
    with pytest.raises(sc.ScenarioError, match="interruption grid"):
        sc.randomize(household, 3, perturbation=Perturbation())


@pytest.mark.parametrize(("table", "message"), [
    ("rate_per_min = -1", "rate_per_min"),
    ('kinds = ["door", "flood"]', "kinds"),
    ("stand_s = [5, 1]", "stand_s"),
])
def test_a_bad_perturbation_table_names_its_field(tmp_path: Path, table: str, message: str) -> None:
    spec = tmp_path / "s.toml"
    spec.write_text('scenarios = ["household"]\nseeds = 2\nstrategies = ["suspension=static"]\n'
                    '[variants.household]\ninterrupt = "requests[2]"\ntimes = { start = 0, stop = 180, step = 60 }\n'
                    f"[perturbation]\n{table}\n")
    with pytest.raises(InputError, match=message):
        load_spec(spec)


def test_a_spec_with_perturbation_gives_it_to_the_jobs_of_varied_scenarios(tmp_path: Path) -> None:
    spec = tmp_path / "s.toml"
    spec.write_text('scenarios = ["household"]\nseeds = 2\nstrategies = ["suspension=static"]\n'
                    '[variants.household]\ninterrupt = "requests[2]"\ntimes = { start = 0, stop = 180, step = 60 }\n'
                    "[perturbation]\nrate_per_min = 2\n")
    jobs = load_spec(spec).jobs()
    assert all(j.perturbation == Perturbation(rate_per_min=2.0) for j in jobs)


def _scenario(tmp_path: Path, events: str) -> Path:
    path = tmp_path / "s.toml"
    path.write_text('kind = "robot"\nname = "s"\nworld = "paper"\n[settings]\nhorizon = 30.0\n' + events)
    return path


def test_device_and_move_world_events_are_checked_run_and_traced(tmp_path: Path) -> None:
    from experiments.run.runner import run_scenario

    ok = _scenario(tmp_path, '[[world_events]]\nt = 1.0\ndevice = ["cooker", "on"]\nnote = "x"\n'
                             '[[world_events]]\nt = 2.0\nmove = ["pan", "hall"]\n')
    with pytest.warns(UserWarning):  # a scenario without requests is valid, and said so
        result = run_scenario(ok, pictures=False)
    world = [(e["t"], e["what"], e["value"]) for e in result.trace.events if e["event"] == "world"]
    assert world == [(1.0, "device", ["cooker", "on"]), (2.0, "move", ["pan", "hall"])]
    for bad, message in (('device = ["kettle", "on"]', "kettle"), ('move = ["pan", "garden"]', "garden"),
                         ('move = ["pan"]', "expected \\[object, place\\]")):
        with pytest.raises(sc.ScenarioError, match=message):
            sc.load(_scenario(tmp_path, f"[[world_events]]\nt = 1.0\n{bad}\n"))


def test_a_world_files_own_events_are_run_and_traced_like_a_scenarios(tmp_path: Path) -> None:
    """The paper world makes Peter fall at 60 s and Sara at 90 s: the trace says so, once each, in time
    order with the scenario's own events."""
    from experiments.run.runner import run_scenario

    path = tmp_path / "s.toml"
    path.write_text('kind = "robot"\nname = "s"\nworld = "paper"\n[settings]\nhorizon = 95.0\n'
                    '[[world_events]]\nt = 61.0\nposture = ["alice", "fallen"]\n')
    with pytest.warns(UserWarning):
        result = run_scenario(path, pictures=False)
    world = [(e["t"], e["value"], e.get("note", "")) for e in result.trace.events if e["event"] == "world"]
    assert world == [(60.0, ["peter", "fallen"], "world file paper"), (61.0, ["alice", "fallen"], ""),
                     (90.0, ["sara", "fallen"], "world file paper")]
