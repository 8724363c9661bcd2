"""The Fast Downward fast path: exit codes, the plan reader, outcomes."""

from __future__ import annotations

import pytest

from planners.fd import FDExit, FDOutcome, parse_plan_text, run_fast_downward
from tests.planners.conftest import DOMAIN, problem_text


@pytest.mark.parametrize(("code", "exit"), [
    (0, FDExit.SOLVED), (11, FDExit.UNSOLVABLE), (12, FDExit.UNSOLVABLE), (21, FDExit.TIMEOUT),
    (23, FDExit.TIMEOUT), (22, FDExit.MEMOUT), (24, FDExit.MEMOUT), (34, FDExit.ERROR), (-9, FDExit.ERROR),
])
def test_exit_codes(code: int, exit: FDExit) -> None:
    assert FDExit.from_code(code) is exit


def test_parse_plan_text() -> None:
    steps, cost = parse_plan_text("(move a b)\n(pick cup b)\n; cost = 3 (general cost)\n")
    assert steps == (("move", "a", "b"), ("pick", "cup", "b"))
    assert cost == 3.0


def test_outcome_checks_fire() -> None:
    with pytest.raises(ValueError, match="needs a plan"):
        FDOutcome(FDExit.SOLVED, 0, None, None, 0.0, 0.0)
    with pytest.raises(ValueError, match="must not carry a plan"):
        FDOutcome(FDExit.UNSOLVABLE, 11, (("a",),), None, 0.0, 0.0)


def test_solves_optimally_with_costs() -> None:
    out = run_fast_downward(DOMAIN, problem_text())
    assert out.exit is FDExit.SOLVED
    assert out.cost == 6  # pick, move a-b, move b-c, drop; not the direct a-c (10)
    assert out.plan == (("pick", "cup", "a"), ("move", "a", "b"), ("move", "b", "c"), ("drop", "cup", "c"))


def test_unsolvable() -> None:
    out = run_fast_downward(DOMAIN, problem_text(goal="(holding cup) (item-at cup c)"))
    assert out.exit is FDExit.UNSOLVABLE and out.plan is None and out.code in (10, 11, 12)


def test_timeout_is_reported() -> None:
    out = run_fast_downward(DOMAIN, problem_text(), timeout=1e-6)
    assert out.exit is FDExit.TIMEOUT


def test_translator_input_error_is_an_error_not_an_exception() -> None:
    out = run_fast_downward(DOMAIN, problem_text(goal="(nonsense cup)"))
    assert out.exit is FDExit.ERROR and "translator" in out.message
