"""``run_scenario`` writes what it has when a run raises, then raises ``RunAborted`` with the partial result."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from experiments.run import runner
from tasker.errors import RunAborted
from tasker.loop import SimulationLoop


def test_a_run_that_raises_still_writes_trace_record_and_metrics(tmp_path: Path,
                                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    def crash(loop: SimulationLoop, progress: bool) -> None:
        loop.run(until=5.0)
        loop.at(loop.now, lambda: (_ for _ in ()).throw(RuntimeError("operator pulled the plug")))
        loop.run()

    monkeypatch.setattr(runner, "_run", crash)
    out = tmp_path / "o"
    with pytest.raises(RunAborted, match="operator pulled the plug") as info:
        runner.run_scenario("synthetic_demo", out=out, seed=3)
    result = info.value.result
    assert isinstance(result, runner.RunResult) and isinstance(info.value.__cause__, RunAborted)
    record = json.loads((out / "run.json").read_text())
    assert record["status"] == "aborted" and "operator pulled the plug" in record["error"]
    assert json.loads((out / "metrics.json").read_text()) == json.loads(json.dumps(result.metrics))
    lines = [json.loads(line) for line in (out / "trace.jsonl").read_text().splitlines()]
    assert lines[0]["event"] == "run" and lines[-1]["event"] == "run" and lines[-1]["status"] == "aborted"
    assert lines[-1]["t"] == pytest.approx(5.0)
    assert not (out / "timeline.png").exists()  # pictures of a cut run are not drawn


def test_a_run_into_a_used_folder_leaves_no_file_of_the_earlier_run(tmp_path: Path) -> None:
    """Before: a run into the folder of an earlier one rewrote only what it writes, so after
    ``--no-pictures`` (or a synthetic run, or fewer planning calls) the old report.html, pictures,
    trajectory and problems/ sat beside the new trace as if they were its own."""
    out = tmp_path / "o"
    (out / "problems").mkdir(parents=True)
    stale = [*(out / n for n in ("trace.jsonl", "trajectory.jsonl", "run.json", "metrics.json", "timeline.png",
                                 "gantt.png", "world.png", "report.html")),
             *(out / "problems" / n for n in ("index.json", "001_d1_upTsk.pddl", "001_d1_upTsk.plan"))]
    for f in stale:
        f.write_text("from an earlier run")
    (out / "notes.txt").write_text("the user's")
    runner.run_scenario("synthetic_demo", out=out, seed=3, pictures=False)
    left = sorted(p.relative_to(out).as_posix() for p in out.rglob("*"))
    assert left == ["metrics.json", "notes.txt", "run.json", "trace.jsonl"]
    assert all(f.read_text() != "from an earlier run" for f in out.iterdir() if f.is_file() and f.suffix != ".txt")


def test_a_folder_that_holds_no_run_keeps_its_files(tmp_path: Path) -> None:
    """Only an earlier run's outputs are removed: ``--out .`` in a project keeps its own report.html."""
    out = tmp_path / "project"
    out.mkdir()
    (out / "report.html").write_text("the user's")
    runner.run_scenario("synthetic_demo", out=out, seed=3, pictures=False)
    assert (out / "report.html").read_text() == "the user's"
