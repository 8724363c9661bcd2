"""Bad input is exit 2 with one clear line, never exit 3: the second round's kinds, through the CLI.

Before, each was an internal error (exit 3), a hang, or memory filled: deep nesting (a
RecursionError), numbers of hundreds or thousands of digits (OverflowError, ValueError), a
device read whole (``/dev/zero``), ``tasker check``'s own TOML reading, a damaged results
database or ``days.jsonl``, simulated times the clock stepped towards forever.
"""

from __future__ import annotations

import json
import os
import sqlite3
from pathlib import Path

import pytest

from experiments.cli import main
from experiments.metrics.store import ResultStore, RunRow, Status

DEEP_TOML = "kind = 'robot'\na = " + "[" * 50_000 + "]" * 50_000 + "\n"
FILES = {
    "deep.toml": DEEP_TOML,
    "deep-inline.toml": "kind = 'robot'\nx = " + "{a = " * 200 + "1" + "}" * 200 + "\n",
    "digits.toml": "kind = 'robot'\nworld = 'paper'\nseed = " + "9" * 5000 + "\n",
    "big.toml": "kind = 'robot'\nworld = 'paper'\nseed = 1" + "0" * 400 + "\n",
    "latin1.toml": b"kind = 'robot'\nname = 'caf\xe9'\n",
    "nul.toml": b"kind = 'robot'\n\x00\n",
}


@pytest.fixture
def bad(tmp_path: Path) -> Path:
    for name, text in FILES.items():
        p = tmp_path / name
        p.write_bytes(text if isinstance(text, bytes) else text.encode())
    os.symlink("/dev/zero", tmp_path / "zero.toml")
    os.symlink("/dev/zero", tmp_path / "zero.pddl")
    return tmp_path


def _fails_cleanly(argv: list[str], capsys: pytest.CaptureFixture[str], status: int = 2) -> str:
    assert main(argv) == status
    captured = capsys.readouterr()
    assert "internal error" not in captured.err and "Traceback" not in captured.err, captured.err
    return captured.err + captured.out


@pytest.mark.parametrize("name", [*FILES, "zero.toml"])
@pytest.mark.parametrize("command", ["run", "check", "sweep", "day", "world"])
def test_a_bad_file_is_bad_input_for_every_command(bad: Path, name: str, command: str,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    path = str(bad / name)
    argv = {"run": ["run", path, "--out", str(bad / "out")], "check": ["check", path],
            "sweep": ["sweep", path, "--db", str(bad / "r.db")],
            "day": ["day", "--protocol", path, "--out", str(bad / "day")], "world": ["world", path]}[command]
    text = _fails_cleanly(argv, capsys, status=1 if command == "check" else 2)
    assert name in text or "/dev/zero" in text


def test_a_pddl_device_is_refused_by_check_and_plan(bad: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert "is not a regular file" in _fails_cleanly(["check", str(bad / "zero.pddl")], capsys, status=1)
    assert "is not a regular file" in _fails_cleanly(["plan", str(bad / "zero.pddl"), str(bad / "zero.pddl")],
                                                     capsys)


@pytest.mark.parametrize(("key", "value", "fragment"), [
    ("horizon", "1e300", "settings.horizon: expected a number <= 604800"),
    ("rep_rate", "1e300", "settings.rep_rate: expected a number <= 1000"),
])
def test_settings_the_clock_could_never_reach_are_refused(tmp_path: Path, key: str, value: str, fragment: str,
                                                          capsys: pytest.CaptureFixture[str]) -> None:
    from experiments.inputs.scenario import SCENARIOS

    text = (SCENARIOS / "paper.toml").read_text()
    text = text.replace("[settings]\n", f"[settings]\n{key} = {value}\n", 1)
    if key == "rep_rate":
        text = text.replace("rep_rate = 1.0\n", "", 1)
    else:
        text = text.replace("horizon = 900.0\n", "", 1)
    p = tmp_path / "s.toml"
    p.write_text(text)
    assert fragment in _fails_cleanly(["run", str(p), "--out", str(tmp_path / "out")], capsys)


def test_a_request_time_the_clock_could_never_reach_is_refused(tmp_path: Path,
                                                              capsys: pytest.CaptureFixture[str]) -> None:
    from tests.experiments.standin import DEMO

    p = tmp_path / "s.toml"
    p.write_text(DEMO.read_text().replace("t = 0.0", "t = 1e300", 1))
    assert "expected a number <= 604800" in _fails_cleanly(["run", str(p), "--out", str(tmp_path / "o")], capsys)


@pytest.fixture
def days_out(tmp_path: Path) -> Path:
    out = tmp_path / "out"
    assert main(["day", "--protocol", "tabsa-short", "--days", "1", "--schedulers", "fifo", "--workers", "1",
                 "--out", str(out)]) == 0
    return out


@pytest.mark.slow
@pytest.mark.parametrize(("sql", "fragment"), [
    ("UPDATE runs SET metrics = '{\"a\": " + "[" * 5000 + "]" * 5000 + "}'", "nested more than 64 deep"),
    ("UPDATE runs SET metrics = '{\"a\": 1" + "0" * 400 + "}'", "expected a 64-bit integer"),
    ("UPDATE runs SET metrics = '{\"scheduler\": \"fifo\"}'", "seed: expected an integer >= 0"),
    ("UPDATE runs SET metrics = json_set(metrics, '$.strategy', 5)", "strategy: expected a strategy label"),
    ("UPDATE runs SET record = 5", "record: expected a JSON object"),
    ("UPDATE runs SET error = x'00ff'", "error: expected text"),
])
def test_a_damaged_days_database_is_named_before_any_day_runs(days_out: Path, sql: str, fragment: str,
                                                              capsys: pytest.CaptureFixture[str]) -> None:
    with sqlite3.connect(days_out / "days.db") as con:
        con.execute(sql)
    capsys.readouterr()
    text = _fails_cleanly(["day", "--protocol", "tabsa-short", "--days", "2", "--schedulers", "fifo", "--workers",
                           "1", "--out", str(days_out)], capsys)
    assert fragment in text and "days.db" in text


def test_a_damaged_days_log_is_named_at_its_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / "days.jsonl").write_text('{"a": 1}\n' + "[" * 5000 + "]" * 5000 + "\n")
    text = _fails_cleanly(["day", "--protocol", "tabsa-short", "--days", "1", "--schedulers", "fifo",
                           "--out", str(out)], capsys)
    assert "days.jsonl:1:" in text
    (out / "days.jsonl").write_text("[" * 5000 + "]" * 5000 + "\n")
    text = _fails_cleanly(["day", "--protocol", "tabsa-short", "--days", "1", "--schedulers", "fifo",
                           "--out", str(out)], capsys)
    assert "days.jsonl:1: not a JSON object: nested more than 64 deep" in text


@pytest.mark.parametrize(("column", "value", "fragment"), [
    ("metrics", "{\"x\": " + "[" * 3000 + "]" * 3000 + "}", "metrics: not JSON (nested more than 64 deep)"),
    ("metrics", "{\"x\": 1" + "0" * 5000 + "}", "thousands of digits"),
    ("record", "x" * (17 * 2**20), "a value larger than 16 MiB"),
])
def test_a_damaged_results_database_is_a_clean_report_error(tmp_path: Path, column: str, value: str, fragment: str,
                                                            capsys: pytest.CaptureFixture[str]) -> None:
    db = tmp_path / "r.db"
    with ResultStore(db) as store:
        store.add(RunRow("a", 1, "default", Status.OK, {}, {"x": 1.0}))
    with sqlite3.connect(db) as con:
        con.execute(f"UPDATE runs SET {column} = ?", (value,))
    text = _fails_cleanly(["report", "--db", str(db), "--out", str(tmp_path / "rep"), "--no-plots"], capsys)
    assert fragment in text and "id=1" in text


def test_the_sweeps_table_is_read_within_the_limits(tmp_path: Path) -> None:
    db = tmp_path / "r.db"
    with ResultStore(db) as store:
        store.log_sweep({"name": "x"}, {"workers": 1})
    with sqlite3.connect(db) as con:
        con.execute("UPDATE sweeps SET spec = ?", (json.dumps({"a": 1}).replace("1", "[" * 3000 + "]" * 3000),))
    from experiments.metrics.store import StoreError

    with ResultStore(db, readonly=True) as store, pytest.raises(StoreError, match="sweeps row id=1: not JSON"):
        store.sweeps()
