"""Which domains are temporal, PlanSys2's empty blocks, and errors that name the file and line."""

from __future__ import annotations

from pathlib import Path

import pytest

from planners.checks import PddlError
from planners.temporal.reading import is_temporal, parse, tolerant
from tests.planners.temporal.conftest import pair

CLASSICAL = "(define (domain d) (:requirements :strips) (:predicates (p)) (:action a :effect (p)))"


def test_a_durative_action_or_the_requirement_makes_a_domain_temporal() -> None:
    assert is_temporal("(define (domain d) (:durative-action a :duration (= ?duration 1)))")
    assert is_temporal("(define (domain d) (:requirements :strips :durative-actions) (:action a :effect (p)))")
    assert not is_temporal(CLASSICAL)
    assert not is_temporal(CLASSICAL.replace("(:predicates", "; a :durative-action here is a comment\n(:predicates"))


def test_empty_blocks_are_blanked_with_lines_and_columns_kept() -> None:
    text = "(define (domain d)\n(:functions\n  ;; none\n)\n(:predicates (p))\n(:constants ))"
    out = tolerant(text)
    assert len(out) == len(text) and out.count("\n") == text.count("\n")
    assert "(:functions" not in out and "(:constants" not in out and "(:predicates (p))" in out
    assert out.index("(:predicates") == text.index("(:predicates")


@pytest.mark.slow
def test_plansys2_simple_example_reads(simple: tuple[Path, Path]) -> None:
    d, p = simple
    assert "(:functions" in d.read_text()  # the empty block UP's reader refuses as written
    problem = parse(d.read_text(), p.read_text(), d, p)
    assert problem.kind.has_continuous_time() and {a.name for a in problem.actions} == {"move", "askcharge", "charge"}


def test_a_fault_names_the_file_and_line(tmp_path: Path) -> None:
    d, p = pair("plansys2_simple")
    bad = p.read_text().replace("(robot_at leia entrance)", "(robot_at leia nowhere)")
    with pytest.raises(PddlError) as e:
        parse(d.read_text(), bad, d, tmp_path / "problem.pddl")
    assert e.value.file == str(tmp_path / "problem.pddl") and e.value.line == bad.splitlines().index(
        "  (robot_at leia nowhere)") + 1


def test_a_domain_fault_is_the_domains(tmp_path: Path) -> None:
    d, p = pair("plansys2_simple")
    with pytest.raises(PddlError) as e:
        parse(d.read_text().replace("(robot_at ?r ?r1)", "(robot_at ?r)", 1), p.read_text(), tmp_path / "d.pddl", p)
    assert e.value.file == str(tmp_path / "d.pddl")


def test_a_reader_crash_is_bad_input_not_a_bug(monkeypatch: pytest.MonkeyPatch) -> None:
    from unified_planning.io import PDDLReader

    def boom(*args: object, **kwargs: object) -> None:
        raise AssertionError

    d, p = pair("plansys2_simple")
    parse(d.read_text(), None, d)  # the domain alone reads
    monkeypatch.setattr(PDDLReader, "parse_problem_string", boom)
    with pytest.raises(PddlError, match="reader cannot read it"):
        parse(d.read_text(), p.read_text(), d, p)


def test_a_domain_constant_declared_again_as_an_object_is_read() -> None:
    from planners.temporal.reading import without_constants

    text = "(define (problem p)\n (:objects\n  leia - robot ; the (robot)\n  jack m1 - person\n  kitchen - room)\n)"
    out = without_constants(text, {"leia": "robot", "jack": "person", "kitchen": "place"})
    assert len(out) == len(text) and out.count("\n") == text.count("\n")
    assert "leia" not in out and "- robot" not in out.split(";")[0]  # the whole entry: name, dash, type
    assert " m1 - person" in out and "jack" not in out  # jack gone, its group's other name kept
    assert "kitchen - room" in out  # a constant of another type stays, for the reader to refuse
    d, p = pair("plansys2_simple")
    domain = d.read_text().replace(");; end Types", ")\n(:constants leia - robot)", 1)
    assert "(:constants leia - robot)" in domain and "leia - robot" in p.read_text()
    problem = parse(domain, p.read_text(), d, p)
    assert [o.name for o in problem.all_objects].count("leia") == 1
