"""Small PDDL tasks written for these tests: legal PDDL that unified-planning's reader cannot read,
one with axioms, and a gripper problem of any size (hard for A* with LM-cut, easy for LAMA).

Each reader-limit case carries the plan expected of it, worked out by hand."""

from __future__ import annotations

from dataclasses import dataclass

from tests.planners.conftest import DOMAIN, problem_text


@dataclass(frozen=True)
class Case:
    domain: str
    problem: str
    plan: tuple[tuple[str, ...], ...]
    refusal: str  # what unified-planning's refusal says (a fragment)


EITHER = Case("""\
(define (domain either-move)
  (:requirements :strips :typing)
  (:types robot box place)
  (:predicates (at ?x - (either robot box) ?p - place) (link ?a ?b - place) (holding ?b - box))
  (:action go :parameters (?r - robot ?a ?b - place)
    :precondition (and (at ?r ?a) (link ?a ?b))
    :effect (and (not (at ?r ?a)) (at ?r ?b)))
  (:action pick :parameters (?r - robot ?x - box ?p - place)
    :precondition (and (at ?r ?p) (at ?x ?p))
    :effect (and (not (at ?x ?p)) (holding ?x))))
""", """\
(define (problem fetch) (:domain either-move)
  (:objects r - robot b - box k h - place)
  (:init (at r k) (at b h) (link k h))
  (:goal (holding b)))
""", (("go", "r", "k", "h"), ("pick", "r", "b", "h")), "declare a common supertype")

DERIVED = Case("""\
(define (domain derived-door)
  (:requirements :strips :derived-predicates)
  (:predicates (at ?p) (link ?a ?b) (open ?a ?b) (passable ?a ?b))
  (:derived (passable ?a ?b) (and (link ?a ?b) (open ?a ?b)))
  (:action go :parameters (?a ?b)
    :precondition (and (at ?a) (passable ?a ?b))
    :effect (and (not (at ?a)) (at ?b)))
  (:action open-door :parameters (?a ?b)
    :precondition (and (at ?a) (link ?a ?b))
    :effect (open ?a ?b)))
""", """\
(define (problem through) (:domain derived-door)
  (:objects k h)
  (:init (at k) (link k h))
  (:goal (at h)))
""", (("open-door", "k", "h"), ("go", "k", "h")), ":derived predicates")

REPEATED = Case("""\
; a predicate that names its parameter twice, as IPC's logistics00 does: legal PDDL
(define (domain load-in)
  (:requirements :strips)
  (:predicates (box ?x) (truck ?x) (at ?x ?l)
               (in ?obj ?obj))
  (:action load :parameters (?b ?t ?l)
    :precondition (and (box ?b) (truck ?t) (at ?b ?l) (at ?t ?l))
    :effect (and (not (at ?b ?l)) (in ?b ?t))))
""", """\
(define (problem load) (:domain load-in)
  (:objects b t l)
  (:init (box b) (truck t) (at b l) (at t l))
  (:goal (in b t)))
""", (("load", "b", "t", "l"),), "predicate in names parameter ?obj twice")

GLUED = Case("""\
; a name glued to its variable, as IPC's zenotravel writes (aircraft?a): PDDL reads (aircraft ?a)
(define (domain glued)
  (:requirements :strips)
  (:predicates (robot ?r) (at ?r ?p) (link ?a ?b))
  (:action go :parameters (?r ?a ?b)
    :precondition (and (robot?r) (at ?r ?a) (link ?a ?b))
    :effect (and (not (at ?r ?a)) (at ?r ?b))))
""", """\
(define (problem hop) (:domain glued)
  (:objects r k h)
  (:init (robot r) (at r k) (link k h))
  (:goal (at r h)))
""", (("go", "r", "k", "h"),), "robot?r: a name and a variable without a space between them")

NO_COST_INIT = Case(DOMAIN, problem_text().replace("(= (total-cost) 0) ", ""),
                    (("pick", "cup", "a"), ("move", "a", "b"), ("move", "b", "c"), ("drop", "cup", "c")),
                    "does not set (= (total-cost) 0)")
"""The planner tests' delivery task, its problem without ``(= (total-cost) 0)`` (as IPC's tetris)."""

READER_LIMITS = {"either": EITHER, "derived": DERIVED, "repeated parameter": REPEATED,
                 "no total-cost init": NO_COST_INIT, "glued variable": GLUED}

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
