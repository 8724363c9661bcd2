"""The facade: ``import experiments`` exports the calls a notebook needs, and the README's example runs.

The fast tests run the example's calls in process on the synthetic scenario; the sweep and the day
run worker processes, so their test is slow."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

import experiments
from experiments.analysis.compare import Analysis
from experiments.metrics.store import ResultStore, RunRow, Status
from experiments.run.records import RunRecord
from tasker.errors import InputError

ROOT = Path(__file__).resolve().parents[2]
DEMO = "experiments/inputs/scenarios/synthetic_demo.toml"


def test_import_experiments_is_cheap_and_exports_the_calls() -> None:
    code = ("import sys, experiments; "
            "print('experiments.facade' in sys.modules, 'experiments.run.runner' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True).stdout
    assert out.split() == ["False", "False"]
    assert set(experiments.__all__) == {"run_scenario", "load_run", "run_sweep", "sweep_report", "compare", "day",
                                        "LoadedRun", "DayReport"}
    assert all(callable(getattr(experiments, n)) for n in experiments.__all__)
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        _ = experiments.nothing  # type: ignore[attr-defined]


def test_run_then_load_run_gives_back_what_was_written(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)
    result = experiments.run_scenario(DEMO, out=tmp_path / "demo", pictures=False, seed=2, scheduler="edf")
    run = experiments.load_run(tmp_path / "demo")
    assert run.record == result.record and run.record.seed == 2 and run.record.settings.scheduler == "edf"
    assert run.metrics == json.loads((tmp_path / "demo" / "metrics.json").read_text())
    assert sorted(run.timeline.agents) == ["d1", "d2", "d3", "d4"]
    assert run.metrics["run"]["duration_s"] == result.metrics["run"]["duration_s"] > 0


def test_load_run_names_what_is_missing(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="no such run folder"):
        experiments.load_run(tmp_path / "nowhere")
    (tmp_path / "r").mkdir()
    with pytest.raises(InputError, match=r"r/run.json: the run folder has no run.json"):
        experiments.load_run(tmp_path / "r")
    experiments.run_scenario(ROOT / DEMO, out=tmp_path / "r", pictures=False)
    (tmp_path / "r" / "run.json").write_text('{"seed": 1}')
    with pytest.raises(InputError, match="run.json: scenario: the run record has no 'scenario'"):
        experiments.load_run(tmp_path / "r")


def test_compare_reads_a_results_database(tmp_path: Path) -> None:
    db = tmp_path / "r.db"
    with ResultStore(db) as store:
        for scheduler in ("fifo", "edf"):
            for seed in (1, 2, 3):
                res = experiments.run_scenario(ROOT / DEMO, seed=seed, scheduler=scheduler)
                store.add(RunRow("demo", seed, f"scheduler={scheduler}", Status.OK, res.record.to_json(),
                                 res.metrics))
    analysis = experiments.compare(db)
    assert isinstance(analysis, Analysis)
    assert {s.strategy for s in analysis.summaries} == {"scheduler=fifo", "scheduler=edf"}
    with pytest.raises(InputError, match="no such results database"):
        experiments.compare(tmp_path / "none.db")


@pytest.mark.slow
def test_the_readme_example_runs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The README's Python block as written (its sweep spec made here, one seed of the synthetic demo)."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    section = text.split("## From Python", 1)[1]
    code = re.search(r"```python\n(.*?)```", section, re.S)
    assert code is not None
    (tmp_path / "my_sweep.toml").write_text(f'name = "my"\nscenarios = ["{ROOT / DEMO}"]\nseeds = 1\n'
                                           'strategies = ["scheduler=fifo", "scheduler=edf"]\n')
    (tmp_path / "experiments" / "inputs" / "scenarios").mkdir(parents=True)
    (tmp_path / DEMO).write_bytes((ROOT / DEMO).read_bytes())
    monkeypatch.chdir(tmp_path)
    scope: dict[str, object] = {}
    exec(compile(code.group(1), "README.md", "exec"), scope)  # noqa: S102 - the README's own example
    assert isinstance(scope["run"], experiments.LoadedRun) and isinstance(scope["run"].record, RunRecord)
    assert scope["summary"].ok == 2 and isinstance(scope["analysis"], Analysis)  # type: ignore[attr-defined]
    assert scope["days"].failed == 0 and (tmp_path / "out" / "days" / "table.md").is_file()  # type: ignore[attr-defined]
