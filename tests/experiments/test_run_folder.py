"""A run folder is data someone may send: ``tasker explain`` reads it only inside itself.

Before: every file an edited ``problems/index.json`` named was printed (and copied with ``--out``),
``../../`` and absolute paths included; a ``trace.jsonl`` that was a folder or a device read as
missing; deep or huge JSON, a stray byte or a NUL in a name was an internal error (exit 3).
Now a path leading out is refused, a damaged file is named as damaged, exit 2, one line.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from pathlib import Path

import pytest

from experiments.cli import main as cli_main
from tests.experiments.events import complete

SECRET = "TOP-SECRET-MARKER"
RECORD = {"n": 1, "t": 1.0, "agent": "d1", "task_type": "cook", "purpose": "upTsk", "label": "",
          "status": "solved", "domain": "cook.domain.pddl", "problem": "1.pddl", "message": "",
          "plan_file": "1.plan"}


@pytest.fixture
def run(tmp_path: Path) -> Path:
    """A small run folder whose files explain reads, and a secret file beside it."""
    (tmp_path / "secret.txt").write_text(SECRET + "\n")
    run = tmp_path / "shared" / "run"
    (run / "problems").mkdir(parents=True)
    (run / "problems" / "cook.domain.pddl").write_text("; domain\n")
    (run / "problems" / "1.pddl").write_text("; problem\n")
    (run / "problems" / "1.plan").write_text("(go)\n")
    (run / "problems" / "index.json").write_text(json.dumps([RECORD]))
    (run / "trace.jsonl").write_text(json.dumps(complete({"t": 0.0, "event": "run"})) + "\n")
    return run


def _index(run: Path, **change: object) -> None:
    (run / "problems" / "index.json").write_text(json.dumps([{**RECORD, **change}]))


def _link(run: Path, name: str, target: str | Path) -> None:
    path = run / name
    if path.is_dir():
        path.rmdir()
    else:
        path.unlink()
    os.symlink(target, path)


MUTATIONS: dict[str, tuple[Callable[[Path], object], str]] = {
    "absolute domain": (lambda r: _index(r, domain=str(r.parent.parent / "secret.txt")), "is an absolute path"),
    "dotdot problem": (lambda r: _index(r, problem="../../../secret.txt"), "leads out of the run folder"),
    "dotdot plan": (lambda r: _index(r, plan_file="../../../secret.txt"), "leads out of the run folder"),
    "dotdot inside a name": (lambda r: _index(r, domain="x/../../../../secret.txt"), "leads out of the run folder"),
    "a link out": (lambda r: _link(r, "problems/1.pddl", r.parent.parent / "secret.txt"),
                   "leads out of the run folder"),
    "the index a link out": (lambda r: _link(r, "problems/index.json", r.parent.parent / "secret.txt"),
                             "leads out of the run folder"),
    "the trace a link out": (lambda r: _link(r, "trace.jsonl", r.parent.parent / "secret.txt"),
                             "leads out of the run folder"),
    "the trace a device": (lambda r: _link(r, "trace.jsonl", "/dev/zero"), "leads out of the run folder"),
    "a NUL in a name": (lambda r: _index(r, domain="a\x00b"), "expected a file name of the run folder"),
    "an empty name": (lambda r: _index(r, problem=""), "expected a file name of the run folder"),
    "the folder itself": (lambda r: _index(r, problem="."), "is a directory, expected a file"),
    "the trace a folder": (lambda r: ((r / "trace.jsonl").unlink(), (r / "trace.jsonl").mkdir()),
                           "trace.jsonl: is a directory, expected a file"),
    "deep index": (lambda r: (r / "problems" / "index.json").write_text("[" * 50_000 + "]" * 50_000),
                   "nested more than 64 deep"),
    "deep but parseable index": (lambda r: (r / "problems" / "index.json").write_text("[" * 500 + "]" * 500),
                                 "nested more than 64 deep"),
    "a 5000-digit time": (lambda r: (r / "problems" / "index.json").write_text(
        json.dumps([RECORD]).replace('"t": 1.0', '"t": 1' + "0" * 5000)), "a number of thousands of digits"),
    "a 400-digit time": (lambda r: (r / "problems" / "index.json").write_text(
        json.dumps([RECORD]).replace('"t": 1.0', '"t": 1' + "0" * 400)), "expected a 64-bit integer"),
    "not UTF-8": (lambda r: (r / "problems" / "index.json").write_bytes(
        json.dumps([RECORD]).encode().replace(b"cook", b"c\xf6ok", 1)), "is not UTF-8 text (byte 0xf6)"),
    "a label that is an object": (lambda r: _index(r, label={"a": 1}), "label: expected a string, got an object"),
    "a message that is a list": (lambda r: _index(r, message=[1]), "message: expected a string, got an array"),
    "a problem file not UTF-8": (lambda r: (r / "problems" / "1.pddl").write_bytes(b"; \xff\n"),
                                 "1.pddl:1: is not UTF-8 text"),
    "a trace with a 400-digit time": (
        lambda r: (r / "trace.jsonl").write_text('{"t":1' + "0" * 400 + ',"event":"run"}\n'),
        "trace.jsonl:1: t: expected a 64-bit integer"),
    "a trace event missing a field": (lambda r: (r / "trace.jsonl").write_text('{"t":0,"event":"transition"}\n'),
                                      "trace.jsonl:1: transition: missing"),
    "a deep trace line": (lambda r: (r / "trace.jsonl").write_text('{"t":0,"event":"run","x":' + "[" * 300
                                                                   + "]" * 300 + "}\n"), "nested more than 64 deep"),
}


@pytest.mark.parametrize("name", list(MUTATIONS))
def test_a_damaged_or_escaping_run_folder_is_refused(run: Path, name: str, tmp_path: Path,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    mutate, fragment = MUTATIONS[name]
    mutate(run)
    out = tmp_path / "copied"
    assert cli_main(["explain", str(run), "--agent", "d1", "--out", str(out)]) == 2
    captured = capsys.readouterr()
    assert fragment in captured.err, captured.err
    assert captured.err.count("\n") == 1 and "Traceback" not in captured.err and "internal error" not in captured.err
    assert SECRET not in captured.out + captured.err
    assert not out.exists() or all(SECRET not in p.read_text(errors="replace") for p in out.iterdir())


def test_the_good_folder_still_explains(run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The fixture itself is fine: each refusal above is the mutation's."""
    assert cli_main(["explain", str(run), "--agent", "d1", "--out", str(tmp_path / "copied")]) == 0
    assert (tmp_path / "copied" / "plan").read_text() == "(go)\n"
    (run / "trace.jsonl").unlink()  # a run folder without a trace: nothing moved the agent, not an error
    assert cli_main(["explain", str(run), "--agent", "d1"]) == 0
    assert "; ---- domain" in capsys.readouterr().out


def test_a_link_inside_the_run_folder_is_followed(run: Path) -> None:
    """Links are not refused as such: one to another file of the run folder is read."""
    os.symlink("1.pddl", run / "problems" / "alias.pddl")
    _index(run, problem="alias.pddl")
    assert cli_main(["explain", str(run), "--agent", "d1"]) == 0
