"""``plan``, ``domains`` and ``fsm`` through their handlers and argparse."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import pytest

from planners.checks import load_problem
from planners.cli import register
from planners.validate import validate_plan
from tests.planners.conftest import DOMAIN, problem_text


def _run(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="tasker")
    register(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(argv)
    return int(args.func(args))


@pytest.mark.parametrize("name", ["depot", "miconic", "safe_road"])
def test_plan_on_up_classical_problems(name: str, up_pddl: Path, capsys: pytest.CaptureFixture[str]) -> None:
    d, p = up_pddl / name / "domain.pddl", up_pddl / name / "problem.pddl"
    assert _run(["plan", str(d), str(p), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "solved" and out["planner"] == "tasker-fd" and out["planner_time_s"] > 0
    _, _, problem = load_problem(d, p)
    assert validate_plan(problem, [tuple(s) for s in out["plan"]]).valid


def test_plan_human_output(pddl_files: tuple[Path, Path], capsys: pytest.CaptureFixture[str]) -> None:
    assert _run(["plan", str(pddl_files[0]), str(pddl_files[1])]) == 0
    out = capsys.readouterr().out
    assert "cost 6" in out and "(move a b)" in out and "stages:" in out and "drop(cup, c)" in out


def test_plan_with_another_planner(pddl_files: tuple[Path, Path], capsys: pytest.CaptureFixture[str]) -> None:
    assert _run(["plan", *map(str, pddl_files), "--planner", "fast-downward-opt", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["cost"] == 6 and out["planner"] == "fast-downward-opt"


def test_plan_unsolvable_exits_1(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    d, p = tmp_path / "d.pddl", tmp_path / "p.pddl"
    d.write_text(DOMAIN)
    p.write_text(problem_text(goal="(holding cup) (item-at cup c)"))
    assert _run(["plan", str(d), str(p), "--json"]) == 1
    assert json.loads(capsys.readouterr().out)["status"] == "unsolvable"


def test_plan_timeout_exits_1(up_pddl: Path, capsys: pytest.CaptureFixture[str]) -> None:
    d, p = up_pddl / "citycar" / "domain.pddl", up_pddl / "citycar" / "problem.pddl"
    assert _run(["plan", str(d), str(p), "--timeout", "0.5", "--json"]) == 1
    assert json.loads(capsys.readouterr().out)["status"] == "timeout"


def test_unknown_planner_exits_2(pddl_files: tuple[Path, Path], capsys: pytest.CaptureFixture[str]) -> None:
    assert _run(["plan", *map(str, pddl_files), "--planner", "nope"]) == 2
    err = capsys.readouterr().err
    assert "unknown planner 'nope'" in err and "tasker-fd" in err


def test_domains_lists_bundled(capsys: pytest.CaptureFixture[str]) -> None:
    assert _run(["domains"]) == 0
    out = capsys.readouterr().out
    for name in ("guide_human", "human_fell", "cook", "carry_object"):
        assert name in out


@pytest.mark.parametrize("fmt", ["mermaid", "dot"])
@pytest.mark.parametrize("purpose", ["upTsk", "genSusp"])
def test_fsm(fmt: str, purpose: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert _run(["fsm", "guide_human", "--purpose", purpose, "--format", fmt]) == 0
    out = capsys.readouterr().out
    assert ("stateDiagram-v2" in out) == (fmt == "mermaid") and ("digraph" in out) == (fmt == "dot")
    assert ("greet(robot, john, hall)" in out) == (purpose == "upTsk")


def test_fsm_static_and_unknown_task(capsys: pytest.CaptureFixture[str]) -> None:
    assert _run(["fsm", "cook", "--strategy", "static"]) == 0
    assert "(static)" in capsys.readouterr().out
    assert _run(["fsm", "no_such_task"]) == 2
    assert "unknown task type 'no_such_task'" in capsys.readouterr().err
