"""What a task means for safety and for people: hazards, people's roles, physical bindings.

A task folder declares them (``docs/domains.md``); a :class:`~tasker.task.TaskType`
exposes them as :attr:`~tasker.task.TaskType.meaning` (empty by default).  Nothing here
knows a task: patterns are literals over the task's predicates, written with

* ``$name`` — the request argument ``name`` (``$robot``: the robot's object name);
* ``?x`` — any object (the same ``?x`` twice must be the same object);
* anything else — that object.

The :class:`Monitor` evaluates every live agent's declared patterns against the
world's facts after each tick in which something changed, and writes an edge to the
trace whenever one becomes true or false — whatever made it so (the task, another
task, a person, a world event).  Metrics read those events, never task names.
Stdlib only.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

from tasker import events as ev

Literal = tuple[str, ...]
Fact = tuple[str, ...]

ROLES = ("waiting", "following", "told_to_wait", "needs_help", "helped")
"""People's roles a task may declare: the person waits for the robot, follows it, has been
told to wait, needs help; ``helped`` marks the moment help was given (time-to-help)."""

BINDING_KINDS = ("device", "door", "held", "follower", "waiting")
"""Physical state a fact may be bound to: a device's state, a door's open/closed, an object
held by the robot, a person following the robot, a person standing still waiting."""

CMD_STATES = frozenset({"upTsk", "exeTsk", "genSusp", "exeSusp"})
"""Leaves of ``cmd`` (Fig. 5): the agent is ``exeDA`` and attends to what its task started."""


@dataclass(frozen=True, slots=True)
class Hazard:
    """A fact pattern that is unsafe while nobody attends to it, for at most ``budget_s``."""

    name: str
    fact: Literal
    budget_s: float
    severity: float = 1.0
    label: str = ""

    def __post_init__(self) -> None:
        if not self.name.isidentifier():
            raise ValueError(f"Hazard.name must be an identifier, got {self.name!r}")
        if not self.fact or self.fact[0] == "not":
            raise ValueError(f"Hazard {self.name!r}: fact must be a positive literal, got {list(self.fact)}")
        if not (math.isfinite(self.budget_s) and self.budget_s >= 0):
            raise ValueError(f"Hazard {self.name!r}: budget_s must be a finite number >= 0, got {self.budget_s!r}")
        if not (math.isfinite(self.severity) and self.severity >= 0):
            raise ValueError(f"Hazard {self.name!r}: severity must be a finite number >= 0, got {self.severity!r}")


@dataclass(frozen=True, slots=True)
class People:
    """Which request argument names the person, and which literals mean each role.

    A role holds while the agent is alive and *any* of its literals holds
    (``["not", ...]`` holds when no fact matches)."""

    person: str
    roles: Mapping[str, tuple[Literal, ...]] = field(default_factory=dict)
    safe: tuple[str, ...] = ()
    """The roles the person may be left in when the task is suspended (a derived suspension
    plans until the person holds one of them); empty: the folder says nothing about it."""

    def __post_init__(self) -> None:
        unknown = sorted(set(self.roles) - set(ROLES))
        if unknown:
            raise ValueError(f"People: unknown role(s) {unknown}; known: {list(ROLES)}")
        undeclared = [r for r in self.safe if r not in self.roles]
        if undeclared:
            raise ValueError(f"People: safe role(s) {undeclared} are not declared; declared: {sorted(self.roles)}")


@dataclass(frozen=True, slots=True)
class Binding:
    """A fact the world derives from physical state instead of storing it.

    ``fact`` has ``?vars`` only; ``object`` is the variable naming the physical thing
    (a device, door, object or person); other variables are the robot.  ``types`` are
    the object types the binding applies to (empty: any).  For a ``device``, the fact
    holds while the device's state is ``state``; removing it sets ``otherwise``."""

    kind: str
    fact: Literal
    object: str
    types: tuple[str, ...] = ()
    state: str = "on"
    otherwise: str = "off"

    def __post_init__(self) -> None:
        if self.kind not in BINDING_KINDS:
            raise ValueError(f"Binding.kind must be one of {list(BINDING_KINDS)}, got {self.kind!r}")
        if self.object not in self.fact[1:]:
            raise ValueError(f"Binding {list(self.fact)}: object {self.object!r} is not one of its variables")

    @property
    def predicate(self) -> str:
        return self.fact[0]

    def object_of(self, fact: Sequence[str]) -> str | None:
        """The physical thing a ground fact of this binding is about (None: not this binding's)."""
        if len(fact) != len(self.fact) or fact[0] != self.fact[0]:
            return None
        return str(fact[self.fact.index(self.object)])

    def ground(self, obj: str, robot: str) -> Fact:
        """The fact for ``obj`` (other variables are the robot)."""
        return tuple(obj if tok == self.object else (robot if tok.startswith("?") else tok) for tok in self.fact)


@dataclass(frozen=True, slots=True)
class Meaning:
    """Everything a task type declares about what it means: hazards, people, bindings."""

    hazards: tuple[Hazard, ...] = ()
    people: People | None = None
    bindings: tuple[Binding, ...] = ()

    def __post_init__(self) -> None:
        names = [h.name for h in self.hazards]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise ValueError(f"Meaning: duplicate hazard name(s) {dup}")


NO_MEANING = Meaning()


@dataclass(frozen=True, slots=True)
class ActiveHazard:
    """A hazard that holds now: whose it is, which one, since when (simulated s), and its budget.

    What :meth:`Monitor.active` gives the harmoniser for hazard-aware waiting
    (:class:`tasker.harmoniser.TaskHarmoniser`).  ``agent`` is None for a hazard nobody owns."""

    agent: str | None
    name: str
    fact: Fact
    budget_s: float
    since: float


# -- patterns ---------------------------------------------------------------------------


def bind(pattern: Sequence[str], args: Mapping[str, Any], robot: str) -> Literal | None:
    """Replace ``$arg`` and ``$robot``; None if an argument is missing (the pattern cannot apply)."""
    out = []
    for tok in pattern:
        if tok.startswith("$"):
            key = tok[1:]
            if key == "robot":
                out.append(robot)
                continue
            value = args.get(key)
            if value is None:
                return None
            out.append(str(value))
        else:
            out.append(tok)
    return tuple(out)


def matches(atom: Sequence[str], facts: Iterable[Fact]) -> list[Fact]:
    """The facts an atom with ``?vars`` matches, sorted."""
    n = len(atom)
    out = []
    for f in facts:
        if len(f) != n or f[0] != atom[0]:
            continue
        seen: dict[str, str] = {}
        for tok, val in zip(atom[1:], f[1:], strict=True):
            if tok.startswith("?"):
                if seen.setdefault(tok, val) != val:
                    break
            elif tok != val:
                break
        else:
            out.append(f)
    return sorted(out)


def holds(literal: Sequence[str], facts: Iterable[Fact]) -> bool:
    """A bound literal holds: some fact matches (``["not", ...]``: none does)."""
    if literal[0] == "not":
        return not matches(literal[1:], facts)
    return bool(matches(literal, facts))


# -- the monitor --------------------------------------------------------------------------


class AgentView(Protocol):
    """What the monitor reads of an agent (``tasker.agent.DynamicAgent`` has it)."""

    id: str

    @property
    def ended(self) -> bool: ...


class Monitor:
    """Writes ``hazard`` and ``role`` edges to the trace as declared patterns change.

    ``agents`` returns every agent created so far (ended ones too), in request order;
    ``meaning_of`` the :class:`Meaning` of a task type; ``facts`` the world's facts now
    (None without a world: then nothing is evaluated); ``robot`` the robot's name.
    Hazards of ``task_types`` (every type the run can request) are watched from the
    start.  A pattern without ``$args`` has one owner whichever types declare it: the
    agent whose stage made it true, else nobody (``agent: null``: a door open in the world
    file, or opened by a person).
    Call :meth:`observe` after each tick; it re-evaluates only when the facts or the
    set of live agents changed, and asks for the facts only when ``version`` (e.g. the
    world's clock and change counter) moved.  Edges are written in a fixed order (agent, hazard or
    role, arguments), so the trace stays deterministic.
    """

    def __init__(self, trace: Any, agents: Callable[[], Sequence[Any]], meaning_of: Callable[[str], Meaning],
                 facts: Callable[[], frozenset[Fact] | None], robot: Callable[[], str] = lambda: "robot",
                 task_types: Sequence[str] = (), version: Callable[[], Any] | None = None) -> None:
        self.trace = trace
        self._version = version
        self._seen: Any = None
        self.task_types = tuple(task_types)
        self._agents = agents
        self._meaning_of = meaning_of
        self._facts = facts
        self._robot = robot
        self._last: tuple[frozenset[Fact], tuple[tuple[str, bool], ...]] | None = None
        self._alive_memo: tuple[list[Any], list[int], tuple[tuple[str, bool], ...]] | None = None
        self.hazards: dict[tuple[str | None, str, Fact], Hazard] = {}
        self._since: dict[tuple[str | None, str, Fact], float] = {}  # when each active hazard went on
        self.roles: dict[tuple[str, str], str] = {}
        self._done_in_tick: list[str] = []
        self._held: tuple[Binding, ...] | None = None  # the held bindings of the run's task types
        self._live: set[str] = set()
        trace.subscribe(self._on_event)

    def _on_event(self, e: ev.Event) -> None:
        if isinstance(e, ev.StageChanged) and e.status == "done":
            self._done_in_tick.append(e.agent)

    def observe(self, now: float) -> None:
        made_by, self._done_in_tick = self._done_in_tick, []
        agents = list(self._agents())
        alive = self._alive(agents)
        if self._version is not None:  # the world says whether its facts can have changed
            seen = (self._version(), alive)
            if seen == self._seen:
                return
            self._seen = seen
        facts = self._facts()
        if facts is None:
            return
        if self._last is not None and self._last == (facts, alive):
            return
        self._last = (facts, alive)
        robot = self._robot()
        self._hazards(now, facts, agents, robot, made_by)
        self._people(now, facts, agents, robot)

    def _alive(self, agents: list[Any]) -> tuple[tuple[str, bool], ...]:
        """``(id, ended)`` of every agent: the last answer again when the list holds the same
        agents and none of those live then has ended since (an ended agent never lives again),
        so a tick costs a look at the live agents, not at every agent of the run."""
        memo = self._alive_memo
        if memo is not None and agents == memo[0] and not any(agents[i].ended for i in memo[1]):
            return memo[2]
        alive = tuple((a.id, bool(a.ended)) for a in agents)
        self._alive_memo = (agents, [i for i, (_, ended) in enumerate(alive) if not ended], alive)
        return alive

    def _hazards(self, now: float, facts: frozenset[Fact], agents: list[Any], robot: str, made_by: list[str]) -> None:
        found: dict[tuple[str | None, str, Fact], Hazard] = {}
        by_type: dict[str, list[Any]] = {t: [] for t in self.task_types}
        for a in agents:
            by_type.setdefault(a.ctx.task_type, []).append(a)
        # patterns without $args, across every type that declares one: (name, fact) -> the
        # declaring types' hazards, so that one fact has one owner whoever declares it
        shared: dict[tuple[str, Fact], dict[str, Hazard]] = {}
        for task_type, members in by_type.items():
            for hz in self._meaning_of(task_type).hazards:
                if any(tok.startswith("$") and tok != "$robot" for tok in hz.fact):
                    for a in members:  # owned by the agent whose arguments bind it (even once ended)
                        atom = bind(hz.fact, a.ctx.args, robot)
                        if atom is not None:
                            for f in matches(atom, facts):
                                found[(a.id, hz.name, f)] = hz
                    continue
                atom = bind(hz.fact, {}, robot)
                assert atom is not None
                for f in matches(atom, facts):
                    shared.setdefault((hz.name, f), {}).setdefault(task_type, hz)
        type_of = {a.id: a.ctx.task_type for a in agents}
        for (name, f), declared in shared.items():
            owner = self._owner(name, f, declared, type_of, made_by)
            found[(owner, name, f)] = declared[type_of[owner]] if owner is not None else next(iter(declared.values()))
        for key in sorted(set(self.hazards) - set(found), key=_order):
            self._since.pop(key, None)
            self._emit_hazard(now, key, self.hazards.pop(key), "off")
        for key in sorted(set(found) - set(self.hazards), key=_order):
            self.hazards[key] = found[key]
            self._since[key] = now
            self._emit_hazard(now, key, found[key], "on")

    def active(self) -> tuple[ActiveHazard, ...]:
        """The hazards that hold now (as of the last :meth:`observe`), in the trace's order.

        A callable the runner gives the harmoniser (``TaskHarmoniser.hazards``): the model
        learns of hazards through it, never from a task's name."""
        return tuple(ActiveHazard(key[0], key[1], key[2], self.hazards[key].budget_s, self._since[key])
                     for key in sorted(self.hazards, key=_order))

    def _owner(self, name: str, fact: Fact, declared: Mapping[str, Hazard], type_of: Mapping[str, str],
               made_by: list[str]) -> str | None:
        """For a pattern without ``$args``: who already owns it, else the agent of a declaring
        type whose stage made it true in this tick, else nobody — a door open in the world
        file, opened by a person or by a task that does not declare it, is nobody's."""
        for (agent, hname, f) in self.hazards:
            if hname == name and f == fact:
                return agent
        for agent in made_by:
            if type_of.get(agent) in declared:
                return agent
        return None

    def _emit_hazard(self, now: float, key: tuple[str | None, str, Fact], hz: Hazard, status: str) -> None:
        agent, name, fact = key
        self.trace.emit(ev.HazardChanged(now, agent, name, list(fact[1:]), list(fact), status, hz.budget_s,
                                         hz.severity, True if self._carried(fact) else None))

    def _carried(self, fact: Fact) -> bool:
        """Whether ``fact`` is something the robot holds: a ``held`` binding of a type the run knows."""
        if self._held is None:
            self._held = tuple(b for t in self.task_types for b in self._meaning_of(t).bindings if b.kind == "held")
        return any(b.object_of(fact) is not None for b in self._held)

    def _people(self, now: float, facts: frozenset[Fact], agents: list[Any], robot: str) -> None:
        """Roles of live agents; an agent that ended since the last look is evaluated once
        more (a role its last stage made true, such as ``helped``, is seen), then all its
        roles go off."""
        found: dict[tuple[str, str], str] = {}
        ended_now = [a.id for a in agents if a.ended and a.id in self._live]
        for a in agents:
            if a.ended and a.id not in self._live:
                continue
            people = self._meaning_of(a.ctx.task_type).people
            if people is None:
                continue
            person = str(a.ctx.args.get(people.person, ""))
            for role in ROLES:
                for lit in people.roles.get(role, ()):
                    atom = bind(lit, a.ctx.args, robot)
                    if atom is not None and holds(atom, facts):
                        found[(a.id, role)] = person
                        break
        for key in sorted(set(self.roles) - set(found)):
            self.trace.emit(ev.RoleChanged(now, key[0], key[1], self.roles.pop(key), "off"))
        for key in sorted(set(found) - set(self.roles)):
            self.roles[key] = found[key]
            self.trace.emit(ev.RoleChanged(now, key[0], key[1], found[key], "on"))
        for key in sorted(k for k in self.roles if k[0] in ended_now):
            self.trace.emit(ev.RoleChanged(now, key[0], key[1], self.roles.pop(key), "off"))
        self._live = {a.id for a in agents if not a.ended}


def _order(key: tuple[str | None, str, Fact]) -> tuple[str, str, Fact]:
    return (key[0] or "", key[1], key[2])
