"""Fuzzing what a run leaves behind: run folders, traces, results databases and ``days.jsonl``.

A run folder, a results database and a day log are data someone may send.  Mutated, each is
read or refused with a :class:`~tasker.errors.TaskerError` (``tasker explain``: exit 2), never a
traceback, a hang or a file read from outside the run folder.
"""

from __future__ import annotations

import json
import shutil
import sqlite3
import warnings
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from experiments.report import explain
from experiments.trace.timeline import Timeline
from tasker.errors import TaskerError
from tests.fuzz.conftest import bounded, examples, mutated

SECRET = "FUZZ-SECRET-MARKER"


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A run folder as ``tasker run`` writes one: a synthetic run's trace, and a ``problems/`` folder
    of three planning calls as :func:`experiments.report.explain.write_problems` writes them."""
    from experiments.inputs import synthetic
    from tests.experiments.standin import DEMO

    root = tmp_path_factory.mktemp("fuzzrun")
    (root / "secret.txt").write_text(SECRET)
    out = root / "shared" / "run"
    (out / "problems").mkdir(parents=True)
    synthetic.run(synthetic.load(DEMO), seed=1).write(out / "trace.jsonl")
    index = []
    for n, (t, agent, purpose) in enumerate([(0.5, "d1", "upTsk"), (9.0, "d1", "genSusp"), (12.0, "d2", "upTsk")], 1):
        stem = f"{n:03d}_{agent}_{purpose}"
        (out / "problems" / f"{stem}.pddl").write_text(f"(define (problem p{n}) (:domain cook))\n")
        (out / "problems" / f"{stem}.plan").write_text("(go robot a b)\n; cost = 1\n")
        index.append({"n": n, "t": t, "agent": agent, "task_type": "cook", "purpose": purpose, "label": "",
                      "status": "solved", "domain": "cook.domain.pddl", "problem": f"{stem}.pddl",
                      "renamed": {}, "message": "", "plan": [["go", "robot", "a", "b"]], "cost": 1.0,
                      "plan_file": f"{stem}.plan"})
    (out / "problems" / "cook.domain.pddl").write_text("(define (domain cook))\n")
    (out / "problems" / "index.json").write_text(json.dumps(index, indent=1, sort_keys=True) + "\n")
    return out


def _copy(run: Path) -> Path:
    work = run.parent / "work"
    if work.exists():
        shutil.rmtree(work)
    shutil.copytree(run, work, symlinks=True)
    return work


def _explains_cleanly(folder: Path, capture: Path) -> None:
    with bounded(10.0):
        try:
            ex = explain.explain(folder, "d1")
        except TaskerError as exc:
            assert str(exc).strip() and SECRET not in str(exc)
            return
        assert SECRET not in ex.text()
        files = explain.write(ex, capture)
        assert all(SECRET not in f.read_text() for f in files)


@pytest.mark.slow
@examples(60)
@given(data=st.data())
def test_a_mutated_index(run: Path, data: st.DataObject) -> None:
    folder = _copy(run)
    index = folder / "problems" / "index.json"
    index.write_bytes(data.draw(mutated(index.read_bytes())))
    _explains_cleanly(folder, run.parent / "out")


ESCAPES = ["../../../secret.txt", "../../secret.txt", "/etc/hostname", "", ".", "..", "a\x00b", "problems/../../x",
           "x/" * 300, "ö" * 200, 5, None, [], {"a": 1}, True, 1e308]


@pytest.mark.slow
@examples(60)
@given(key=st.sampled_from(["domain", "problem", "plan_file", "agent", "t", "label", "message", "status"]),
       value=st.sampled_from(ESCAPES) | st.text(max_size=30), which=st.integers(0, 50))
def test_an_index_naming_anything(run: Path, key: str, value: object, which: int) -> None:
    folder = _copy(run)
    path = folder / "problems" / "index.json"
    index = json.loads(path.read_text())
    index[which % len(index)][key] = value
    path.write_text(json.dumps(index))
    _explains_cleanly(folder, run.parent / "out")


@pytest.mark.slow
@examples(80)
@given(data=st.data())
def test_a_mutated_trace(run: Path, data: st.DataObject) -> None:
    folder = _copy(run)
    trace = folder / "trace.jsonl"
    trace.write_bytes(data.draw(mutated(trace.read_bytes())))
    with bounded(10.0):
        try:
            Timeline.read(trace)
        except TaskerError:
            pass
    _explains_cleanly(folder, run.parent / "out")


@examples(30)
@given(column=st.sampled_from(["record", "metrics", "error", "seed", "strategy", "status", "wall", "finished"]),
       value=st.one_of(st.text(max_size=40), st.integers(-2**63, 2**63 - 1), st.floats(), st.binary(max_size=20),
                       st.none(),
                       st.sampled_from(["{\"a\": " + "[" * 3000 + "]" * 3000 + "}", "{\"a\": 1" + "0" * 400 + "}",
                                        "{}", "[]", "{\"x\": NaN}"])))
def test_a_damaged_results_database_row(tmp_path_factory: pytest.TempPathFactory, column: str,
                                        value: object) -> None:
    from experiments.metrics.store import ResultStore, RunRow, Status
    from experiments.sweep.report import build_report

    folder = tmp_path_factory.mktemp("db")
    db = folder / "r.db"
    with ResultStore(db) as store:
        store.add(RunRow("a", 1, "update=static", Status.OK, {"seed": 1}, {"x": 1.0}))
        store.add(RunRow("a", 1, "update=planned", Status.OK, {"seed": 1}, {"x": 2.0}))
    with sqlite3.connect(db) as con:
        con.execute("PRAGMA ignore_check_constraints = ON")
        try:
            con.execute(f"UPDATE runs SET {column} = ? WHERE id = 2", (value,))
        except sqlite3.IntegrityError:  # NOT NULL: a value SQLite itself refuses
            return
    with bounded(20.0), warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a constant or non-finite metric is noted: a fact, not a fault
        try:
            files = build_report(db, folder / "report", plots=False)
        except TaskerError:
            return
    assert files.markdown.is_file() and files.summary_csv.is_file()  # read through: a whole report


@examples(60)
@given(data=st.data())
def test_a_mutated_days_log(tmp_path_factory: pytest.TempPathFactory, data: st.DataObject) -> None:
    from experiments.days.resume import import_log

    folder = tmp_path_factory.mktemp("log")
    day = {"scheduler": "fifo", "seed": 1, "strategy": "default", "backend": "synthetic", "completed": 3,
           "lateness_s": 0.0, "dead_falls": 0, "interruptions": 1, "suspensions": 1, "suspension_time_s": 2.0,
           "switches": 1, "longest_order": 2, "anytime_decisions": 0, "completion_minus_deadline_s": None,
           "per_type": {"fall": {"completed": 1}}, "ending": "all done"}
    log = folder / "days.jsonl"
    log.write_bytes(data.draw(mutated((json.dumps(day) + "\n" + json.dumps({**day, "seed": 2}) + "\n").encode())))
    with bounded(10.0):
        try:
            import_log(log, folder / "days.db", "tabsa-short", "synthetic")
        except TaskerError:
            return
    assert (folder / "days.db").is_file()  # accepted: the days were imported, not dropped
