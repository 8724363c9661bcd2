"""The factorial sweep: factors and their grid, the stratified interruption grid, people moved in free space."""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pytest

from experiments.inputs import scenario as scenarios
from experiments.inputs.scenario import InterruptionGrid
from experiments.inputs.strategy import Strategy, expand
from experiments.sweep.spec import SpecError, load_spec
from robot.scene import PERSON_RADIUS, Scene
from robot.spec import load_world


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "spec.toml"
    path.write_text(textwrap.dedent(text), encoding="utf-8")
    return path


# ----------------------------------------------------------------------------------------- factors


def test_strategy_label_with_policy_and_hazard_waiting_round_trips() -> None:
    s = Strategy(suspension="planned", policy="conditional", hazard_waiting=True)
    assert s.label == "suspension=planned,policy=conditional,hazard_waiting=on"
    assert Strategy.parse(s.label) == s
    assert Strategy.parse("hazard_waiting=off").hazard_waiting is False
    # labels of older sweeps are unchanged: the new factors appear only when set
    assert Strategy("planned", "static", "alg2").label == "update=planned,suspension=static,scheduler=alg2"
    with pytest.raises(ValueError, match="policy: expected one of"):
        Strategy(policy="sometimes")
    with pytest.raises(ValueError, match="hazard_waiting: expected on/off"):
        Strategy.parse("hazard_waiting=maybe")
    with pytest.raises(ValueError, match="did you mean 'policy'"):
        Strategy.parse("polcy=strict")
    # a factor with no value was answered "did you mean 'suspension'?" for 'suspension='
    for text, expected in (("suspension=",
                            "suspension: expected static or planned or derived or fallback after 'suspension='"),
                           ("update=static, hazard_waiting = ", "hazard_waiting: expected off or on after"),
                           ("scheduler=", "scheduler: expected a scheduler name after 'scheduler='")):
        with pytest.raises(ValueError, match=expected) as info:
            Strategy.parse(text)
        assert "did you mean" not in str(info.value)
    with pytest.raises(ValueError, match="hazard_waiting: expected true or false"):
        Strategy(hazard_waiting="yes")  # type: ignore[arg-type]


def test_expand_is_the_full_grid_in_factor_order() -> None:
    grid = expand({"hazard_waiting": [False, True], "suspension": ["static", "planned"],
                   "policy": ["strict", "conditional"]})
    assert len(grid) == 8 and len({s.label for s in grid}) == 8
    assert grid[0].label == "suspension=static,policy=strict,hazard_waiting=off"
    assert grid[-1].label == "suspension=planned,policy=conditional,hazard_waiting=on"


def test_spec_factors_grid_and_explicit_list(tmp_path: Path) -> None:
    spec = load_spec(_write(tmp_path, """
        scenarios = ["household"]
        seeds = 2
        strategies = ["update=static,suspension=static,scheduler=alg2"]
        [factors]
        suspension = ["static", "planned"]
        policy = ["strict", "conditional"]
        hazard_waiting = [false, true]
    """))
    labels = [s.label for s in spec.strategies]
    assert len(labels) == 9 and labels[0] == "update=static,suspension=static,scheduler=alg2"
    assert "suspension=planned,policy=conditional,hazard_waiting=on" in labels
    assert len(spec.jobs()) == 18


@pytest.mark.parametrize(("body", "message"), [
    ('[factors]\nsuspnsion = ["static"]', "factors.suspnsion: unknown factor 'suspnsion'; did you mean 'suspension'?"),
    ('[factors]\npolicy = ["strict", "lenient"]', "factors.policy[1]: expected one of ['strict', 'conditional']"),
    ('[factors]\nhazard_waiting = ["on"]', "factors.hazard_waiting[0]: expected true or false"),
    ('[factors]\nsuspension = ["static", "static"]', "factors.suspension: duplicates"),
    ('[factors]\nscheduler = ["alg3"]', "factors.scheduler[0]"),
    ('strategies = ["suspension=static"]\n[factors]\nsuspension = ["static"]', "strategies: duplicates"),
    ("", "strategies: missing"),
])
def test_bad_factors_name_the_field(tmp_path: Path, body: str, message: str) -> None:
    path = _write(tmp_path, 'scenarios = ["household"]\nseeds = 2\n' + body + "\n")
    with pytest.raises(SpecError) as err:
        load_spec(path)
    assert message in str(err.value) and "spec.toml:" in str(err.value)


# ----------------------------------------------------------------------------------------- interruption grid


def test_spec_variants_reach_the_jobs(tmp_path: Path) -> None:
    spec = load_spec(_write(tmp_path, """
        scenarios = ["household"]
        seeds = 4
        strategies = ["suspension=static"]
        [variants.household]
        interrupt = "requests[2]"
        times = { start = 5, stop = 45, step = 10 }
    """))
    assert {j.interruption for j in spec.jobs()} == {InterruptionGrid("requests[2]", 5.0, 45.0, 10.0)}
    assert spec.to_json()["variants"]["household"]["interrupt"] == "requests[2]"


@pytest.mark.parametrize(("body", "message"), [
    ('[variants.kitchen]\ninterrupt = "requests[1]"\ntimes = {start = 0, stop = 10, step = 1}',
     "variants.kitchen: not one of the spec's scenarios"),
    ('[variants.household]\ninterrupt = "request 1"\ntimes = {start = 0, stop = 10, step = 1}',
     "variants.household.interrupt: expected 'requests[N]'"),
    ('[variants.household]\ninterrupt = "requests[1]"\ntimes = {start = 10, stop = 5, step = 1}',
     "variants.household.times: expected 0 <= start < stop"),
    ('[variants.household]\ninterrupt = "requests[1]"\ntimes = {start = 0, stop = 10, stp = 1}',
     "variants.household.times.step: missing"),
])
def test_bad_variants_name_the_field(tmp_path: Path, body: str, message: str) -> None:
    path = _write(tmp_path, 'scenarios = ["household"]\nseeds = 2\nstrategies = ["suspension=static"]\n' + body + "\n")
    with pytest.raises(SpecError) as err:
        load_spec(path)
    assert message in str(err.value)


def test_stratified_grid_covers_every_stratum_reproducibly() -> None:
    scn = scenarios.load("household")
    grid = InterruptionGrid("requests[2]", 5.0, 200.0, 10.0)
    assert grid.strata == 20

    def placed(seed: int) -> float:
        v = scenarios.randomize(scn, seed, interruption=grid)
        fall = [a for a in v.actions if a.origin == ("requests", 2)][0]
        world = [a for a in v.actions if a.kind == "world"][0]
        assert world.t == fall.t  # what happened with the interruption (Peter's fall) moves with it
        return fall.t

    times = [placed(seed) for seed in range(20)]
    for seed, t in enumerate(times):
        low, high = grid.stratum(seed)
        assert low <= t < high + 1e-9
    assert sorted(int((t - 5.0) // 10.0) for t in times) == list(range(20))  # every stratum once
    assert placed(7) == times[7] and placed(27) != times[7]  # same seed, same time; same stratum, new draw
    with pytest.raises(scenarios.ScenarioError, match=r"no requests\[5\]"):
        scenarios.randomize(scn, 1, interruption=InterruptionGrid("requests[5]", 0.0, 10.0, 1.0))


# ----------------------------------------------------------------------------------------- people


@pytest.mark.parametrize("name", ["household", "carry"])
def test_every_person_moves_and_stays_in_free_space(name: str) -> None:
    scn = scenarios.load(name)
    world = load_world(scn.world)
    scene = Scene(world, PERSON_RADIUS["standing"])
    moved = 0
    for seed in range(5):
        v = scenarios.randomize(scn, seed)
        assert set(v.people) == set(world.people)  # those only in the world file too
        for person, entry in v.people.items():
            x, y, _ = entry["pose"]
            assert scene.static_free(x, y) or (x, y) == world.people[person].pose[:2]
            moved += (x, y) != world.people[person].pose[:2]
            points = [(x, y)] + [(wx, wy) for _, wx, wy in entry.get("walk", [])]
            for (ax, ay), (bx, by) in zip(points, points[1:], strict=False):
                assert scene.segments_free(np.array([(ax, ay)]), np.array([(bx, by)]), dynamic=False)[0] or \
                    not scene.static_free(bx, by)
            times = [t for t, _, _ in entry.get("walk", [])]
            assert times == sorted(times) and len(set(times)) == len(times)
        assert scenarios.randomize(scn, seed) == v  # reproducible
    assert moved >= 4 * len(world.people)  # nearly every draw moves the person
