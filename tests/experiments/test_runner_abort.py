"""``run_scenario`` writes what it has when a run raises, then raises ``RunAborted`` with the partial result."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from experiments import runner
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
