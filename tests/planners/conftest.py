"""Fixtures for the planner tests: a small action-cost domain and UP's classical test problems."""

from __future__ import annotations

from pathlib import Path

import pytest
import unified_planning

UP_PDDL = Path(unified_planning.__file__).parent / "test" / "pddl"

DOMAIN = """\
(define (domain delivery)
  (:requirements :strips :typing :action-costs)
  (:types room item - object)
  (:predicates (robot-at ?r - room) (item-at ?i - item ?r - room) (holding ?i - item) (free))
  (:functions (dist ?a ?b - room) - number (total-cost) - number)
  (:action move
    :parameters (?a ?b - room)
    :precondition (robot-at ?a)
    :effect (and (not (robot-at ?a)) (robot-at ?b) (increase (total-cost) (dist ?a ?b))))
  (:action pick
    :parameters (?i - item ?r - room)
    :precondition (and (robot-at ?r) (item-at ?i ?r) (free))
    :effect (and (holding ?i) (not (item-at ?i ?r)) (not (free)) (increase (total-cost) 1)))
  (:action drop
    :parameters (?i - item ?r - room)
    :precondition (and (robot-at ?r) (holding ?i))
    :effect (and (item-at ?i ?r) (not (holding ?i)) (free) (increase (total-cost) 1)))
)
"""


def problem_text(goal: str = "(item-at cup c)", extra_init: str = "") -> str:
    """A delivery problem where the cheap route a-b-c (2+2) beats the direct a-c (10)."""
    dists = {("a", "b"): 2, ("b", "c"): 2, ("a", "c"): 10}
    init = []
    for (x, y), d in dists.items():
        init += [f"(= (dist {x} {y}) {d})", f"(= (dist {y} {x}) {d})"]
    init += [f"(= (dist {r} {r}) 0)" for r in "abc"]
    return f"""\
(define (problem deliver)
  (:domain delivery)
  (:objects a b c - room cup - item)
  (:init (robot-at a) (item-at cup a) (free) (= (total-cost) 0) {' '.join(init)} {extra_init})
  (:goal (and {goal}))
  (:metric minimize (total-cost)))
"""


@pytest.fixture
def pddl_files(tmp_path: Path) -> tuple[Path, Path]:
    d, p = tmp_path / "domain.pddl", tmp_path / "problem.pddl"
    d.write_text(DOMAIN)
    p.write_text(problem_text())
    return d, p


@pytest.fixture(scope="session")
def up_pddl() -> Path:
    return UP_PDDL
