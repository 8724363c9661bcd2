"""The day report on both backends: protocol task types in the rows, path metrics only where measured,
resumable logs."""

from __future__ import annotations

import dataclasses
import json
import re
from pathlib import Path
from typing import Any

import pytest

from experiments.cli import main as _tasker
from experiments.days import pipeline as day_pipeline_mod
from experiments.days import runner as day_runner
from experiments.days import table as day_table
from experiments.metrics import day as day_metrics_mod
from experiments.sweep.spec import Job
from tasker.errors import ConfigError
from tests.experiments.events import completed


def _day_main(argv: list[str]) -> int:
    return _tasker(["day", *argv])


EVENTS = completed([
    {"t": 0.0, "event": "request", "agent": "d1", "task_type": "folder_a", "args": {"deadline": 10.0}},
    {"t": 12.0, "event": "end", "agent": "d1", "task_type": "folder_a", "cause": "finished"},
])


def test_trace_task_types_are_reported_under_the_protocols_names() -> None:
    m = day_metrics_mod.day_metrics(EVENTS, day_end=20.0, kinds={"folder_a": "transport"})
    assert set(m["per_type"]) == {"transport"} and m["per_type"]["transport"]["lateness_s"] == 2.0


def result(name: str, seed: int, **extra: float) -> dict[str, object]:
    m = day_metrics_mod.day_metrics(EVENTS, day_end=20.0, kinds={"folder_a": "transport"})
    return {"scheduler": name, "seed": seed, **m, **extra}


def test_path_rows_appear_only_with_path_metrics() -> None:
    synthetic = day_table.table([result(n, s) for n in ("lookahead", "alg2") for s in (1, 2)])
    assert "abandonments" not in synthetic and "travel distance" not in synthetic
    robot = day_table.table([result(n, s, abandonments=s, abandoned_falls=1, travel_m=10.0 * s)
                             for n in ("lookahead", "alg2") for s in (1, 2)])
    assert "| abandonments (robot leaves a fallen person's 2 m circle) | 1.50 ± 6.35 | 1.50 ± 6.35 |" in robot
    assert "| travel distance (m) | 15.00 ± 63.53 | 15.00 ± 63.53 |" in robot


def test_failure_rows_are_the_robots_and_a_day_stored_before_renewals_made_none() -> None:
    synthetic = day_table.table([{**result(n, s), "backend": "synthetic"}
                                 for n in ("lookahead", "alg2") for s in (1, 2)])
    assert "failed tasks" not in synthetic and "requests made again" not in synthetic
    days = [{**result(n, s), "backend": "robot"} for n in ("lookahead", "alg2") for s in (1, 2)]
    days[0]["renewals"], days[0]["failed"] = 2, 1  # lookahead, day 1; the other days predate renewals
    robot = day_table.table(days)
    assert "| requests made again after a failed task (robot) | 1.00 ± 12.71 | 0.00 ± 0.00 |" in robot
    assert "| failed tasks not served by their renewals (robot) | 0.50 ± 6.35 | 0.00 ± 0.00 |" in robot


@pytest.mark.slow
def test_a_stopped_run_resumes_from_its_database(tmp_path: Path) -> None:
    from experiments.metrics.store import ResultStore

    db = tmp_path / "days.db"
    first = day_runner.run_days("tabsa-short", 1, ["fifo"], workers=1, db=db)
    with ResultStore(db) as store:
        (row,) = store.rows()
        assert row.key == ("tabsa-short@synthetic", 1, "scheduler=fifo") and row.metrics == first[0]
        # a day already stored is read back, not run again
        store.forget({row.key})
        store.add(dataclasses.replace(row, metrics={**row.metrics, "completed": -1}))
    again = day_runner.run_days("tabsa-short", 2, ["fifo"], workers=1, db=db)
    assert [r["seed"] for r in again] == [1, 2] and again[0]["completed"] == -1
    with ResultStore(db) as store:
        assert store.count() == 2


def _crash_on_seed_2(job: Job, **kw: Any) -> tuple[dict[str, Any], dict[str, Any]]:
    if job.seed == 2:
        raise RuntimeError("a broken day")
    return day_runner.day_job(job, **kw)


@pytest.mark.slow
def test_a_day_that_fails_is_listed_and_the_others_go_on(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(day_runner, "day_job", _crash_on_seed_2)  # the worker imports it from this module
    results = day_runner.run_days("tabsa-short", 3, ["fifo"], workers=1, db=tmp_path / "d.db")
    assert [(r["seed"], "error" in r) for r in results] == [(1, False), (2, True), (3, False)]
    assert "a broken day" in results[1]["error"]
    text = day_table.report(results, title="t")
    assert "2 days per scheduler" in text
    assert "- `default`, fifo, seed 2: " in text and "a broken day" in text


def _bad_input_on_seed_2(job: Job, **kw: Any) -> tuple[dict[str, Any], dict[str, Any]]:
    if job.seed == 2:
        raise ConfigError("day.toml:3: tasks.fall.count: a mistake of the user's")
    return _crash_on_seed_2(job, **kw)


@pytest.mark.slow
def test_a_day_failing_on_bad_input_lists_its_message_and_a_bug_its_traceback(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(day_runner, "day_job", _bad_input_on_seed_2)
    bad = day_runner.run_days("tabsa-short", 2, ["fifo"], workers=1, db=tmp_path / "a.db")[1]["error"]
    assert bad == "ConfigError: day.toml:3: tasks.fall.count: a mistake of the user's"
    monkeypatch.setattr(day_runner, "day_job", _crash_on_seed_2)
    bug = day_runner.run_days("tabsa-short", 2, ["fifo"], workers=1, db=tmp_path / "b.db")[1]["error"]
    assert bug.startswith("RuntimeError: a broken day\n") and "Traceback" in bug


def test_a_protocol_whose_days_cannot_be_drawn_fails_before_any_day(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """More people asked for than the world has: one line naming the protocol, no day run."""
    protocols = Path(day_pipeline_mod.__file__).parent / "protocols"
    text = (protocols / "tabsa_short.toml").read_text(encoding="utf-8").replace("count = 3", "count = 4")
    text = text.replace('world = "tabsa_apartment_short.toml"', f'world = "{protocols / "tabsa_apartment_short.toml"}"')
    proto = tmp_path / "crowded.toml"
    proto.write_text(text, encoding="utf-8")
    out = tmp_path / "out"
    assert _day_main(["--protocol", str(proto), "--backend", "robot", "--days", "2", "--schedulers", "fifo",
                           "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "--protocol" in err and "crowded.toml" in err and "needs 8 people" in err and "Traceback" not in err
    assert not (out / "days.db").exists()


@pytest.mark.slow
def test_the_command_writes_database_log_and_table(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    assert _day_main(["--protocol", "tabsa-short", "--days", "2", "--schedulers", "lookahead", "fifo",
                           "--workers", "1", "--out", str(out)]) == 0
    assert (out / "days.db").is_file() and (out / "table.md").is_file()
    lines = (out / "days.jsonl").read_text().splitlines()
    assert [(json.loads(x)["scheduler"], json.loads(x)["seed"]) for x in lines] == [
        ("lookahead", 1), ("lookahead", 2), ("fifo", 1), ("fifo", 2)]
    assert "| metric | lookahead | fifo |" in capsys.readouterr().out


@pytest.mark.slow
def test_an_older_days_log_is_kept_by_resume(tmp_path: Path) -> None:
    out = tmp_path / "out"
    old = {**day_runner.run_day("tabsa-short", 1, "fifo"), "completed": -1}
    old.pop("strategy")  # written before strategies were a field
    out.mkdir()
    (out / "days.jsonl").write_text(json.dumps(old) + "\n")
    args = ["--protocol", "tabsa-short", "--days", "2", "--schedulers", "fifo", "--workers", "1", "--resume",
            "--out", str(out)]
    assert _day_main(args) == 0
    rows = [json.loads(x) for x in (out / "days.jsonl").read_text().splitlines()]
    assert [r["seed"] for r in rows] == [1, 2] and rows[0]["completed"] == -1


@pytest.mark.parametrize(("line", "message"), [
    ("garbage", r"days\.jsonl:2: not a JSON object: Expecting value"),
    ("[1]", r"days\.jsonl:2: expected a day \(a JSON object\), got \[1\]"),
    ('{"scheduler": "fifo", "seed": "x"}', r"days\.jsonl:2: seed: expected an integer >= 0"),
    ('{"scheduler": "fifo", "seed": 3, "completed": "lots"}', r"days\.jsonl:2: completed: expected a number"),
])
def test_a_damaged_older_days_log_is_an_error_naming_its_line(tmp_path: Path, line: str, message: str,
                                                              capsys: pytest.CaptureFixture[str]) -> None:
    """--resume imports an older days.jsonl; a damaged one is refused whole, at its line (exit 2),
    where it was an internal error (JSONDecodeError, KeyError) once some days had been imported."""
    out = tmp_path / "out"
    out.mkdir()
    good = day_runner.run_day("tabsa-short", 1, "fifo")
    (out / "days.jsonl").write_text(json.dumps(good) + "\n" + line + "\n")
    args = ["--protocol", "tabsa-short", "--days", "2", "--schedulers", "fifo", "--workers", "1", "--resume",
            "--out", str(out)]
    assert _day_main(args) == 2
    err = capsys.readouterr().err
    assert re.search(message, err) and "internal error" not in err, err
    assert not (out / "days.db").exists()  # nothing imported: the fixed log is read in whole next time


def test_strategies_are_compared_under_each_scheduler() -> None:
    a = [{**result(n, s, travel_m=10.0 * s), "strategy": "suspension=static"} for n in ("lookahead", "alg2")
         for s in (1, 2, 3)]
    b = [{**result(n, s, travel_m=10.0 * s + 1.0), "strategy": "suspension=planned"} for n in ("lookahead", "alg2")
         for s in (1, 2, 3)]
    text = day_table.report(a + b, title="t")
    assert "## t, strategy `suspension=static`" in text and "## t, strategy `suspension=planned`" in text
    assert "| travel distance (m) | `suspension=planned`, lookahead | 3 | 1.00 ± 0.00 | 0 / 0 / 3 |" in text
    assert "| travel distance (m) | `suspension=planned`, alg2 | 3 | 1.00 ± 0.00 | 0 / 0 / 3 |" in text
    assert "| time suspending (s, ours) | `suspension=planned`, alg2 |" in text  # what strategies differ in


def test_strategies_on_the_synthetic_backend_are_refused(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    assert _day_main(["--days", "1", "--strategies", "suspension=static", "--out", str(tmp_path)]) == 2
    assert "--strategies" in capsys.readouterr().err
    assert _day_main(["--days", "1", "--strategies", "suspension=maybe", "--out", str(tmp_path)]) == 2
    assert "suspension" in capsys.readouterr().err


@pytest.mark.slow
def test_days_run_on_a_dask_cluster(tmp_path: Path) -> None:
    from distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        on_dask = day_runner.run_days("tabsa-short", 2, ["fifo", "lookahead"], db=tmp_path / "d.db",
                                     address=cluster.scheduler_address)
    local = day_runner.run_days("tabsa-short", 2, ["fifo", "lookahead"], workers=1)
    assert on_dask == local and len(local) == 4


def test_an_unreachable_dask_scheduler_is_bad_input(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert _day_main(["--days", "1", "--scheduler-address", "tcp://127.0.0.1:1", "--out", str(tmp_path)]) == 2
    assert "--scheduler-address" in capsys.readouterr().err


@pytest.mark.parametrize(("args", "fragment"), [(["--first-seed", "-1"], "--first-seed"),
                                                (["--first-seed", "4294967295", "--days", "2"], "--days")])
def test_day_seeds_outside_the_seed_range_are_refused(args: list[str], fragment: str, tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    from experiments.cli import main

    assert main(["day", *args, "--schedulers", "fifo", "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert fragment in err and "2**32" in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()


def test_a_scheduler_given_twice_or_an_out_that_is_a_file_names_the_argument(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Both were refused only by what they broke: 'two jobs have the same key (scenario, seed,
    strategy)' and '...: File exists', neither naming the argument at fault."""
    base = ["--protocol", "tabsa-short", "--days", "1", "--workers", "1"]
    assert _day_main([*base, "--schedulers", "fifo", "alg2", "fifo", "--out", str(tmp_path / "o")]) == 2
    assert "argument --schedulers: 'fifo' is given twice" in capsys.readouterr().err
    (tmp_path / "file").write_text("")
    assert _day_main([*base, "--schedulers", "fifo", "--out", str(tmp_path / "file")]) == 2
    assert f"argument --out: {tmp_path / 'file'} exists and is not a folder" in capsys.readouterr().err


def test_more_days_than_a_sweep_may_have_are_refused_before_any_job(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """--days 3000000 built millions of jobs (gigabytes) before the first day; a sweep refuses
    more than MAX_JOBS, and so does a day run."""
    from experiments.sweep.spec import MAX_JOBS

    days = MAX_JOBS // 2 + 1
    assert _day_main(["--protocol", "tabsa-short", "--days", str(days), "--schedulers", "fifo", "alg2",
                           "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert f"argument --days: {days} days x 2 schedulers x 1 strategies" in err and str(MAX_JOBS) in err
    assert "Traceback" not in err and not (tmp_path / "out").exists()


@pytest.mark.parametrize("name", ["table.md", "days.jsonl", "days.db"])
def test_an_output_that_cannot_be_written_is_refused_before_any_day(
        name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A folder where table.md goes was found only after every day had run: the table was lost."""
    out = tmp_path / "out"
    (out / name).mkdir(parents=True)
    for resume in ([], ["--resume"]):
        assert _day_main(["--protocol", "tabsa-short", "--days", "1", "--schedulers", "fifo", "--workers", "1",
                               "--out", str(out), *resume]) == 2
        err = capsys.readouterr().err
        assert f"argument --out: {out / name} is a folder; expected a file name" in err and "Traceback" not in err
        assert sorted(p.name for p in out.iterdir()) == [name]  # no day ran, nothing written


@pytest.mark.slow
def test_resuming_with_a_changed_protocol_is_refused_and_keeps_the_stored_days(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """--resume kept the days of the protocol as it was and ran the others from the edited file:
    one table mixed days of 3 and of 15 requests.  A comment changes nothing and resumes."""
    from experiments.metrics.store import ResultStore

    shipped = Path(day_pipeline_mod.__file__).parent / "protocols" / "tabsa_short.toml"
    text = shipped.read_text(encoding="utf-8").split("\n[robot_backend]")[0]
    proto, out = tmp_path / "mine.toml", tmp_path / "out"
    proto.write_text(text, encoding="utf-8")
    args = ["--protocol", str(proto), "--schedulers", "fifo", "--workers", "1", "--out", str(out), "--resume"]
    assert _day_main([*args, "--days", "1"]) == 0
    proto.write_text("# my edit\n" + text, encoding="utf-8")
    assert _day_main([*args, "--days", "2"]) == 0  # the same values: day 1 is kept, day 2 added
    proto.write_text(text.replace("count = 3", "count = 5", 1), encoding="utf-8")
    capsys.readouterr()
    assert _day_main([*args, "--days", "3"]) == 2
    err = capsys.readouterr().err
    assert f"argument --out: {out / 'days.db'} holds days of {proto} as it was when they ran" in err
    assert "give --overwrite to delete them and start afresh" in err and "Traceback" not in err
    with ResultStore(out / "days.db", readonly=True) as store:
        assert sorted(r.seed for r in store.rows()) == [1, 2]
    assert _day_main([a for a in args if a != "--resume"] + ["--days", "1", "--overwrite"]) == 0  # afresh


def test_a_folder_given_as_the_protocol_is_named_a_folder(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """--protocol my_protocols (a folder) was 'no protocol ...; or give a .toml file', as if it did not exist."""
    (tmp_path / "my_protocols").mkdir()
    assert _day_main(["--protocol", str(tmp_path / "my_protocols"), "--days", "1", "--schedulers", "fifo",
                           "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert f"{tmp_path / 'my_protocols'}: is a directory, expected a file" in err and "Traceback" not in err


@pytest.mark.slow
def test_a_second_run_into_the_same_out_leaves_the_running_ones_days(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Without --resume, a second 'tasker day' into the OUT of a running one deleted its days.db
    before finding the sweep lease taken: the running one then wrote into a deleted file and ended
    'no such results database', every day it had run lost."""
    from experiments.metrics.store import ResultStore
    from experiments.sweep.driver import lease

    out = tmp_path / "out"
    assert _day_main(["--protocol", "tabsa-short", "--days", "1", "--schedulers", "fifo", "--workers", "1",
                           "--out", str(out)]) == 0
    capsys.readouterr()
    with lease(out / "days.db"):  # the running one holds it
        assert _day_main(["--protocol", "tabsa-short", "--days", "1", "--schedulers", "alg2", "--workers", "1",
                               "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "another sweep is running on this database" in err and "Traceback" not in err
    with ResultStore(out / "days.db", readonly=True) as store:
        assert [r.strategy for r in store.rows()] == ["scheduler=fifo"]
    assert (out / "days.jsonl").is_file()
