"""A sweep checks, before its first job, everything a job would fail on; a scenario is counted once.

Before: a spec whose values passed the spec's checks could fail every one of its jobs (each
stored as an error after it started); the same scenario listed under two spellings ran, and was
counted, twice.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from experiments.cli import main as cli_main
from experiments.inputs import scenario as scenarios
from experiments.inputs.scenario import SCENARIOS, InterruptionGrid
from experiments.inputs.strategy import Strategy
from experiments.sweep.driver import SweepError, run_sweep
from experiments.sweep.spec import Job, SpecError, load_spec
from tests.experiments import standin


def _spec(tmp_path: Path, text: str) -> Path:
    p = tmp_path / "spec.toml"
    p.write_text(text)
    return p


@pytest.mark.parametrize("second", [
    "{shipped}/paper.toml", "{shipped}/../scenarios/paper.toml",
])
def test_a_shipped_scenario_and_its_file_are_one_scenario(tmp_path: Path, second: str) -> None:
    p = _spec(tmp_path, f'scenarios = ["paper", "{second.format(shipped=SCENARIOS)}"]\nseeds = 1\n'
                        'strategies = ["default"]\n')
    with pytest.raises(SpecError, match=r"spec.toml:1: scenarios\[1\]: .* is the scenario 'paper' again"):
        load_spec(p)


def test_one_file_under_two_spellings_is_one_scenario(tmp_path: Path) -> None:
    shutil.copy(standin.DEMO, tmp_path / "demo.toml")
    (tmp_path / "sub").mkdir()
    for other in ("./demo.toml", "sub/../demo.toml", str(tmp_path / "demo.toml")):
        p = _spec(tmp_path, f'scenarios = ["demo.toml", "{other}"]\nseeds = 1\nstrategies = ["default"]\n')
        with pytest.raises(SpecError, match="is the scenario 'demo.toml' again"):
            load_spec(p)
    (tmp_path / "copy.toml").write_text((tmp_path / "demo.toml").read_text())  # another file: another scenario
    p = _spec(tmp_path, 'scenarios = ["demo.toml", "copy.toml"]\nseeds = 1\nstrategies = ["default"]\n')
    assert len(load_spec(p).jobs()) == 2


VARIANTS = """scenarios = ["paper"]
seeds = 3
strategies = ["default"]

[variants.paper]
interrupt = "requests[2]"
times = {times}
"""


@pytest.mark.parametrize(("times", "fragment"), [
    ("{ start = 0.0, stop = 1e300, step = 1e-300 }", "times.step: inf strata"),
    ("{ start = 0.0, stop = 1e12, step = 1.0 }", "more than the 100000 a sweep may have jobs"),
    ("{ start = 900.0, stop = 1000.0, step = 50.0 }", "is not before 'paper''s horizon (900 s)"),
])
def test_a_variant_grid_that_no_job_could_run_is_refused(tmp_path: Path, times: str, fragment: str,
                                                          capsys: pytest.CaptureFixture[str]) -> None:
    """The first: every job raised OverflowError (ceil of infinite strata); the last: the interruption
    came after every run ended, and the sweep compared runs without one."""
    p = _spec(tmp_path, VARIANTS.format(times=times))
    with pytest.raises(SpecError) as info:
        load_spec(p)
    assert fragment in str(info.value) and info.value.line == 7
    assert cli_main(["sweep", str(p), "--db", str(tmp_path / "r.db")]) == 2
    assert "internal error" not in capsys.readouterr().err
    assert not (tmp_path / "r.db").exists()


def test_a_job_that_cannot_be_built_stops_the_sweep_before_any_job(tmp_path: Path) -> None:
    """Jobs made in code skip the spec's checks: the precheck builds each (scenario, strategy)."""
    grid = InterruptionGrid("requests[2]", 0.0, 1e300, 1e-300)
    jobs = [Job("paper", "paper", seed, Strategy(), interruption=grid) for seed in (1, 2)]
    with pytest.raises(SweepError, match=r"scenario 'paper' with strategy 'default' \(seed 1\) cannot run, so no "
                                         r"job of it would: OverflowError"):
        run_sweep(jobs, tmp_path / "r.db", workers=1, progress=False)
    assert not (tmp_path / "r.db").exists()


def test_the_precheck_builds_every_strategy_of_a_scenario(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    built: list[tuple[str | None, str | None]] = []
    from experiments.run import runner
    from experiments.run.options import RunOptions

    real = runner.build_robot

    def spy(scn: scenarios.RobotScenario, options: RunOptions, **kw: object) -> object:
        built.append((options.suspension, options.scheduler))
        return real(scn, options, **kw)  # type: ignore[arg-type]

    monkeypatch.setattr(runner, "build_robot", spy)
    from experiments.sweep.driver import precheck

    strategies = [Strategy(suspension="static"), Strategy(suspension="planned", scheduler="fifo")]
    precheck([Job("paper", "paper", seed, st) for seed in (1, 2, 3) for st in strategies])
    assert sorted(built, key=str) == [("planned", "fifo"), ("static", None)]
