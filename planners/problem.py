"""From a world state to a PDDL problem, and from a plan step back to its grounded effects.

:class:`DomainModel` holds what task types need of a checked domain (predicates and
their types, each action's parameters, effects and constant cost), read by
:mod:`planners.schema`.
:func:`render_problem` writes a standard PDDL problem: the world's objects whose type
the domain knows, the facts over them, travel times between places, and the goal.
"""

from __future__ import annotations

import math
import re
import threading
from collections import OrderedDict
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from planners.checks import CheckedDomain, PddlError
from planners.schema import DomainSchema, SchemaError, read_schema
from tasker.world import Fact, MotionModel, Pose, WorldState

PLACE_TYPE = "place"
TRAVEL_FUNCTION = "travel-time"
CONNECTED = "connected"
UNREACHABLE_COST = 1_000_000
"""``travel-time`` written for a pair that is not connected (it can never be used)."""
RENDERED = 512
"""How many rendered problems each domain remembers (:func:`render_problem`)."""


class DomainModel:
    """Read-only view of a checked domain, built once when a task folder is loaded.

    Its contents come from :func:`planners.schema.read_schema` (Fast Downward's parser),
    so building one imports neither unified-planning nor pyparsing.
    """

    def __init__(self, domain: CheckedDomain) -> None:
        schema = self._schema(domain)
        self.checked = domain
        self.name = schema.name
        self.types: dict[str, set[str]] = {name: set(chain) for name, chain in schema.types}
        self.predicates: dict[str, tuple[str, ...]] = dict(schema.predicates)
        self.functions = set(schema.functions)
        self.constants: dict[str, str] = dict(schema.constants)
        self.actions = {a.name: a for a in schema.actions}
        self.opens_doors = "door_between" in self.predicates and any(
            e.fluent == "open" and e.positive for a in schema.actions for e in a.effects)
        """The domain models doors its plans may open: a ``door_between`` predicate and an action that adds
        ``open``.  In a domain that does not, a closed door is a wall (:func:`closed_door_pairs`)."""
        # render_problem's answers by everything they are made of (a pure function of these)
        self.rendered: OrderedDict[tuple[Any, ...], tuple[str, frozenset[Fact]]] = OrderedDict()
        self.rendered_lock = threading.Lock()

    @staticmethod
    def _schema(domain: CheckedDomain) -> DomainSchema:
        """The domain's schema, read by Fast Downward's parser (a temporal domain's subclass,
        :class:`planners.temporal.folder.TemporalDomainModel`, reads it from UP's model)."""
        try:
            return read_schema(domain.text)
        except SchemaError as exc:
            raise PddlError(domain.path, f"Fast Downward's parser refuses the domain: {exc}") from None

    def has_type(self, obj_type: str, wanted: str) -> bool:
        return wanted == "" or wanted in self.types.get(obj_type, ())

    def check_literal(self, lit: Sequence[str], where: str) -> None:
        """Raise if a literal names an unknown predicate or has the wrong arity."""
        atom = lit[1:] if lit[0] == "not" else lit
        if atom[0] not in self.predicates:
            raise PddlError(self.checked.path, f"{where}: unknown predicate {atom[0]!r}; the domain declares "
                                               f"{sorted(self.predicates)}")
        if len(atom) - 1 != len(self.predicates[atom[0]]):
            raise PddlError(self.checked.path, f"{where}: {atom[0]!r} takes {len(self.predicates[atom[0]])} "
                                               f"argument(s), got {len(atom) - 1}: {list(lit)}")

    def unmet(self, action: str, args: Sequence[str], facts: frozenset[Fact] | set[Fact]) -> list[Fact] | None:
        """The literals of ``action``'s precondition, grounded with ``args``, that do not hold in
        ``facts`` (empty: it can run); None when the precondition is not a plain conjunction of
        literals (it is then not decided here)."""
        model = self.actions[action]
        if model.precondition is None:
            return None
        binding = {f"?{p}": a for p, a in zip(model.params, args, strict=True)}
        out: list[Fact] = []
        for lit in model.precondition:
            atom = tuple(binding.get(x, x) for x in lit.args)
            if lit.fluent == "=":
                ok = (len(set(atom)) == 1) == lit.positive
            else:
                ok = ((lit.fluent, *atom) in facts) == lit.positive
            if not ok:
                out.append((lit.fluent, *atom) if lit.positive else ("not", lit.fluent, *atom))
        return out

    def ground(self, action: str, args: Sequence[str]) -> tuple[list[Fact], list[Fact]]:
        """``(add, delete)`` of an action applied with ``args`` (PDDL semantics: delete first)."""
        model = self.actions[action]
        binding = {f"?{p}": a for p, a in zip(model.params, args, strict=True)}
        add = [(e.fluent, *(binding.get(x, x) for x in e.args)) for e in model.effects if e.positive]
        delete = [(e.fluent, *(binding.get(x, x) for x in e.args)) for e in model.effects if not e.positive]
        return add, [d for d in delete if d not in add]


def travel_table(world: WorldState, motion: MotionModel | None, travel_s: float, *,
                 opens_doors: bool) -> dict[tuple[str, str], float]:
    """Seconds between every ordered pair of places; ``inf`` when the motion model says unreachable
    (walled off, or behind a closed door: people in the way only slow a leg, :func:`_past_people`).

    Without a motion model (or a pose) the declared ``travel_s`` is used, never zero.
    When the domain ``opens_doors`` (:attr:`DomainModel.opens_doors`), pairs joined by a
    ``door_between`` fact whose door is closed now (no ``open`` fact) are timed
    with the motion model's optional ``estimate_ignoring_doors`` (``robot.estimator.MotionEstimator``
    has it): the plan may open it.  Through an open door a leg is timed like any other, people
    and all (:func:`closed_door_pairs`).  A motion model
    with a ``table(poses)`` method (the same class) gives the whole matrix in one pass.
    """
    places = sorted(n for n, t in world.objects.items() if t == PLACE_TYPE)
    # places joined by a door the domain models and closed now: the plan decides whether to open it,
    # so their travel time is the geometry's with the door open (if the motion model can say it)
    through_door = closed_door_pairs(world, opens_doors=opens_doors)
    ignoring_doors = getattr(motion, "estimate_ignoring_doors", None)
    out: dict[tuple[str, str], float] = {}
    table = getattr(motion, "table", None)  # a whole matrix in one pass (robot.estimator.MotionEstimator)
    posed = [n for n in places if n in world.poses]
    if table is not None and len(posed) > 1:
        matrix = table([world.poses[n] for n in posed])
        out = {(a, b): float(matrix[i][j]) for i, a in enumerate(posed) for j, b in enumerate(posed) if a != b}
    for a in places:
        for b in places:
            if a == b:
                continue
            if (a, b) in out and (a, b) not in through_door:
                continue
            if motion is not None and a in world.poses and b in world.poses:
                estimate = ignoring_doors if (a, b) in through_door and ignoring_doors else motion.estimate
                out[a, b] = float(estimate(world.poses[a], world.poses[b]).time_s)
            else:
                out[a, b] = float(travel_s)
    _from_robot(world, motion, out, through_door, ignoring_doors)
    _past_people(world, motion, out)
    return out


def closed_door_pairs(world: WorldState, *, opens_doors: bool) -> set[tuple[str, str]]:
    """Ordered pairs of places a ``door_between`` fact joins through a door that is not ``open`` now, when
    the domain ``opens_doors``; none when it does not (its plans cannot open one: a closed door is a wall,
    timed as the motion model says, and the world's door facts describe the house, not the task)."""
    if not opens_doors:
        return set()
    return {(f[2], f[3]) for f in world.matching("door_between") if len(f) == 4 and ("open", f[1]) not in world.facts}


def _past_people(world: WorldState, motion: MotionModel | None, out: dict[tuple[str, str], float]) -> None:
    """A leg unreachable only because people are in the way now is timed as if they were not.

    People move: someone standing in a doorway blocks it only while they stand there, and
    the ``navigate`` skill waits for them to clear (it fails only after making no progress
    for a while).  Making the leg unreachable would make ``upTsk`` unsolvable — the task
    failed — on a moment's crowding.  With a motion model's optional
    ``estimate_ignoring_people`` (doors as they are; ``robot.estimator.MotionEstimator`` has
    it), such a leg gets the free building's time; a leg behind a closed door, or walled
    off, stays ``inf``.
    """
    ignoring_people = getattr(motion, "estimate_ignoring_people", None)
    if ignoring_people is None:
        return
    robot = _robot_where(world)
    for (a, b), secs in sorted(out.items()):
        if math.isfinite(secs) or b not in world.poses:
            continue
        start = robot[1] if robot is not None and robot[0] == a else world.poses.get(a)
        if start is not None:
            out[a, b] = float(ignoring_people(start, world.poses[b]).time_s)


def _from_robot(world: WorldState, motion: MotionModel | None, out: dict[tuple[str, str], float],
                through_door: set[tuple[str, str]], ignoring_doors: Callable[..., Any] | None) -> None:
    """Legs leaving the robot's place start where the robot *is*, not at the place's pose.

    The robot's ``at`` fact is its nearest place, which may be metres away (a navigation
    interrupted between places); timing its first leg from the place's pose can price a
    direct leg through people standing *there* and make the planner detour through another
    place, while the robot itself is already past them.
    """
    robot = _robot_where(world)
    if robot is None or motion is None:
        return
    a, here = robot
    for b in sorted(n for n, t in world.objects.items() if t == PLACE_TYPE):
        if b == a or b not in world.poses:
            continue
        estimate = ignoring_doors if ((a, b) in through_door and ignoring_doors is not None) else motion.estimate
        out[a, b] = float(estimate(here, world.poses[b]).time_s)


def _robot_where(world: WorldState) -> tuple[str, Pose] | None:
    """The robot's place (its one ``at`` fact) and its pose, or None when either is unknown."""
    robots = sorted(n for n, t in world.objects.items() if t == "robot")
    if not robots or robots[0] not in world.poses:
        return None
    at = [f[2] for f in world.facts if len(f) == 3 and f[0] == "at" and f[1] == robots[0]]
    return (at[0], world.poses[robots[0]]) if len(at) == 1 else None


def _atom(fact: Iterable[str]) -> str:
    return "(" + " ".join(fact) + ")"


def render_problem(
    domain: DomainModel,
    world: WorldState,
    goal: Sequence[Sequence[str]],
    *,
    extra_facts: Iterable[Fact] = (),
    travel: Mapping[tuple[str, str], float] | None = None,
    name: str = "task",
) -> tuple[str, frozenset[Fact]]:
    """A PDDL problem for ``domain`` from ``world``; also returns the init facts used.

    Objects of types the domain does not know, and facts over predicates it does not
    declare, are left out: the world holds facts for every task.  A fact with the right
    predicate but the wrong arity is an error.  The domain's constants are objects too
    (declared by the domain, so a world object of the same name is not declared again).

    Remembered per domain (the last ``RENDERED`` answers): the same facts, objects, goal,
    travel times and name give the same text, so a repeat costs building the key.
    """
    extra = tuple(extra_facts)
    key = (world.facts, tuple(world.objects.items()), tuple(map(tuple, goal)), tuple(map(tuple, extra)),
           None if travel is None else tuple(travel.items()), name)
    with domain.rendered_lock:
        done = domain.rendered.get(key)
        if done is not None:
            domain.rendered.move_to_end(key)
            return done
    done = _render_problem(domain, world, goal, extra, travel, name)
    with domain.rendered_lock:
        domain.rendered[key] = done
        while len(domain.rendered) > RENDERED:
            domain.rendered.popitem(last=False)
    return done


def _render_problem(domain: DomainModel, world: WorldState, goal: Sequence[Sequence[str]], extra_facts: Iterable[Fact],
                    travel: Mapping[tuple[str, str], float] | None, name: str) -> tuple[str, frozenset[Fact]]:
    known = {**domain.constants, **{n: t for n, t in sorted(world.objects.items()) if t in domain.types}}
    objects = {n: t for n, t in known.items() if n not in domain.constants}
    init: set[Fact] = set()
    for fact in [*world.facts, *extra_facts]:
        sig = domain.predicates.get(fact[0]) if fact else None
        if sig is None:
            continue
        if len(fact) - 1 != len(sig):
            raise PddlError(domain.checked.path, f"world fact {list(fact)}: {fact[0]!r} takes {len(sig)} argument(s)")
        if all(a in known and domain.has_type(known[a], t) for a, t in zip(fact[1:], sig, strict=True)):
            init.add(tuple(fact))
    numeric = []
    timed = TRAVEL_FUNCTION in domain.functions
    if travel is not None and (timed or CONNECTED in domain.predicates):  # either may be declared alone
        places = [n for n, t in sorted(known.items()) if domain.has_type(t, PLACE_TYPE)]
        for a in places:
            for b in places:
                # Every pair gets a value so UP's simulator and validator accept the problem;
                # pairs that are not `connected` (itself, unreachable) can never be travelled.
                secs = travel.get((a, b), math.inf)
                if math.isfinite(secs):
                    if CONNECTED in domain.predicates:
                        init.add((CONNECTED, a, b))
                    value = max(1, math.ceil(secs))
                else:
                    value = 0 if a == b else UNREACHABLE_COST
                if timed:
                    numeric.append(f"(= ({TRAVEL_FUNCTION} {a} {b}) {value})")
    by_type: dict[str, list[str]] = {}
    for n, t in objects.items():
        by_type.setdefault(t, []).append(n)
    lines = [f"(define (problem {name})", f"  (:domain {domain.name})", "  (:objects"]
    lines += [f"    {' '.join(ns)} - {t}" for t, ns in sorted(by_type.items())]
    lines.append("  )")
    lines.append("  (:init")
    lines += [f"    {_atom(f)}" for f in sorted(init)]
    lines += [f"    {n}" for n in numeric]
    if "total-cost" in domain.functions:
        lines.append("    (= (total-cost) 0)")
    lines.append("  )")
    goals = [f"(not {_atom(g[1:])})" if g[0] == "not" else _atom(g) for g in goal]
    lines.append(f"  (:goal (and {' '.join(goals)}))")
    if "total-cost" in domain.functions:
        lines.append("  (:metric minimize (total-cost))")
    lines.append(")")
    return "\n".join(lines) + "\n", frozenset(init)


def holds(facts: frozenset[Fact] | set[Fact], literals: Iterable[Sequence[str]]) -> bool:
    """True if every literal holds among ``facts`` (``["not", ...]`` means absent)."""
    return all((tuple(lit[1:]) not in facts) if lit[0] == "not" else (tuple(lit) in facts) for lit in literals)


# ------------------------------------------------------------------ PDDL any reader accepts

_OBJECTS_SECTION = re.compile(r"\(:objects(.*?)\)", re.S)


@dataclass(frozen=True, slots=True)
class PortablePddl:
    """A domain and problem renamed so that a default ``PDDLReader`` reads them.

    PDDL keeps types, predicates, actions and objects in separate namespaces (an object
    ``robot`` of type ``robot``, an action ``place`` beside a type ``place``);
    unified-planning refuses a name used twice.  ``renamed`` maps each original name to
    the one written; :meth:`original` maps a written plan step back.
    """

    domain: str
    problem: str
    renamed: Mapping[str, str]

    def written(self, step: Sequence[str]) -> tuple[str, ...]:
        return tuple(self.renamed.get(s, s) for s in step)

    def original(self, step: Sequence[str]) -> tuple[str, ...]:
        back = {v: k for k, v in self.renamed.items()}
        return tuple(back.get(s, s) for s in step)


def portable(domain: DomainModel, domain_text: str, problem_text: str) -> PortablePddl:
    """Rename actions and problem objects whose names a domain's types, predicates or
    functions already use (``robot`` → ``robot-obj``, action ``place`` → ``place-action``)."""
    domain_names = set(domain.types) | set(domain.predicates) | set(domain.functions)
    section = _OBJECTS_SECTION.search(problem_text)
    objects = set(_names(section.group(1))) if section else set()
    taken = domain_names | set(domain.actions) | objects
    renamed: dict[str, str] = {}

    def fresh(name: str, suffix: str) -> str:
        new, i = f"{name}-{suffix}", 1
        while new in taken:
            i += 1
            new = f"{name}-{suffix}{i}"
        taken.add(new)
        return new

    for action in sorted(domain.actions):
        if action in domain_names:
            renamed[action] = fresh(action, "action")
    for obj in sorted(objects):
        if obj in domain_names or obj in domain.actions:
            renamed[obj] = fresh(obj, "obj")
    for action in (a for a in renamed if a in domain.actions):
        domain_text = re.sub(rf"(\(:action\s+){re.escape(action)}(?=[\s)])", rf"\g<1>{renamed[action]}",
                             domain_text)
    head_end = problem_text.find("(:objects")
    head, body = (problem_text[:head_end], problem_text[head_end:]) if head_end >= 0 else ("", problem_text)
    for obj in (o for o in renamed if o in objects):
        # every use of the object after the header, but not a type after " - " in :objects
        body = re.sub(rf"(?<![\w?-])(?<!- ){re.escape(obj)}(?![\w-])", renamed[obj], body)
    problem_text = head + body
    if renamed:
        note = "; renamed for unified-planning's PDDLReader: " + ", ".join(
            f"{k} -> {v}" for k, v in sorted(renamed.items())) + "\n"
        problem_text = note + problem_text
    return PortablePddl(domain_text, problem_text, renamed)


def _names(objects_section: str) -> list[str]:
    """Object names of a ``:objects`` section (the words that are not types after ``-``)."""
    words = objects_section.split()
    return [w for i, w in enumerate(words) if w != "-" and (i == 0 or words[i - 1] != "-")]
