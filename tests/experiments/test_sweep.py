"""Sweeps: spec files, the results database, parallel runs (local and Dask), kill and resume."""

from __future__ import annotations

import csv
import dataclasses
import math
import os
import signal
import sqlite3
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from experiments.inputs.strategy import Strategy
from experiments.metrics.store import ResultStore, RunRow, Status, StoreError
from experiments.sweep.driver import SweepError, run_sweep
from experiments.sweep.report import build_report
from experiments.sweep.spec import Job, SpecError, SweepSpec, load_spec
from tests.experiments import standin

ROOT = Path(__file__).parents[2]
STRATEGIES = (Strategy("static", "static"), Strategy("static", "planned"))


@pytest.fixture
def small_spec() -> SweepSpec:
    """Two scenarios × two seeds × two strategies (the scenarios are the demo under two names)."""
    demo = str(standin.DEMO)
    return SweepSpec(("demo-a", "demo-b"), (1, 2), STRATEGIES, name="small", sources={"demo-a": demo, "demo-b": demo})


def _all_keys(spec: SweepSpec) -> set[tuple[str, int, str]]:
    return {j.key for j in spec.jobs()}


# ----------------------------------------------------------------------------------------- specs


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "spec.toml"
    path.write_text(textwrap.dedent(text), encoding="utf-8")
    return path


def test_spec_file_expands_to_jobs(tmp_path: Path) -> None:
    (tmp_path / "s.toml").write_text(standin.DEMO.read_text())
    spec = load_spec(_write(tmp_path, """
        name = "demo"
        scenarios = ["s.toml", "paper"]
        seeds = 3
        seed_start = 10
        strategies = [
            "update=static,suspension=planned",
            {update = "planned", suspension = "planned", scheduler = "alg2"},
        ]
    """))
    assert spec.name == "demo"
    assert spec.seeds == (10, 11, 12)
    assert spec.sources["s.toml"] == str(tmp_path / "s.toml")  # relative to the spec file
    assert "paper" not in spec.sources  # a shipped scenario's name is passed on as it is
    jobs = spec.jobs()
    assert len(jobs) == 2 * 3 * 2
    assert jobs[0].key == ("s.toml", 10, "update=static,suspension=planned")
    assert jobs[-1].key == ("paper", 12, "update=planned,suspension=planned,scheduler=alg2")
    listed = load_spec(_write(tmp_path, 'scenarios = ["paper"]\nseeds = [5, 3]\nstrategies = ["default"]'))
    assert listed.seeds == (5, 3)


@pytest.mark.parametrize(("body", "field"), [
    ('seeds = 2\nstrategies = ["default"]', "scenarios: missing"),
    ('scenarios = ["nope.toml"]\nseeds = 2\nstrategies = ["default"]', "scenarios[0]: no such file"),
    ('scenarios = ["paper"]\nseeds = 0\nstrategies = ["default"]', "seeds: expected a positive count"),
    ('scenarios = ["paper"]\nseeds = [1, "2"]\nstrategies = ["default"]', "seeds[1]"),
    ('scenarios = ["paper"]\nseeds = [1, 1]\nstrategies = ["default"]', "seeds: duplicates"),
    ('scenarios = ["paper"]\nseeds = 2\nstrategies = ["update=sometimes"]', "strategies[0]"),
    ('scenarios = ["paper"]\nseeds = 2\nstrategies = [{update = "static", speed = 2}]',
     "strategies[0].speed: unknown key"),
    ('scenarios = ["paper"]\nseeds = 2\nstrategies = ["update=static", "update=static"]', "strategies: duplicates"),
    ('scenarios = ["paper"]\nseeds = 2\nstrategies = []', "strategies: expected a non-empty array"),
    ('scenarios = ["paper"]\nseeds = 2\nstrategies = ["default"]\nworkers = 3', "workers: unknown key"),
    ('scenarios = ["paper"\n', "not valid TOML"),
])
def test_bad_spec_names_the_field(tmp_path: Path, body: str, field: str) -> None:
    path = _write(tmp_path, body)
    with pytest.raises(SpecError) as info:
        load_spec(path)
    assert str(path) in str(info.value) and field in str(info.value)


def test_strategy_label_round_trips_and_checks_its_values() -> None:
    s = Strategy("planned", "static", "alg2")
    assert s.label == "update=planned,suspension=static,scheduler=alg2"
    assert Strategy.parse(s.label) == s
    assert Strategy().label == "default" and Strategy.parse("default") == Strategy()
    with pytest.raises(ValueError, match="update"):
        Strategy(update="sometimes")
    with pytest.raises(ValueError, match="scheduler"):
        Strategy(scheduler="")
    with pytest.raises(ValueError, match="given twice"):
        Strategy.parse("update=static,update=planned")


def test_sweep_spec_checks_its_fields() -> None:
    with pytest.raises(ValueError, match="scenarios"):
        SweepSpec((), (1,), STRATEGIES)
    with pytest.raises(ValueError, match="seeds"):
        SweepSpec(("a",), (1, 1), STRATEGIES)
    with pytest.raises(ValueError, match="strategies"):
        SweepSpec(("a",), (1,), ())


# ----------------------------------------------------------------------------------------- the database


def test_store_keeps_the_first_result_of_a_key(tmp_path: Path) -> None:
    with ResultStore(tmp_path / "r.db") as store:
        row = RunRow("a", 1, "default", Status.OK, {"seed": 1}, {"x": 1.0})
        assert store.add(row)
        assert not store.add(RunRow("a", 1, "default", Status.OK, {"seed": 1}, {"x": 2.0}))
        (stored,) = store.rows()
        assert stored == dataclasses.replace(row, finished=stored.finished) and stored.record == {"seed": 1}
        assert store.keys() == {("a", 1, "default")}
        assert store._db.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
        assert store.add(RunRow("b", 1, "default", Status.OK, {}, {"x": math.nan, "y": [math.inf], "z": {1, 2}}))
        assert store.rows()[-1].metrics == {"x": "nan", "y": ["inf"], "z": "{1, 2}"}  # stored, never invalid JSON
    with pytest.raises(ValueError, match="error"):
        RunRow("a", 1, "default", Status.ERROR, {}, {})  # an error needs its message
    with pytest.raises(ValueError, match="status"):
        RunRow("a", 1, "default", "ok", {}, {})  # type: ignore[arg-type]
    (tmp_path / "junk.db").write_bytes(b"this is not sqlite" * 100)
    with pytest.raises(StoreError, match="junk.db"):
        ResultStore(tmp_path / "junk.db")


# ----------------------------------------------------------------------------------------- running


@pytest.mark.slow
def test_failing_runs_are_stored_as_errors_and_retried_only_when_asked(tmp_path: Path, small_spec: SweepSpec) -> None:
    db = tmp_path / "r.db"
    first = run_sweep(small_spec, db, workers=2, run_fn=standin.flaky_run, progress=False)
    assert (first.ran, first.ok, first.errors) == (8, 4, 4)  # seed 1 fails; the sweep goes on
    with ResultStore(db) as store:
        errors = store.rows(Status.ERROR)
        assert {r.seed for r in errors} == {1}
        assert all("ValueError: seed 1 is cursed" in (r.error or "") for r in errors)
    again = run_sweep(small_spec, db, workers=2, run_fn=standin.run, progress=False)
    assert (again.skipped, again.ran) == (8, 0)
    retried = run_sweep(small_spec, db, workers=2, run_fn=standin.run, retry_errors=True, progress=False)
    assert (retried.skipped, retried.ran, retried.ok) == (4, 4, 4)
    with ResultStore(db) as store:
        assert store.keys(Status.OK) == _all_keys(small_spec)


@pytest.mark.slow
def test_a_job_that_kills_its_worker_is_stored_as_an_error_and_the_sweep_goes_on(tmp_path: Path) -> None:
    db = tmp_path / "r.db"
    spec = SweepSpec(("demo",), (1, 2, 3, 4, 5, 6), (Strategy("static", "static"),),
                     sources={"demo": str(standin.DEMO)})
    crasher = ("demo", standin.CRASH_SEED, "update=static,suspension=static")
    first = run_sweep(spec, db, workers=2, run_fn=standin.crashing_run, progress=False)
    assert (first.ran, first.ok, first.errors, first.not_run) == (6, 5, 1, 0)
    with ResultStore(db) as store:
        rows = store.rows()
        assert len(rows) == store.count() == 6 and {r.key for r in rows} == _all_keys(spec)
        (error,) = store.rows(Status.ERROR)
        assert error.key == crasher
        assert error.error and error.error.startswith("worker process died (exit code 3) while running this job")
        assert store.keys(Status.OK) == _all_keys(spec) - {crasher}  # those in flight alongside it ran normally
        before = {r.key: r for r in rows}
    again = run_sweep(spec, db, workers=2, run_fn=standin.crashing_run, progress=False)
    assert (again.skipped, again.ran) == (6, 0)  # the crasher does not stop a resumption: nothing is left to run
    retried = run_sweep(spec, db, workers=2, run_fn=standin.crashing_run, retry_errors=True, progress=False)
    assert (retried.skipped, retried.ran, retried.errors) == (5, 1, 1)
    with ResultStore(db) as store:
        rows = store.rows()
        assert len(rows) == 6 and all(before[r.key] == r for r in rows if r.key != crasher)
        assert [r.key for r in rows if r.status is Status.ERROR] == [crasher]


@pytest.mark.slow
def test_a_job_that_kills_its_dask_worker_is_stored_as_an_error(tmp_path: Path) -> None:
    import dask
    from distributed import LocalCluster

    db = tmp_path / "r.db"
    spec = SweepSpec(("demo",), (3, 4, 5), (Strategy("static", "static"),), sources={"demo": str(standin.DEMO)})
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}), \
            LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        summary = run_sweep(spec, db, scheduler_address=cluster.scheduler_address, run_fn=standin.crashing_run,
                            progress=False)
    assert (summary.ran, summary.ok, summary.errors) == (3, 2, 1)
    with ResultStore(db) as store:
        (error,) = store.rows(Status.ERROR)
    assert error.seed == standin.CRASH_SEED
    assert error.error and error.error.startswith("worker process died") and "KilledWorker" in error.error


@pytest.mark.slow
def test_sweep_on_dask_stopped_half_way_and_resumed(tmp_path: Path, small_spec: SweepSpec) -> None:
    from distributed import LocalCluster

    db = tmp_path / "r.db"
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        half = run_sweep(small_spec, db, scheduler_address=cluster.scheduler_address, run_fn=standin.run,
                         max_jobs=4, progress=False)
        assert (half.ran, half.ok, half.not_run, half.backend) == (4, 4, 4, "dask")
        with ResultStore(db) as store:
            before = {r.key: r for r in store.rows()}
        rest = run_sweep(small_spec, db, scheduler_address=cluster.scheduler_address, run_fn=standin.run,
                         progress=False)
        assert (rest.skipped, rest.ran, rest.not_run) == (4, 4, 0)
    with ResultStore(db) as store:
        rows = store.rows()
        assert len(rows) == store.count() == 8
        assert {r.key for r in rows} == _all_keys(small_spec)
        assert all(r.status is Status.OK for r in rows)
        assert all(before[r.key] == r for r in rows if r.key in before)  # the first half was not run again
        assert len(store.sweeps()) == 2 and store.sweeps()[0]["setup"]["backend"] == "dask"
        record = rows[0].record
        assert {"scenario", "seed", "settings", "host", "date", "version"} <= set(record)

    files = build_report(db, tmp_path / "report")
    md = files.markdown.read_text()
    for strategy in STRATEGIES:
        # per scenario (a, b), never pooled: a row in the primary-outcome table and one in the metric table
        assert sum(line.startswith(f"| {strategy.label} |") for line in md.splitlines()) == 4
    assert "suspension: `update=static,suspension=planned` vs `update=static,suspension=static`" in md
    with files.summary_csv.open() as f:
        summary = list(csv.DictReader(f))
    assert {r["strategy"] for r in summary} == {s.label for s in STRATEGIES}
    assert all(int(r["n"]) == 4 for r in summary if r["scenario"] == "*")
    with files.paired_csv.open() as f:
        paired = list(csv.DictReader(f))
    # a metric with a verdict counts every pair; one without (better "–") has no wins or losses
    assert paired and all(int(r["wins"]) + int(r["ties"]) + int(r["losses"]) == (int(r["n"]) if r["better"] != "–"
                                                                                else 0) for r in paired)
    assert files.plots and all(p.stat().st_size > 0 for p in files.plots)
    # every comparison has its wins/ties/losses chart, in the PNGs and on the page (pairs are per scenario)
    comparisons = {(r["dimension"], r["treatment"], r["baseline"]) for r in paired}
    assert len([p for p in files.plots if p.name.startswith("paired_")]) == len(comparisons)
    assert files.html is not None
    page = files.html.read_text(encoding="utf-8")
    assert all(f'id="paired-{n}"' in page for n in range(len(comparisons)))


_KILLED_SWEEP = """
import sys
from experiments.inputs.strategy import Strategy
from experiments.sweep.driver import run_sweep
from experiments.sweep.spec import SweepSpec
from tests.experiments import standin

if __name__ == "__main__":
    demo = str(standin.DEMO)
    spec = SweepSpec(("demo-a", "demo-b"), (1, 2), (Strategy("static", "static"), Strategy("static", "planned")),
                     sources={"demo-a": demo, "demo-b": demo})
    run_sweep(spec, sys.argv[1], workers=2, run_fn=standin.slow_run, progress=False)
"""


def _stored(db: Path) -> int:
    try:
        with sqlite3.connect(f"file:{db}?mode=ro", uri=True) as con:
            return int(con.execute("SELECT COUNT(*) FROM runs").fetchone()[0])
    except sqlite3.OperationalError:  # not created yet
        return 0


@pytest.mark.slow
def test_sweep_killed_mid_way_loses_nothing_and_resumes(tmp_path: Path, small_spec: SweepSpec) -> None:
    db, script = tmp_path / "r.db", tmp_path / "killed.py"
    script.write_text(_KILLED_SWEEP)
    env = {**os.environ, "PYTHONPATH": str(ROOT), "STANDIN_SLEEP": "0.6"}
    proc = subprocess.Popen([sys.executable, str(script), str(db)], cwd=ROOT, env=env, start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 30
        while _stored(db) < 3 and time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.05)
        assert proc.poll() is None, proc.stderr.read().decode() if proc.stderr else ""
    finally:
        os.killpg(proc.pid, signal.SIGKILL)  # the driver, the forkserver and the workers, mid-run
        proc.wait()
    with ResultStore(db) as store:
        before = {r.key: r for r in store.rows()}
    assert 3 <= len(before) < 8
    assert all(r.status is Status.OK for r in before.values())

    summary = run_sweep(small_spec, db, workers=2, run_fn=standin.run, progress=False)
    assert (summary.skipped, summary.ran, summary.errors) == (len(before), 8 - len(before), 0)
    with ResultStore(db) as store:
        rows = store.rows()
    assert len(rows) == 8 and {r.key for r in rows} == _all_keys(small_spec)
    assert all(before[r.key] == r for r in rows if r.key in before)


@pytest.mark.slow
def test_default_run_fn_runs_the_scenario_randomised(tmp_path: Path) -> None:
    spec = SweepSpec((str(standin.DEMO),), (1, 2), STRATEGIES)
    summary = run_sweep(spec, tmp_path / "r.db", workers=2, progress=False)
    assert (summary.ok, summary.errors) == (4, 0)
    with ResultStore(tmp_path / "r.db") as store:
        rows = store.rows()
    for row in rows:
        assert row.record["seed"] == row.seed
        assert row.record["settings"]["randomized"] is True
        # synthetic task types have only static strategies, and the record says what was used
        assert row.record["settings"]["suspension"] == "static"
        assert Strategy.parse(row.strategy).suspension in ("static", "planned")
        assert {"host", "date", "tasker_version"} <= set(row.record)
        assert row.metrics["totals"]["requested"] > 0


def test_bad_arguments_are_errors(tmp_path: Path, small_spec: SweepSpec) -> None:
    with pytest.raises(SweepError, match="workers"):
        run_sweep(small_spec, tmp_path / "r.db", workers=0, run_fn=standin.run)
    job = Job("a", "a", 1, Strategy())
    with pytest.raises(SweepError, match="same key"):
        run_sweep([job, job], tmp_path / "r.db", run_fn=standin.run)


@pytest.mark.slow
def test_sweep_and_report_commands(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    import argparse

    from experiments.cli import sweep as sweep_cli

    parser = argparse.ArgumentParser()
    sweep_cli.register(parser.add_subparsers(dest="command", required=True))
    spec = tmp_path / "spec.toml"
    spec.write_text(f'scenarios = ["{standin.DEMO}"]\nseeds = 2\n'
                    'strategies = ["update=static,suspension=static", "update=static,suspension=planned"]\n')
    db = tmp_path / "r.db"
    args = parser.parse_args(["sweep", str(spec), "--db", str(db), "--workers", "2", "--no-progress"])
    assert args.func(args) == 0
    assert "4 jobs; 0 already stored, 4 run (4 ok, 0 errors)" in capsys.readouterr().out
    args = parser.parse_args(["report", "--db", str(db), "--out", str(tmp_path / "out"), "--no-plots"])
    assert args.func(args) == 0
    assert (tmp_path / "out" / "report.md").is_file() and not (tmp_path / "out" / "plots").exists()
