"""``plan``, ``domains``, ``fsm`` and ``new`` through the ``tasker`` command line."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from experiments.cli import main
from planners.checks import load_problem
from planners.validate import validate_plan
from tests.planners.conftest import DOMAIN, problem_text


def _run(argv: list[str]) -> int:
    return main(argv)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["depot", "miconic", "safe_road"])
def test_plan_on_up_classical_problems(name: str, up_pddl: Path, capsys: pytest.CaptureFixture[str]) -> None:
    d, p = up_pddl / name / "domain.pddl", up_pddl / name / "problem.pddl"
    assert _run(["plan", str(d), str(p), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "solved" and out["planner"] == "tasker-anytime" and out["planner_time_s"] > 0
    assert out["reader"] == "unified-planning" and out["validated"] is True
    _, _, problem = load_problem(d, p)
    assert validate_plan(problem, [tuple(s) for s in out["plan"]]).valid


def test_plan_human_output(pddl_files: tuple[Path, Path], capsys: pytest.CaptureFixture[str]) -> None:
    assert _run(["plan", str(pddl_files[0]), str(pddl_files[1])]) == 0
    out = capsys.readouterr().out
    assert "cost 6" in out and "(move a b)" in out and "plan valid (UP's sequential_plan_validator" in out
    assert "optimal: proven" in out
    # no task folder declares this domain's skills, kinds or durations: none are made up ("suspendable, 0 s")
    assert "stages: none shown: domain 'delivery' is no task folder's" in out and "0 s]" not in out


@pytest.mark.slow
def test_plan_with_another_planner(pddl_files: tuple[Path, Path], capsys: pytest.CaptureFixture[str]) -> None:
    assert _run(["plan", *map(str, pddl_files), "--planner", "fast-downward-opt", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["cost"] == 6 and out["planner"] == "fast-downward-opt"


@pytest.mark.slow
def test_plan_unsolvable_exits_1(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    d, p = tmp_path / "d.pddl", tmp_path / "p.pddl"
    d.write_text(DOMAIN)
    p.write_text(problem_text(goal="(holding cup) (item-at cup c)"))
    assert _run(["plan", str(d), str(p), "--json"]) == 1
    assert json.loads(capsys.readouterr().out)["status"] == "unsolvable"


@pytest.mark.slow
def test_plan_timeout_exits_1(up_pddl: Path, capsys: pytest.CaptureFixture[str]) -> None:
    d, p = up_pddl / "citycar" / "domain.pddl", up_pddl / "citycar" / "problem.pddl"
    assert _run(["plan", str(d), str(p), "--timeout", "0.5", "--json"]) == 1
    assert json.loads(capsys.readouterr().out)["status"] == "timeout"


def test_unknown_planner_exits_2(pddl_files: tuple[Path, Path], capsys: pytest.CaptureFixture[str]) -> None:
    assert _run(["plan", *map(str, pddl_files), "--planner", "nope"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("tasker plan: error: unknown planner 'nope'") and "tasker-fd" in err


def test_domains_lists_bundled(capsys: pytest.CaptureFixture[str]) -> None:
    assert _run(["domains"]) == 0
    out = capsys.readouterr().out
    for name in ("guide_human", "human_fell", "cook", "carry_object"):
        assert name in out


@pytest.mark.slow
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
    err = capsys.readouterr().err
    assert "unknown task type 'no_such_task'" in err and "--path DIR or TASKER_TASKS" in err
    assert _run(["fsm", "guide_humn"]) == 2
    assert "did you mean 'guide_human'?" in capsys.readouterr().err


@pytest.mark.slow
def test_plan_with_another_planner_prints_no_warnings(pddl_files: tuple[Path, Path],
                                                      capfd: pytest.CaptureFixture[str]) -> None:
    assert _run(["plan", *map(str, pddl_files), "--planner", "fast-downward-opt"]) == 0
    out, err = capfd.readouterr()
    assert "cost 6" in out and err == "" and "Warning" not in out


def test_plan_warm_cache_skips_the_reader_and_gives_the_same_plan(
        pddl_files: tuple[Path, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setenv("TASKER_CACHE", str(tmp_path / "cache"))
    assert _run(["plan", *map(str, pddl_files), "--json"]) == 0
    cold = json.loads(capsys.readouterr().out)
    import planners.checks

    def no_reader(*_: object) -> None:
        raise AssertionError("a checked problem is not read again")

    monkeypatch.setattr(planners.checks, "load_problem", no_reader)
    assert _run(["plan", *map(str, pddl_files), "--json"]) == 0
    warm = json.loads(capsys.readouterr().out)
    assert warm["plan"] == cold["plan"] and warm["cost"] == cold["cost"]
    Path(pddl_files[1]).write_text(Path(pddl_files[1]).read_text() + "\n; changed\n")
    assert _run(["plan", *map(str, pddl_files), "--json"]) == 3  # new content: checked again (here: our stub)
    assert "not read again" in capsys.readouterr().err


def test_new_check_plan_run_as_a_new_user_would(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    folder = tmp_path / "fetch"
    assert _run(["new", "fetch", str(folder)]) == 0
    assert {p.name for p in folder.iterdir()} == {"domain.pddl", "task.toml", "problem.pddl", "scenario.toml"}
    toml = (folder / "task.toml").read_text()
    for key in ("planning_time_s", "timeout_s", "suspended_facts", "max_interruption_s", "travel_s", "[example]",
                "[[hazards]]", "[[bindings]]", "[people]", "stages = ["):
        assert key in toml
    assert _run(["check", str(folder)]) == 0
    assert "0 problems" in capsys.readouterr().out
    assert _run(["plan", str(folder / "domain.pddl"), str(folder / "problem.pddl")]) == 0
    out = capsys.readouterr().out  # the domain's own task folder gives the stages their skills
    assert "(pick robot vase kitchen)" in out and "skill=manipulate" in out
    assert _run(["domains", "--path", str(folder)]) == 0
    assert "fetch(item, destination?)" in capsys.readouterr().out
    assert _run(["fsm", "fetch", "--path", str(folder), "--purpose", "genSusp", "--after", "2"]) == 0
    assert "put_down" in capsys.readouterr().out


def test_new_refuses_a_bad_name_and_a_full_folder(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert _run(["new", "Bad-Name", str(tmp_path / "a")]) == 2
    assert "argument TASK" in capsys.readouterr().err and not (tmp_path / "a").exists()
    (tmp_path / "b").mkdir()
    (tmp_path / "b" / "keep.txt").write_text("mine")
    assert _run(["new", "ok", str(tmp_path / "b")]) == 2
    assert "argument DIR" in capsys.readouterr().err and (tmp_path / "b" / "keep.txt").read_text() == "mine"


@pytest.mark.slow
def test_plan_says_when_the_domains_task_folder_does_not_load(tmp_path: Path,
                                                              capsys: pytest.CaptureFixture[str]) -> None:
    """Before: the stages printed as "skill=-, 0 s", silently, as if the domain were no task's."""
    folder = tmp_path / "fetch"
    assert _run(["new", "fetch", str(folder)]) == 0
    toml = folder / "task.toml"
    toml.write_text(toml.read_text().replace('skill = "manipulate"', 'skill = "grasp"', 1))
    capsys.readouterr()
    assert _run(["plan", str(folder / "domain.pddl"), str(folder / "problem.pddl")]) == 0
    err = capsys.readouterr().err
    assert "warning: the stages have no skills or durations" in err and "task.toml:" in err and "'grasp'" in err
