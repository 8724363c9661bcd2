"""Small PDDL tasks written for these tests: legal PDDL that unified-planning's reader cannot read,
one with axioms, and a gripper problem of any size (hard for A* with LM-cut, easy for LAMA).

Each reader-limit case carries the plan expected of it, worked out by hand."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

CASES = Path(__file__).resolve().parents[2] / "benchmarks" / "data" / "pddl_cases"
"""The cases' PDDL: one folder each (``domain.pddl``, ``problem.pddl``), read by these tests and by
``benchmarks/bench_planner.py --engines`` (benchmarks import nothing from the tests)."""


@dataclass(frozen=True)
class Case:
    domain: str
    problem: str
    plan: tuple[tuple[str, ...], ...]
    refusal: str  # what unified-planning's refusal says (a fragment)


def _case(folder: str, plan: tuple[tuple[str, ...], ...], refusal: str) -> Case:
    return Case((CASES / folder / "domain.pddl").read_text(), (CASES / folder / "problem.pddl").read_text(),
                plan, refusal)


EITHER = _case("either", (("go", "r", "k", "h"), ("pick", "r", "b", "h")), "declare a common supertype")
DERIVED = _case("derived", (("open-door", "k", "h"), ("go", "k", "h")), ":derived predicates")
REPEATED = _case("repeated-parameter", (("load", "b", "t", "l"),), "predicate in names parameter ?obj twice")
GLUED = _case("glued-variable", (("go", "r", "k", "h"),),
              "robot?r: a name and a variable without a space between them")
NO_COST_INIT = _case("no-total-cost-init",
                     (("pick", "cup", "a"), ("move", "a", "b"), ("move", "b", "c"), ("drop", "cup", "c")),
                     "does not set (= (total-cost) 0)")
"""The planner tests' delivery task, its problem without ``(= (total-cost) 0)`` (as IPC's tetris)."""

READER_LIMITS = {"either": EITHER, "derived": DERIVED, "repeated parameter": REPEATED,
                 "no total-cost init": NO_COST_INIT, "glued variable": GLUED}

SUBTYPES = ((CASES / "subtypes" / "domain.pddl").read_text(), (CASES / "subtypes" / "problem.pddl").read_text())
"""A ``tiago - robot`` hierarchy: what Tamer's type checker refuses (UP issue #290)."""

GRIPPER = """\
(define (domain gripper)
  (:requirements :strips)
  (:predicates (room ?r) (ball ?b) (gripper ?g) (at-robby ?r) (at ?b ?r) (free ?g) (carry ?o ?g))
  (:action move :parameters (?from ?to)
    :precondition (and (room ?from) (room ?to) (at-robby ?from))
    :effect (and (at-robby ?to) (not (at-robby ?from))))
  (:action pick :parameters (?obj ?room ?gripper)
    :precondition (and (ball ?obj) (room ?room) (gripper ?gripper) (at ?obj ?room) (at-robby ?room) (free ?gripper))
    :effect (and (carry ?obj ?gripper) (not (at ?obj ?room)) (not (free ?gripper))))
  (:action drop :parameters (?obj ?room ?gripper)
    :precondition (and (ball ?obj) (room ?room) (gripper ?gripper) (carry ?obj ?gripper) (at-robby ?room))
    :effect (and (at ?obj ?room) (free ?gripper) (not (carry ?obj ?gripper)))))
"""


def gripper_problem(balls: int) -> str:
    """Carry ``balls`` balls from room a to room b with two grippers: optimal length 4·⌈n/2⌉ + ... (A*
    with LM-cut expands a great many states past ten balls; LAMA-first solves it at once)."""
    names = [f"b{k}" for k in range(1, balls + 1)]
    init = ["(room a)", "(room b)", "(gripper left)", "(gripper right)", "(at-robby a)", "(free left)",
            "(free right)", *(f"(ball {n})" for n in names), *(f"(at {n} a)" for n in names)]
    return (f"(define (problem carry-{balls}) (:domain gripper)\n  (:objects a b left right {' '.join(names)})\n"
            f"  (:init {' '.join(init)})\n  (:goal (and {' '.join(f'(at {n} b)' for n in names)})))\n")
