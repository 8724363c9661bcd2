"""``tasker plan``'s pipeline: Fast Downward's translator where UP's reader cannot read legal PDDL,
plans validated by UP where UP reads the task, and engine failures named, exit 1, never exit 3."""

from __future__ import annotations

import importlib.util
import json
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any

import pytest
import unified_planning as up
from unified_planning.engines import Engine, PlanGenerationResult
from unified_planning.engines.mixins import OneshotPlannerMixin
from unified_planning.model import ProblemKind

from experiments.cli import main
from planners.checks import PddlError, load_problem
from planners.plan_files import FilesAnswer, Reader, plan_files
from planners.planner import PddlText, Planner
from planners.results import Failure, PlanResult, PlanStatus
from tests.planners.conftest import DOMAIN, problem_text
from tests.planners.pddl_cases import EITHER, READER_LIMITS, SUBTYPES, Case


def _files(tmp_path: Path, case: Case | tuple[str, str]) -> tuple[Path, Path]:
    domain, problem = (case.domain, case.problem) if isinstance(case, Case) else case
    d, p = tmp_path / "domain.pddl", tmp_path / "problem.pddl"
    d.write_text(domain)
    p.write_text(problem)
    return d, p


@pytest.mark.parametrize("name", sorted(READER_LIMITS))
def test_what_fast_downward_reads_is_planned_and_said_so(name: str, tmp_path: Path,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    case = READER_LIMITS[name]
    d, p = _files(tmp_path, case)
    assert main(["plan", str(d), str(p), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [tuple(s) for s in out["plan"]] == list(case.plan)
    assert out["reader"] == "fast-downward-translator" and case.refusal in out["reader_refusal"]
    assert out["validated"] is None and out["validation"].startswith("not validated: unified-planning's reader")


@pytest.mark.parametrize("name", sorted(READER_LIMITS))
def test_task_folders_keep_ups_reader_and_the_refusal_points_to_the_form_it_reads(name: str, tmp_path: Path) -> None:
    case = READER_LIMITS[name]
    d, p = _files(tmp_path, case)
    with pytest.raises(PddlError) as info:
        load_problem(d, p)
    assert info.value.reader_only and case.refusal in str(info.value) and info.value.line is not None


def test_human_output_says_which_reader_and_that_the_plan_is_unvalidated(tmp_path: Path,
                                                                        capsys: pytest.CaptureFixture[str]) -> None:
    d, p = _files(tmp_path, EITHER)
    assert main(["plan", str(d), str(p)]) == 0
    out = capsys.readouterr().out
    assert "(go r k h)" in out and "read by Fast Downward's translator; not validated" in out
    assert "optimal: proven" in out


def test_a_real_error_is_not_handed_to_the_lenient_translator(tmp_path: Path,
                                                              capsys: pytest.CaptureFixture[str]) -> None:
    """FD's translator takes an undeclared type for an empty one; UP's refusal stands (exit 2)."""
    d, p = _files(tmp_path, (DOMAIN.replace("(?i - item ?r - room)\n    :precondition (and (robot-at ?r) (item-at",
                                            "(?i - thing ?r - room)\n    :precondition (and (robot-at ?r) (item-at"),
                             problem_text()))
    assert main(["plan", str(d), str(p)]) == 2
    assert "type: thing" in capsys.readouterr().err


def test_when_neither_reader_reads_it_ups_refusal_names_the_line(tmp_path: Path,
                                                                 capsys: pytest.CaptureFixture[str]) -> None:
    d, p = _files(tmp_path, (EITHER.domain, EITHER.problem.replace("(holding b)", "(carrying b)")))
    assert main(["plan", str(d), str(p)]) == 2
    err = capsys.readouterr().err
    assert f"{d}:4:" in err and "translator refuses it too" in err and "Traceback" not in err


def test_another_engine_needs_ups_reader_and_says_what_reads_more(tmp_path: Path,
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    d, p = _files(tmp_path, EITHER)
    assert main(["plan", str(d), str(p), "--planner", "fast-downward-opt"]) == 2
    assert "the default planner reads more of PDDL" in capsys.readouterr().err


def test_plans_are_validated_and_the_verdict_remembered(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                        capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setenv("TASKER_CACHE", str(tmp_path / "cache"))
    d, p = _files(tmp_path, (DOMAIN, problem_text()))
    assert main(["plan", str(d), str(p), "--json", "--planner", "tasker-fd"]) == 0
    first = json.loads(capsys.readouterr().out)
    assert first["validated"] is True and first["validation"] == "valid (UP's sequential_plan_validator)"
    assert main(["plan", str(d), str(p), "--json", "--planner", "tasker-fd"]) == 0
    again = json.loads(capsys.readouterr().out)
    assert again["validated"] is True and "remembered" in again["validation"] and again["plan"] == first["plan"]


class _WrongPlanner(Planner):
    """A planner whose plan skips the pick: what an engine with a bug could return."""

    def solve(self, problem: Any, timeout: float | None = None) -> PlanResult:
        return PlanResult(PlanStatus.SOLVED, (("move", "a", "b"), ("drop", "cup", "b")), 3.0, self.name, 0.01,
                          search="lama-first")


def test_a_plan_the_validator_rejects_is_the_engines_failure(tmp_path: Path) -> None:
    d, p = _files(tmp_path, (DOMAIN, problem_text()))
    answer = plan_files(d, p, DOMAIN, problem_text(), _WrongPlanner("tasker-first"))
    assert answer.result.status is PlanStatus.ERROR and answer.result.failure is Failure.ENGINE
    assert "tasker-first returned a plan that UP's sequential_plan_validator rejects" in answer.result.message


class RaisingEngine(Engine, OneshotPlannerMixin):
    """A UP one-shot engine that fails inside ``_solve``, as Tamer does on subtypes (UP issue #290)."""

    def __init__(self) -> None:
        Engine.__init__(self)
        OneshotPlannerMixin.__init__(self)

    @property
    def name(self) -> str:
        return "raising"

    @staticmethod
    def supported_kind() -> ProblemKind:
        from planners.kind import supported_kind

        return supported_kind()

    @staticmethod
    def supports(problem_kind: ProblemKind) -> bool:
        return True

    def _solve(self, problem: up.model.AbstractProblem, heuristic: Callable[..., Any] | None = None,
               timeout: float | None = None, output_stream: IO[str] | None = None) -> PlanGenerationResult:
        raise RuntimeError("index 3 out of range in the engine")


class TimingOutEngine(RaisingEngine):
    """A UP one-shot engine that runs out of time."""

    @property
    def name(self) -> str:
        return "timing-out"

    def _solve(self, problem: up.model.AbstractProblem, heuristic: Callable[..., Any] | None = None,
               timeout: float | None = None, output_stream: IO[str] | None = None) -> PlanGenerationResult:
        from unified_planning.engines import PlanGenerationResultStatus as UPStatus

        return PlanGenerationResult(UPStatus.TIMEOUT, None, self.name)


def test_another_engines_timeout_says_what_to_try(tmp_path: Path) -> None:
    from unified_planning.environment import get_environment

    factory = get_environment().factory
    if "timing-out" not in factory.engines:
        factory.add_engine("timing-out", __name__, "TimingOutEngine")
    _, _, problem = load_problem(*_files(tmp_path, (DOMAIN, problem_text())))
    res = Planner("timing-out").solve(problem, timeout=2.0)
    assert res.status is PlanStatus.TIMEOUT
    assert res.message.startswith("engine timing-out found no plan within 2 s") and "try tasker-anytime" in res.message


def test_an_exception_inside_an_engine_exits_1_naming_it(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from unified_planning.environment import get_environment

    factory = get_environment().factory
    if "raising" not in factory.engines:
        factory.add_engine("raising", __name__, "RaisingEngine")
    d, p = _files(tmp_path, (DOMAIN, problem_text()))
    assert main(["plan", str(d), str(p), "--planner", "raising", "--json"]) == 1
    out = capsys.readouterr()
    assert json.loads(out.out)["failure"] == "engine"
    assert "tasker plan: error: engine raising failed: RuntimeError: index 3 out of range" in out.err
    assert "internal error" not in out.err


@pytest.mark.skipif(importlib.util.find_spec("up_tamer") is None,
                    reason="up-tamer is optional (its licence reads 'Free For Educational Use')")
def test_tamers_subtype_bug_is_tamers_exit_1(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    d, p = _files(tmp_path, SUBTYPES)
    assert main(["plan", str(d), str(p), "--planner", "tamer"]) == 1
    err = capsys.readouterr().err
    assert "engine tamer failed" in err and "internal error" not in err
    assert main(["plan", str(d), str(p), "--json"]) == 0  # the default planner reads subtypes


def test_files_answer_checks_fire() -> None:
    solved = Planner("tasker-fd", cache_size=0).solve(PddlText(DOMAIN, problem_text()))
    timeout = PlanResult(PlanStatus.TIMEOUT, None, None, "x", 1.0)
    with pytest.raises(ValueError, match="exactly when the translator"):
        FilesAnswer(solved, Reader.FAST_DOWNWARD)
    with pytest.raises(ValueError, match="exactly when the translator"):
        FilesAnswer(solved, Reader.UNIFIED_PLANNING, refused="no")
    with pytest.raises(ValueError, match="cannot have validated"):
        FilesAnswer(solved, Reader.FAST_DOWNWARD, refused="either", validated=True)
    with pytest.raises(ValueError, match="only a plan"):
        FilesAnswer(timeout, Reader.UNIFIED_PLANNING, validated=True)
    with pytest.raises(ValueError, match="ERROR result"):
        FilesAnswer(solved, Reader.UNIFIED_PLANNING, validated=False)


def test_a_validator_that_fails_leaves_the_plan_unvalidated_not_a_crash(tmp_path: Path,
                                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    import planners.validate

    def broken(*_: object) -> None:
        raise KeyError("fluent")

    monkeypatch.setenv("TASKER_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(planners.validate, "validate_plan", broken)
    d, p = _files(tmp_path, (DOMAIN, problem_text()))
    answer = plan_files(d, p, DOMAIN, problem_text(), Planner("tasker-fd", cache_size=0))
    assert answer.result.solved and answer.validated is None
    assert answer.validation == "not validated: UP's validator failed: KeyError: 'fluent'"
