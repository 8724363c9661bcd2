"""``tasker plan`` on temporal domains and ``tasker new --temporal`` through the command line."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from experiments.cli import main
from planners.temporal import engines
from planners.temporal.reading import parse
from tests.planners.temporal.conftest import pair


@pytest.mark.slow
def test_plan_json_is_a_validated_timed_plan(capsys: pytest.CaptureFixture[str]) -> None:
    d, p = pair("plansys2_simple")
    assert main(["plan", str(d), str(p), "--json", "--timeout", "30"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "solved" and out["planner"] == "kairos" and out["attempts"][0]["outcome"] == "valid"
    assert [s["action"] for s in out["timed_plan"]] == [s[0] for s in out["plan"]]
    assert out["makespan"] == out["cost"] and 30 <= out["makespan"] < 31


def test_plan_names_engines_in_order(capsys: pytest.CaptureFixture[str]) -> None:
    d, p = pair("tasker_concurrency")
    assert main(["plan", str(d), str(p), "--planner", "kairos,aries", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [a["engine"] for a in out["attempts"]][:1] == ["kairos"] and out["status"] == "solved"


def test_an_engine_error_is_exit_1_naming_it(monkeypatch: pytest.MonkeyPatch,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    def panic(name: str) -> str:
        raise RuntimeError(f"{name} panicked: state variable lifting")

    monkeypatch.setattr(engines, "register", panic)
    d, p = pair("plansys2_simple")
    assert main(["plan", str(d), str(p), "--planner", "aries"]) == 1
    out = capsys.readouterr().out
    assert "aries: error (RuntimeError: aries panicked: state variable lifting)" in out


def test_a_classical_planner_on_a_temporal_domain_is_bad_input(capsys: pytest.CaptureFixture[str]) -> None:
    d, p = pair("plansys2_simple")
    assert main(["plan", str(d), str(p), "--planner", "fast-downward"]) == 2
    assert "not a temporal engine" in capsys.readouterr().err


def test_a_pddl_fault_is_exit_2_with_its_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    d, p = pair("plansys2_simple")
    bad = tmp_path / "problem.pddl"
    bad.write_text(p.read_text().replace("(:goal", "(:goa"))
    assert main(["plan", str(d), str(bad)]) == 2
    assert f"{bad}:" in capsys.readouterr().err


def test_unsolvable_is_exit_1(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    d, p = pair("plansys2_simple")
    q = tmp_path / "problem.pddl"
    q.write_text(p.read_text().replace("(charging_point_at chargingroom)", ""))  # never charged: move never runs
    assert main(["plan", str(d), str(q), "--planner", "kairos", "--json", "--timeout", "20"]) == 1
    assert json.loads(capsys.readouterr().out)["status"] in ("unsolvable", "timeout")


@pytest.mark.slow
def test_new_temporal_writes_a_durative_folder_that_plans(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    folder = tmp_path / "fetch_t"
    assert main(["new", "fetch_t", str(folder), "--temporal", "--quiet"]) == 0
    d, p = folder / "domain.pddl", folder / "problem.pddl"
    assert parse(d.read_text(), p.read_text(), d, p).kind.has_continuous_time()
    capsys.readouterr()
    assert main(["plan", str(d), str(p)]) == 0
    out = capsys.readouterr().out
    assert "pick(robot, vase, kitchen) [blocking, skill=manipulate, 5 s]" in out


def test_a_domain_that_declares_durative_actions_but_has_none_is_planned(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """As ROSPlan's domains may: every action instantaneous, :durative-actions in the header (refused before)."""
    from tests.planners.conftest import DOMAIN, problem_text

    d, p = tmp_path / "domain.pddl", tmp_path / "problem.pddl"
    d.write_text(DOMAIN.replace(":action-costs", ":action-costs :durative-actions"))
    p.write_text(problem_text())
    assert main(["plan", str(d), str(p), "--json", "--timeout", "30"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "solved" and out["plan"][-1] == ["drop", "cup", "c"]
    assert all(s["duration"] == 0 for s in out["timed_plan"])  # instantaneous actions take no time
