"""The day report on both backends: protocol task types in the rows, path metrics only where measured,
resumable logs."""

from __future__ import annotations

import json
from pathlib import Path

from experiments import dayreport

EVENTS = [
    {"t": 0.0, "event": "request", "agent": "d1", "task_type": "folder_a", "args": {"deadline": 10.0}},
    {"t": 12.0, "event": "end", "agent": "d1", "task_type": "folder_a", "cause": "finished"},
]


def test_trace_task_types_are_reported_under_the_protocols_names() -> None:
    m = dayreport.day_metrics(EVENTS, day_end=20.0, kinds={"folder_a": "transport"})
    assert set(m["per_type"]) == {"transport"} and m["per_type"]["transport"]["lateness_s"] == 2.0


def result(name: str, seed: int, **extra: float) -> dict[str, object]:
    m = dayreport.day_metrics(EVENTS, day_end=20.0, kinds={"folder_a": "transport"})
    return {"scheduler": name, "seed": seed, **m, **extra}


def test_path_rows_appear_only_with_path_metrics() -> None:
    synthetic = dayreport.table([result(n, s) for n in ("lookahead", "alg2") for s in (1, 2)])
    assert "abandonments" not in synthetic and "travel distance" not in synthetic
    robot = dayreport.table([result(n, s, abandonments=s, abandoned_falls=1, travel_m=10.0 * s)
                             for n in ("lookahead", "alg2") for s in (1, 2)])
    assert "| abandonments (robot leaves a fallen person's 2 m circle) | 1.50 ± 6.35 | 1.50 ± 6.35 |" in robot
    assert "| travel distance (m) | 15.00 ± 63.53 | 15.00 ± 63.53 |" in robot


def test_a_stopped_run_resumes_from_its_log(tmp_path: Path) -> None:
    log = tmp_path / "days.jsonl"
    first = dayreport.run_days("tabsa-short", 1, ["fifo"], workers=1, log=log)
    assert len(log.read_text().splitlines()) == 1
    marked = {**first[0], "completed": -1}  # a result already logged is read back, not run again
    log.write_text(json.dumps(marked) + "\n")
    again = dayreport.run_days("tabsa-short", 2, ["fifo"], workers=1, log=log)
    assert [r["seed"] for r in again] == [1, 2] and again[0]["completed"] == -1
    assert len(log.read_text().splitlines()) == 2
