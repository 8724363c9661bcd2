"""Malformed PDDL is refused before any run: the file, the line, what is wrong; exit 2 from ``plan``."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import pytest

from experiments.cli import main
from planners.checks import SUPPORTED_REQUIREMENTS, DefinitionError, PddlError, load_problem
from tests.planners.conftest import DOMAIN, problem_text

Mutation = Callable[[str, str], tuple[str, str]]

# name -> (mutation of (domain, problem), file at fault, expects a line, message fragment)
CASES: dict[str, tuple[Mutation, str, bool, str]] = {
    "domain syntax error": (lambda d, p: (d.replace("(free))", "(free)", 1), p), "domain", True, "syntax error"),
    "unknown predicate": (lambda d, p: (d.replace("(holding ?i) (not (item-at", "(hold ?i) (not (item-at"), p),
                          "domain", True, "unknown predicate"),
    "wrong arity in action": (lambda d, p: (d.replace("(holding ?i) (not (item-at", "(holding ?i ?r) (not (item-at"),
                                            p), "domain", True, "arity"),
    "undefined type": (lambda d, p: (d.replace("(?i - item ?r - room)\n    :precondition (and (robot-at ?r) (holding",
                                               "(?i - thing ?r - room)\n    :precondition (and (robot-at ?r) (holding"),
                                     p), "domain", True, "type: thing"),
    "undefined parameter": (lambda d, p: (d.replace(":precondition (robot-at ?a)", ":precondition (robot-at ?z)"), p),
                            "domain", True, "undefined name found: z"),
    # (not :durative-actions: such a domain is planned by the temporal engines, tests/planners/temporal)
    "unsupported requirement": (lambda d, p: (d.replace(":action-costs", ":action-costs :timed-initial-literals"), p),
                                "domain", True, ":timed-initial-literals"),
    "empty domain": (lambda d, p: ("", p), "domain", True, "syntax error"),
    "missing goal": (lambda d, p: (d, re.sub(r"\(:goal.*?\)\)\n", "", p, flags=re.S)), "problem", False, "goal"),
    "unknown object": (lambda d, p: (d, p.replace("(robot-at a)", "(robot-at nowhere)")), "problem", True, "nowhere"),
    "problem syntax error": (lambda d, p: (d, p + ")"), "problem", True, "syntax error"),
    "wrong arity in goal": (lambda d, p: (d, p.replace("(item-at cup c)", "(item-at cup)")), "problem", True, "arity"),
    "unknown predicate in goal": (lambda d, p: (d, p.replace("(item-at cup c)", "(on cup c)")), "problem", True,
                                  "unknown predicate"),
    "undefined object type": (lambda d, p: (d, p.replace("cup - item", "cup - widget")), "problem", False, "widget"),
    "numeric fluents": (lambda d, p: (d.replace("(increase (total-cost) 1)))\n  (:action drop",
                                                "(increase (dist ?r ?r) 1)))\n  (:action drop"), p),
                        "domain", True, "an effect on the numeric fluent dist"),
}


def _write(tmp_path: Path, name: str) -> tuple[Path, Path, str, bool, str]:
    mutate, at_fault, has_line, fragment = CASES[name]
    d_text, p_text = mutate(DOMAIN, problem_text())
    assert (d_text, p_text) != (DOMAIN, problem_text()), f"mutation {name!r} changed nothing"
    d, p = tmp_path / "dom.pddl", tmp_path / "prob.pddl"
    d.write_text(d_text)
    p.write_text(p_text)
    return d, p, str(d if at_fault == "domain" else p), has_line, fragment


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(CASES))
def test_malformed_input_is_refused_with_file_and_line(name: str, tmp_path: Path) -> None:
    d, p, fault, has_line, fragment = _write(tmp_path, name)
    with pytest.raises(PddlError) as info:
        load_problem(d, p)
    err = info.value
    assert err.file == fault
    assert fragment.lower() in str(err).lower()
    assert (err.line is not None) == has_line
    if has_line:
        assert f"{fault}:{err.line}" in str(err)


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(CASES))
def test_plan_command_exits_2_without_traceback(name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    d, p, fault, _, _ = _write(tmp_path, name)
    assert main(["plan", str(d), str(p), "--timeout", "10"]) == 2
    out = capsys.readouterr()
    assert out.err.startswith("tasker plan: error: ")
    assert fault in out.err and "Traceback" not in out.err + out.out


def test_missing_file(tmp_path: Path, pddl_files: tuple[Path, Path]) -> None:
    with pytest.raises(DefinitionError, match="no such file"):
        load_problem(tmp_path / "absent.pddl", pddl_files[1])


def test_error_format() -> None:
    err = PddlError("x.pddl", "bad", 3, 7)
    assert str(err) == "x.pddl:3:7: bad" and err.line == 3 and err.col == 7


@pytest.mark.parametrize(("requirements", "passes"), [
    (":strips :typing :action-costs", True), (":adl", True), (":strips :durative-actions", False),
    (":fluents", False), ("", False), (":strips :bogus", False), (":strips) (:requirements :typing", False),
])
def test_requirements_at_a_glance_agree_with_the_grammar(requirements: str, passes: bool) -> None:
    """The quick s-expression look at ``:requirements`` passes what we support, and never passes
    what the grammar refuses."""
    from planners.checks import _supported_at_a_glance, declared_requirements

    text = DOMAIN.replace(":strips :typing :action-costs", requirements)
    try:
        grammar_ok = all(r in SUPPORTED_REQUIREMENTS for r in declared_requirements(text))
    except PddlError:
        grammar_ok = False
    assert _supported_at_a_glance(text) is passes
    assert grammar_ok is passes
