"""The run's records as frozen types: run.json and problems/index.json keep their JSON forms."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from experiments.report.explain import ProblemEntry
from experiments.run.records import PlannerConfig, RunRecord, RunSettings
from experiments.run.runner import run_scenario
from tasker.errors import InputError

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "experiments" / "inputs" / "scenarios" / "synthetic_demo.toml"


def _record(**kw: object) -> RunRecord:
    settings = RunSettings("alg2", "IT", "static", "static", False, None, False)
    base = dict(scenario={"kind": "synthetic"}, seed=3, settings=settings, planner=None, host="h", platform="p",
                python="3.11", date="d", tasker_version="0.4", wall_time_s=1.5)
    return RunRecord(**{**base, **kw})  # type: ignore[arg-type]


def test_a_runs_run_json_is_its_record_and_reads_back(tmp_path: Path) -> None:
    result = run_scenario(DEMO, out=tmp_path, pictures=False)
    text = (tmp_path / "run.json").read_text()
    assert text == json.dumps(result.record.to_json(), indent=2, sort_keys=True, default=str) + "\n"
    back = RunRecord.from_json(json.loads(text))
    assert back == result.record and back.settings.update == "static" and back.status is None


def test_optional_keys_appear_only_when_set() -> None:
    plain = _record().to_json()
    assert sorted(plain) == ["date", "host", "planner", "platform", "python", "scenario", "seed", "settings",
                             "tasker_version", "wall_time_s"]
    assert sorted(plain["settings"]) == ["hazard_waiting", "mode", "policy", "randomized", "scheduler",
                                         "suspension", "update"]
    ended = _record(status="aborted", error="boom", planner=PlannerConfig("tasker-fd", "1.3.0", None)).to_json()
    assert (ended["status"], ended["error"]) == ("aborted", "boom")
    assert ended["planner"] == {"engine": "tasker-fd", "unified_planning": "1.3.0", "up_fast_downward": None}
    chosen = RunSettings("edf", "CT", "planned", "derived", True, "strict", True, tree="quick",
                         interruption={"strata": 4}).to_json()
    assert (chosen["tree"], chosen["interruption"], "perturbation" in chosen) == ("quick", {"strata": 4}, False)


def test_a_record_of_another_version_keeps_its_unknown_keys() -> None:
    data = {**_record().to_json(), "protocol_digest": "abc"}
    assert RunRecord.from_json(data).to_json() == data


def test_a_damaged_run_json_names_what_is_missing() -> None:
    data = _record().to_json()
    del data["seed"]
    with pytest.raises(InputError, match="out/run.json: seed: the run record has no 'seed'"):
        RunRecord.from_json(data, "out/run.json")
    with pytest.raises(InputError, match="expected a run record"):
        RunRecord.from_json([1, 2], "out/run.json")


def test_a_problem_entry_keeps_the_index_json_form() -> None:
    solved = ProblemEntry(1, 0.5, "d1", "cook", "upTsk", "", "solved", "cook.domain.pddl", "001_d1_upTsk.pddl",
                          {"b": "x", "a": "y"}, "", (("go", "a", "b"),), 3.0, plan_file="001_d1_upTsk.plan")
    j = solved.to_json()
    assert j["plan"] == [["go", "a", "b"]] and list(j["renamed"]) == ["a", "b"] and j["plan_file"].endswith(".plan")
    assert ProblemEntry.from_json(j) == solved
    failed = ProblemEntry(2, 1.0, "d1", "cook", "genSusp", "", "unsolvable", "cook.domain.pddl", "002.pddl", {},
                          "no plan", None, ProblemEntry.json_cost(math.inf))
    assert "plan_file" not in failed.to_json() and failed.to_json()["cost"] == "inf"
    assert ProblemEntry.json_cost(None) is None and ProblemEntry.json_cost(2.5) == 2.5
