"""The results database as an input: foreign files and corrupt rows are clean errors, and a
report reads without writing a byte."""

from __future__ import annotations

import hashlib
import sqlite3
import warnings
from pathlib import Path

import pytest

from experiments.inputs.strategy import Strategy
from experiments.metrics.store import ResultStore, RunRow, Status, StoreError
from experiments.sweep.driver import run_sweep
from experiments.sweep.report import EmptyDatabase, build_report
from experiments.sweep.spec import SweepSpec
from tests.experiments import standin


def _digest(folder: Path) -> dict[str, str]:
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.iterdir()) if p.is_file()}


@pytest.fixture
def db(tmp_path: Path) -> Path:
    path = tmp_path / "db" / "r.db"
    with ResultStore(path) as store:
        store.add(RunRow("a", 1, "update=static,suspension=static", Status.OK, {"seed": 1}, {"x": 1.0}))
        store.add(RunRow("a", 1, "update=static,suspension=planned", Status.OK, {"seed": 1}, {"x": 2.0}))
    return path


def test_a_foreign_sqlite_file_is_refused_and_left_untouched(tmp_path: Path) -> None:
    path = tmp_path / "app.db"
    with sqlite3.connect(path) as con:
        con.execute("CREATE TABLE users (name TEXT)")
    before = path.read_bytes()
    for readonly in (False, True):
        with pytest.raises(StoreError, match=r"not a tasker results database: it has tables \['users'\]"):
            ResultStore(path, readonly=readonly)
    assert path.read_bytes() == before
    with sqlite3.connect(path) as con:
        assert [r[0] for r in con.execute("SELECT name FROM sqlite_master")] == ["users"]


def test_a_foreign_runs_table_and_a_newer_schema_are_refused(db: Path, tmp_path: Path) -> None:
    other = tmp_path / "other.db"
    with sqlite3.connect(other) as con:
        con.executescript("CREATE TABLE meta (key TEXT, value TEXT); CREATE TABLE runs (id INTEGER, x TEXT);"
                          "CREATE TABLE sweeps (id INTEGER, started TEXT, spec TEXT, setup TEXT);")
    with pytest.raises(StoreError, match="table 'runs' has columns"):
        ResultStore(other)
    with sqlite3.connect(db) as con:
        con.execute("UPDATE meta SET value = '99' WHERE key = 'schema_version'")
    with pytest.raises(StoreError, match="schema version '99'"):
        ResultStore(db, readonly=True)


@pytest.mark.parametrize(("column", "value", "fragment"), [
    ("record", "{not json", "record: not JSON"),
    ("metrics", "[1, 2]", "metrics: expected a JSON object"),
    ("seed", "'x'", "seed: expected an integer"),
    ("status", "'maybe'", "status"),
])
def test_a_corrupt_row_names_its_id_and_column(db: Path, column: str, value: str, fragment: str) -> None:
    with sqlite3.connect(db) as con:
        if column == "status":  # the CHECK constraint guards it: a foreign writer could still drop it
            con.execute("PRAGMA ignore_check_constraints = ON")
        quoted = value if column in ("seed", "status") else "'" + value.replace("'", "''") + "'"
        con.execute(f"UPDATE runs SET {column} = {quoted} WHERE id = 2")
    with ResultStore(db, readonly=True) as store, pytest.raises(StoreError, match=rf"runs row id=2: .*{fragment}"):
        store.rows()
    with pytest.raises(StoreError, match="id=2"):
        build_report(db, db.parent.parent / "out", plots=False)


def test_report_never_writes_to_the_database(db: Path, tmp_path: Path) -> None:
    before = _digest(db.parent)
    files = build_report(db, tmp_path / "out", plots=False)
    assert files.markdown.is_file()
    assert _digest(db.parent) == before  # no schema, no WAL, no journal: not a byte
    with ResultStore(db, readonly=True) as store, pytest.raises(StoreError, match="read-only"):
        store.add(RunRow("b", 1, "default", Status.OK, {}, {}))


def test_report_on_an_empty_database_warns(tmp_path: Path) -> None:
    path = tmp_path / "empty.db"
    ResultStore(path).close()
    before = _digest(tmp_path)
    with pytest.warns(EmptyDatabase, match="holds no runs"):
        build_report(path, tmp_path / "out", plots=False)
    assert _digest(tmp_path) == before
    (tmp_path / "zero.db").write_bytes(b"")
    with pytest.raises(StoreError, match="empty SQLite file"):
        build_report(tmp_path / "zero.db", tmp_path / "out2", plots=False)
    assert (tmp_path / "zero.db").read_bytes() == b""
    with pytest.raises(StoreError, match="no such results database"):
        build_report(tmp_path / "none.db", tmp_path / "out3", plots=False)
    assert not (tmp_path / "none.db").exists()


def test_a_sweep_refuses_a_foreign_database_before_running_anything(tmp_path: Path) -> None:
    path = tmp_path / "app.db"
    with sqlite3.connect(path) as con:
        con.execute("CREATE TABLE users (name TEXT)")
    spec = SweepSpec(("demo",), (1,), (Strategy("static", "static"),), sources={"demo": str(standin.DEMO)})
    with pytest.raises(StoreError, match="not a tasker results database"):
        run_sweep(spec, path, workers=1, run_fn=standin.run, progress=False)


def test_an_absurd_spec_built_in_code_is_refused() -> None:
    with pytest.raises(ValueError, match="more than the"):
        SweepSpec(("a", "b"), tuple(range(60_000)), (Strategy(),))


def test_warnings_stay_quiet_on_a_good_database(db: Path, tmp_path: Path) -> None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        files = build_report(db, tmp_path / "out", plots=False)
    assert [str(w.message) for w in caught] == []
    report = files.markdown.read_text(encoding="utf-8")
    assert "update=static,suspension=static" in report and "update=static,suspension=planned" in report
