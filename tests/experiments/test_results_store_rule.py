"""One rule for results stores (``tasker sweep --db``, ``tasker day``'s ``OUT/days.db``): run again, a
command goes on with what the store holds; nothing stored is deleted unless asked by name
(``--retry-errors``: the errors; ``--overwrite``: all); a store that cannot be gone on with is refused
before any job, naming the flag; a failed first write leaves nothing that blocks the next run; the
lease file goes when the run ends.

Before: ``tasker day`` into an OUT holding days replaced them silently unless ``--resume`` was given;
``--retry-errors`` without ``--resume`` emptied ``days.db``; a day run failing on a full disk left an
empty ``days.db`` that ``--resume`` refused; ``days.db.lock`` stayed after a clean run.
"""

from __future__ import annotations

import sqlite3
from pathlib import Path
from typing import Any

import pytest

from experiments.cli import main as cli_main
from experiments.inputs.strategy import Strategy
from experiments.metrics import store as store_mod
from experiments.metrics.store import ResultStore, RunRow, Status, StoreError
from experiments.sweep.driver import SweepError, lease, run_sweep
from experiments.sweep.spec import SweepSpec
from tests.experiments import standin

DAY = ["day", "--protocol", "tabsa-short", "--schedulers", "fifo", "--workers", "1"]


def _stored(db: Path) -> list[tuple[str, int, str]]:
    with ResultStore(db, readonly=True) as store:
        return sorted((r.strategy, r.seed, r.status.value) for r in store.rows())


@pytest.mark.slow
def test_a_day_run_again_goes_on_and_keeps_what_is_stored(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    assert cli_main([*DAY, "--days", "1", "--out", str(out)]) == 0
    assert _stored(out / "days.db") == [("scheduler=fifo", 1, "ok")]
    assert cli_main([*DAY, "--days", "1", "--first-seed", "2", "--out", str(out)]) == 0  # no --resume
    assert _stored(out / "days.db") == [("scheduler=fifo", 1, "ok"), ("scheduler=fifo", 2, "ok")]
    assert cli_main([*DAY, "--days", "2", "--out", str(out), "--resume"]) == 0  # the old flag: the same
    assert len(_stored(out / "days.db")) == 2
    assert not (out / "days.db.lock").exists()  # the lease goes with the run


@pytest.mark.slow
def test_retry_errors_keeps_the_days_stored_as_ok(tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert cli_main([*DAY, "--days", "1", "--out", str(out)]) == 0
    with ResultStore(out / "days.db") as store:
        store.add(RunRow("tabsa-short@synthetic", 2, "scheduler=fifo", Status.ERROR, {}, {}, "boom"))
    with sqlite3.connect(out / "days.db") as con:  # mark the stored day: kept, not run again
        con.execute("UPDATE runs SET worker = 'kept' WHERE seed = 1")
    assert cli_main([*DAY, "--days", "2", "--out", str(out), "--retry-errors"]) == 0
    assert _stored(out / "days.db") == [("scheduler=fifo", 1, "ok"), ("scheduler=fifo", 2, "ok")]
    with ResultStore(out / "days.db", readonly=True) as store:
        assert [r.worker for r in store.rows() if r.seed == 1] == ["kept"]


@pytest.mark.slow
def test_overwrite_is_the_one_way_to_start_afresh(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    assert cli_main([*DAY, "--days", "1", "--first-seed", "5", "--out", str(out)]) == 0
    assert cli_main([*DAY, "--days", "1", "--out", str(out), "--overwrite"]) == 0
    assert _stored(out / "days.db") == [("scheduler=fifo", 1, "ok")]
    capsys.readouterr()
    assert cli_main([*DAY, "--days", "1", "--out", str(out), "--overwrite", "--resume"]) == 2
    assert "--overwrite: and --resume contradict each other" in capsys.readouterr().err


@pytest.mark.slow
def test_days_of_a_changed_protocol_are_refused_naming_overwrite(tmp_path: Path,
                                                                  capsys: pytest.CaptureFixture[str]) -> None:
    from experiments.days import pipeline

    text = (Path(pipeline.__file__).parent / "protocols" / "tabsa_short.toml").read_text().split(
        "\n[robot_backend]")[0]
    proto, out = tmp_path / "mine.toml", tmp_path / "out"
    proto.write_text(text)
    args = ["day", "--protocol", str(proto), "--schedulers", "fifo", "--workers", "1", "--days", "1", "--out",
            str(out)]
    assert cli_main(args) == 0
    proto.write_text(text.replace("count = 3", "count = 5", 1))
    capsys.readouterr()
    assert cli_main(args) == 2
    err = capsys.readouterr().err
    assert "give --overwrite to delete them and start afresh" in err and "Traceback" not in err
    assert _stored(out / "days.db") == [("scheduler=fifo", 1, "ok")]
    assert cli_main([*args, "--overwrite"]) == 0


def _full_disk(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every new SQLite connection may hold one page: the first write fails with SQLITE_FULL."""
    real = sqlite3.connect

    def connect(*a: Any, **kw: Any) -> sqlite3.Connection:
        con = real(*a, **kw)
        con.execute("PRAGMA max_page_count = 1")
        return con

    monkeypatch.setattr(store_mod.sqlite3, "connect", connect)


@pytest.mark.slow
def test_a_first_write_that_fails_leaves_nothing_that_blocks_the_next_run(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    with monkeypatch.context() as m:
        _full_disk(m)
        assert cli_main([*DAY, "--days", "1", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "database or disk is full" in err and "Traceback" not in err
    assert not (out / "days.db").exists()
    assert cli_main([*DAY, "--days", "1", "--out", str(out), "--resume"]) == 0  # --resume: as a user would go on
    assert _stored(out / "days.db") == [("scheduler=fifo", 1, "ok")]


@pytest.mark.slow
def test_an_empty_database_file_counts_as_none(tmp_path: Path) -> None:
    """What an older tasker's failed first write left: an empty file, and ``--resume`` refused it."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "days.db").write_bytes(b"")
    assert cli_main([*DAY, "--days", "1", "--out", str(out), "--resume"]) == 0
    assert not store_mod.holds_results(tmp_path / "nothing.db")
    with sqlite3.connect(tmp_path / "tables-less.db") as con:
        con.execute("PRAGMA user_version = 1")  # a valid SQLite file without a table
    assert not store_mod.holds_results(tmp_path / "tables-less.db")


def test_a_write_that_fails_later_keeps_what_was_stored(tmp_path: Path) -> None:
    db = tmp_path / "r.db"
    with ResultStore(db) as store:
        assert store.add(RunRow("a", 1, "default", Status.OK, {}, {"x": 1.0}))
        store._db.execute(f"PRAGMA max_page_count = {store._db.execute('PRAGMA page_count').fetchone()[0]}")
        with pytest.raises(StoreError, match="cannot store a result: database or disk is full.*run the same command"):
            store.add(RunRow("a", 2, "default", Status.OK, {}, {"x": "y" * 100_000}))
    with ResultStore(db, readonly=True) as store:
        assert [r.seed for r in store.rows()] == [1]


@pytest.fixture
def spec() -> SweepSpec:
    return SweepSpec((str(standin.DEMO),), (1, 2), (Strategy(),))


@pytest.mark.slow
def test_sweep_overwrite_and_the_lease_file(tmp_path: Path, spec: SweepSpec,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    db = tmp_path / "r.db"
    run_sweep(spec, db, workers=1, run_fn=standin.run, progress=False)
    assert not Path(f"{db}.lock").exists()
    with ResultStore(db) as store:
        store.add(RunRow("other", 9, "default", Status.OK, {}, {"x": 1.0}))
    spec_file = tmp_path / "s.toml"
    spec_file.write_text(f'scenarios = ["{standin.DEMO}"]\nseeds = 1\nstrategies = ["default"]\n')
    assert cli_main(["sweep", str(spec_file), "--db", str(db), "--workers", "1", "--overwrite"]) == 0
    assert [r[0] for r in _stored_keys(db)] == [str(standin.DEMO)]  # the other run went: asked by name
    assert not Path(f"{db}.lock").exists()


def _stored_keys(db: Path) -> list[tuple[str, int, str]]:
    with ResultStore(db, readonly=True) as store:
        return sorted(r.key for r in store.rows())


def test_overwrite_never_deletes_a_file_that_is_no_results_database(tmp_path: Path,
                                                                    capsys: pytest.CaptureFixture[str]) -> None:
    db = tmp_path / "app.db"
    with sqlite3.connect(db) as con:
        con.execute("CREATE TABLE users (name TEXT)")
    before = db.read_bytes()
    spec_file = tmp_path / "s.toml"
    spec_file.write_text(f'scenarios = ["{standin.DEMO}"]\nseeds = 1\nstrategies = ["default"]\n')
    assert cli_main(["sweep", str(spec_file), "--db", str(db), "--overwrite"]) == 2
    assert "not a tasker results database" in capsys.readouterr().err
    assert db.read_bytes() == before
    with pytest.raises(StoreError, match="is not a regular file"):
        ResultStore("/dev/null")
    with pytest.raises(StoreError, match="is not a file"):
        store_mod.remove("/dev/null")
    assert Path("/dev/null").exists()


def test_the_lease_is_exclusive_across_its_file_being_removed(tmp_path: Path) -> None:
    db = tmp_path / "r.db"
    with lease(db):
        assert Path(f"{db}.lock").exists()
        with pytest.raises(SweepError, match="another sweep is running"), lease(db):
            pass
    assert not Path(f"{db}.lock").exists()
    with lease(db), pytest.raises(SweepError, match="another sweep is running"), lease(db):
        pass
