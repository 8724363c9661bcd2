"""The results database of a sweep: one SQLite file, one row per finished run.

A run is identified by its job key ``(scenario, seed, strategy)``; the key is UNIQUE
in the table, so a run is stored at most once.  Each run is written in its own
transaction as soon as it finishes, and the database is in WAL mode with full
synchronisation, so a sweep that is killed loses nothing it had finished, and a
resumed sweep runs only the keys the table does not hold yet.

Only the process that drives a sweep writes to the database (workers return their
results to it); any number of readers (``tasker report``) may read meanwhile, and a
reader (``ResultStore(path, readonly=True)``) never writes: not even the schema.  A
file that is not a results database (another program's SQLite file, a foreign or newer
schema) is refused before anything is written to it, and a corrupt row is a
:class:`StoreError` naming the row and the column.
"""

from __future__ import annotations

import json
import math
import sqlite3
from collections.abc import Iterable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from datetime import UTC, datetime
from enum import StrEnum
from pathlib import Path
from typing import Any

from tasker.errors import StoreError as StoreError  # defined there; re-exported here
from tasker.support import reader

SCHEMA_VERSION = 1

_SCHEMA = """
CREATE TABLE IF NOT EXISTS meta (
    key   TEXT PRIMARY KEY,
    value TEXT NOT NULL
);
CREATE TABLE IF NOT EXISTS runs (
    id       INTEGER PRIMARY KEY,
    scenario TEXT NOT NULL,
    seed     INTEGER NOT NULL,
    strategy TEXT NOT NULL,
    status   TEXT NOT NULL CHECK (status IN ('ok', 'error')),
    error    TEXT,
    record   TEXT NOT NULL,
    metrics  TEXT NOT NULL,
    wall     REAL,
    worker   TEXT,
    finished TEXT NOT NULL,
    UNIQUE (scenario, seed, strategy)
);
CREATE TABLE IF NOT EXISTS sweeps (
    id       INTEGER PRIMARY KEY,
    started  TEXT NOT NULL,
    spec     TEXT NOT NULL,
    setup    TEXT NOT NULL
);
"""

MAX_ROWS = 1_000_000
"""The most runs a results database may hold (a sweep has at most 100 000 jobs)."""

MAX_CELL_BYTES = 16 * 2**20
"""The largest record, metrics or error text of one run (a run's are a few kB)."""

JobKey = tuple[str, int, str]
"""``(scenario, seed, strategy)``: what identifies one run of a sweep."""


_COLUMNS = {
    "meta": ("key", "value"),
    "runs": ("id", "scenario", "seed", "strategy", "status", "error", "record", "metrics", "wall", "worker",
             "finished"),
    "sweeps": ("id", "started", "spec", "setup"),
}


def _remove(path: Path) -> None:
    """Delete a database file with its ``-wal``, ``-shm`` and ``-journal`` files (those that exist)."""
    for p in (path, *(Path(f"{path}{x}") for x in ("-wal", "-shm", "-journal"))):
        try:
            p.unlink(missing_ok=True)
        except OSError:
            pass


def holds_results(path: str | Path) -> bool:
    """Whether ``path`` is a results database that holds anything: a missing file, an empty one or
    a database a failed first write left without the schema is none, and never blocks a run."""
    p = Path(path)
    if not p.is_file() or p.stat().st_size == 0:
        return False
    with ResultStore(p, readonly=True, empty_ok=True) as store:
        return store._has_schema


def remove(path: str | Path) -> bool:
    """Delete the results database at ``path`` (``--overwrite``); ``False`` if there was none.

    Only a results database (or an empty file) is deleted: another program's file is refused
    (:class:`StoreError`), as every write to one is."""
    p = Path(path)
    if not p.exists():
        return False
    if p.is_file() and p.stat().st_size > 0:
        ResultStore(p, readonly=True, empty_ok=True).close()  # refuses a file that is not one
    elif not p.is_file():
        raise StoreError(f"{p}: is not a file, expected a results database")
    _remove(p)
    return True


class Status(StrEnum):
    """How a run ended."""

    OK = "ok"
    ERROR = "error"


@dataclass(frozen=True)
class RunRow:
    """One stored run: its key, how it ended, and what it recorded."""

    scenario: str
    seed: int
    strategy: str
    status: Status
    record: dict[str, Any]
    metrics: dict[str, Any]
    error: str | None = None
    wall: float | None = None
    worker: str | None = None
    finished: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.status, Status):
            raise ValueError(f"RunRow.status: expected a Status, got {self.status!r}")
        if self.status is Status.ERROR and not self.error:
            raise ValueError("RunRow.error: a run with status 'error' needs a message")

    @property
    def key(self) -> JobKey:
        return (self.scenario, self.seed, self.strategy)


def _now() -> str:
    return datetime.now(UTC).isoformat(timespec="seconds")


def _finite(value: Any) -> Any:
    """Non-finite floats as the strings ``"inf"``, ``"-inf"``, ``"nan"`` (as in the trace): JSON has none."""
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, Mapping):
        return {str(k): _finite(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_finite(v) for v in value]
    return value


def _dumps(value: Any) -> str:
    return json.dumps(_finite(value), sort_keys=True, allow_nan=False, default=str)


class ResultStore:
    """The SQLite results database at ``path`` (created on first use).

    Use as a context manager, or call :meth:`close`.
    """

    def __init__(self, path: str | Path, *, readonly: bool = False, empty_ok: bool = False) -> None:
        self.path = Path(path)
        self.readonly = readonly
        self._has_schema = True
        if readonly:
            if not self.path.is_file():
                raise StoreError(f"{self.path}: " + ("no such results database" if not self.path.exists() else
                                                     "is not a regular file, expected a results database"))
            try:
                # mode=ro: a reader never creates, migrates or journals anything.  Without a live
                # writer (no -wal file: a sweep removes it when it closes) the file is opened
                # immutable, else SQLite would leave -wal and -shm files beside it.
                live = Path(f"{self.path}-wal").exists()
                flags = "mode=ro" if live else "mode=ro&immutable=1"
                self._db = sqlite3.connect(f"{self.path.resolve().as_uri()}?{flags}", uri=True, timeout=30.0,
                                           isolation_level=None)
                self._has_schema = not self._check_schema(must_exist=not empty_ok)
            except sqlite3.DatabaseError as exc:
                raise StoreError(f"{self.path}: not a results database: {exc}") from None
            return
        if self.path.is_dir():
            raise StoreError(f"{self.path}: is a directory, expected a results database file")
        if self.path.exists() and not self.path.is_file():
            raise StoreError(f"{self.path}: is not a regular file (a device, a pipe or a socket), expected a "
                             "results database file")
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise StoreError(f"{self.path}: cannot create its folder: {exc.strerror or exc}") from None
        new = not self.path.exists() or self.path.stat().st_size == 0
        self._db = None  # type: ignore[assignment]
        try:
            # isolation_level=None: we issue BEGIN/COMMIT ourselves, one transaction per run
            self._db = sqlite3.connect(self.path, timeout=30.0, isolation_level=None)
            fresh = self._check_schema(must_exist=False)
            self._db.execute("PRAGMA journal_mode=WAL")
            self._db.execute("PRAGMA synchronous=FULL")
            if fresh:
                with self._transaction() as db:
                    for statement in _SCHEMA.split(";"):
                        if statement.strip():
                            db.execute(statement)
                    db.execute("INSERT OR IGNORE INTO meta VALUES ('schema_version', ?)", (str(SCHEMA_VERSION),))
        except sqlite3.DatabaseError as exc:
            if self._db is not None:
                self._db.close()
            if new:  # a first write that failed (a full disk): leave nothing that would block the next run
                _remove(self.path)
            what = "not a results database" if isinstance(exc, sqlite3.DatabaseError) and not isinstance(
                exc, sqlite3.OperationalError) else "cannot create the results database"
            raise StoreError(f"{self.path}: {what}: {exc}") from None
        except StoreError:
            self._db.close()
            raise
        self._has_schema = True

    def _check_schema(self, *, must_exist: bool) -> bool:
        """Is this an empty database (``True``), ours (``False``), or neither (:class:`StoreError`)?"""
        tables = {r[0] for r in self._db.execute("SELECT name FROM sqlite_master WHERE type='table'")}
        if not tables:
            if must_exist:
                raise StoreError(f"{self.path}: an empty SQLite file, not a results database "
                                 "(no sweep has written to it)")
            return True
        missing = sorted(set(_COLUMNS) - tables)
        if missing:
            raise StoreError(f"{self.path}: not a tasker results database: it has tables {sorted(tables)}, "
                             f"expected {sorted(_COLUMNS)} (missing {missing}); refusing to touch it")
        for table, expected in _COLUMNS.items():
            cols = tuple(r[1] for r in self._db.execute(f"PRAGMA table_info({table})"))
            if cols != expected:
                raise StoreError(f"{self.path}: table {table!r} has columns {list(cols)}, expected {list(expected)}: "
                                 "a foreign or damaged schema")
        version = self._db.execute("SELECT value FROM meta WHERE key='schema_version'").fetchone()
        if version is None or str(version[0]) != str(SCHEMA_VERSION):
            found = "none" if version is None else repr(version[0])
            raise StoreError(f"{self.path}: schema version {found}, this tasker reads {SCHEMA_VERSION}")
        return False

    def __enter__(self) -> ResultStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        self._db.close()

    @contextmanager
    def _transaction(self) -> Iterator[sqlite3.Connection]:
        self._db.execute("BEGIN IMMEDIATE")
        try:
            yield self._db
        except BaseException:
            if self._db.in_transaction:  # SQLite has rolled back already after some errors (a full disk)
                self._db.execute("ROLLBACK")
            raise
        self._db.execute("COMMIT")

    def _writable(self) -> None:
        if self.readonly:
            raise StoreError(f"{self.path}: opened read-only")

    def add(self, row: RunRow) -> bool:
        """Store one finished run in its own transaction.

        Returns ``False`` (and changes nothing) if a run with the same key is already
        stored: the first result of a key is the one kept.
        """
        self._writable()
        try:
            with self._transaction() as db:
                db.execute(
                    "INSERT INTO runs (scenario, seed, strategy, status, error, record, metrics, wall, worker,"
                    " finished) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                    (row.scenario, row.seed, row.strategy, row.status.value, row.error, _dumps(row.record),
                     _dumps(row.metrics), row.wall, row.worker, row.finished or _now()),
                )
        except sqlite3.IntegrityError:
            return False
        except sqlite3.DatabaseError as exc:  # a full disk, a file made read-only meanwhile
            raise StoreError(f"{self.path}: cannot store a result: {exc} (what was stored before is kept: "
                             "run the same command again to go on)") from None
        return True

    def keys(self, status: Status | None = None) -> set[JobKey]:
        """The keys of the stored runs (of one status, if given)."""
        sql = "SELECT scenario, seed, strategy FROM runs"
        args: tuple[Any, ...] = ()
        if status is not None:
            sql += " WHERE status = ?"
            args = (status.value,)
        try:
            return {(str(s), int(n), str(k)) for s, n, k in self._db.execute(sql, args)}
        except (sqlite3.DatabaseError, TypeError, ValueError) as exc:
            raise StoreError(f"{self.path}: cannot read the run keys: {exc}") from None

    def forget(self, keys: Iterable[JobKey]) -> int:
        """Delete the runs with these keys (to run them again); returns how many were deleted."""
        self._writable()
        with self._transaction() as db:
            return sum(db.execute("DELETE FROM runs WHERE scenario=? AND seed=? AND strategy=?", k).rowcount
                       for k in keys)

    def rows(self, status: Status | None = None) -> list[RunRow]:
        """The stored runs in key order (of one status, if given)."""
        sql = ("SELECT id, scenario, seed, strategy, status, error, record, metrics, wall, worker, finished FROM runs"
               + (" WHERE status = ?" if status is not None else "") + " ORDER BY scenario, seed, strategy")
        args = (status.value,) if status is not None else ()
        try:
            n = self.count()
            if n > MAX_ROWS:
                raise StoreError(f"{self.path}: {n} runs, more than the {MAX_ROWS} a results database may hold")
            big = self._db.execute("SELECT id FROM runs WHERE length(CAST(record AS BLOB)) > ? OR "
                                   "length(CAST(metrics AS BLOB)) > ? OR length(CAST(error AS BLOB)) > ? LIMIT 1",
                                   (MAX_CELL_BYTES,) * 3).fetchone()
            if big is not None:
                raise StoreError(f"{self.path}: runs row id={big[0]}: a value larger than "
                                 f"{MAX_CELL_BYTES // 2**20} MiB, more than a run records")
            return [self._row(*r) for r in self._db.execute(sql, args)]
        except sqlite3.DatabaseError as exc:
            raise StoreError(f"{self.path}: cannot read the runs: {exc}") from None

    def _row(self, rid: int, s: Any, n: Any, k: Any, st: Any, err: Any, rec: Any, met: Any, wall: Any,
             worker: Any, fin: Any) -> RunRow:
        """One stored row, checked: a corrupt one names its id and column."""
        def bad(column: str, what: str) -> StoreError:
            return StoreError(f"{self.path}: runs row id={rid}: {column}: {what}")

        for column, value in (("scenario", s), ("strategy", k), ("finished", fin)):
            if not isinstance(value, str):
                raise bad(column, f"expected text, got {value!r}")
        if isinstance(n, bool) or not isinstance(n, int):
            raise bad("seed", f"expected an integer, got {n!r}")
        try:
            status = Status(st)
        except ValueError:
            raise bad("status", f"expected one of {[x.value for x in Status]}, got {st!r}") from None
        decoded = []
        for column, text in (("record", rec), ("metrics", met)):
            if not isinstance(text, str):
                raise bad(column, f"not JSON (expected text, got {type(text).__name__})")
            try:  # within the readers' limits: nesting, 64-bit integers
                value = reader.parse_json(text, "row")
            except reader.InputError as exc:
                why = exc.message.removeprefix("not valid JSON: ").removeprefix("not readable JSON: ")
                raise bad(column, f"not JSON ({exc.field + ': ' if exc.field else ''}{why})") from None
            if not isinstance(value, dict):
                raise bad(column, f"expected a JSON object, got {type(value).__name__}")
            decoded.append(value)
        if wall is not None and (isinstance(wall, bool) or not isinstance(wall, int | float)):
            raise bad("wall", f"expected a number, got {wall!r:.40}")
        for column, value in (("error", err), ("worker", worker)):
            if value is not None and not isinstance(value, str):
                raise bad(column, f"expected text, got {value!r:.40}")
        try:
            return RunRow(s, n, k, status, decoded[0], decoded[1], err, wall, worker, fin)
        except ValueError as exc:
            raise bad("error", str(exc)) from None

    def count(self) -> int:
        return int(self._db.execute("SELECT COUNT(*) FROM runs").fetchone()[0])

    def log_sweep(self, spec: Mapping[str, Any], setup: Mapping[str, Any]) -> None:
        """Record that a sweep (or a resumption of one) started: its spec and how it runs."""
        self._writable()
        with self._transaction() as db:
            db.execute("INSERT INTO sweeps (started, spec, setup) VALUES (?, ?, ?)",
                       (_now(), _dumps(spec), _dumps(setup)))

    def sweeps(self) -> list[dict[str, Any]]:
        """Every logged sweep start, oldest first: ``started``, ``spec``, ``setup``."""
        out = []
        for sid, st, sp, se in self._db.execute("SELECT id, started, spec, setup FROM sweeps ORDER BY id LIMIT ?",
                                                (MAX_ROWS,)):
            try:
                if not all(isinstance(x, str) and len(x) <= MAX_CELL_BYTES for x in (sp, se)):
                    raise reader.InputError("row", "expected JSON text")
                out.append({"started": st, "spec": reader.parse_json(sp, "row"), "setup": reader.parse_json(se, "row")})
            except reader.InputError as exc:
                why = exc.message.removeprefix("not valid JSON: ").removeprefix("not readable JSON: ")
                raise StoreError(f"{self.path}: sweeps row id={sid}: not JSON ({why})") from None
        return out
