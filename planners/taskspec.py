"""``task.toml``: the declarative part of a task folder, read into frozen dataclasses.

It is read strictly with :mod:`tasker.support.reader`: every fault (an unknown key or table
such as ``kindd`` or ``[shedule]`` included) is a :class:`~planners.checks.DefinitionError`
naming ``task.toml``, the line, the field and what was expected, with a "did you mean".
The format is documented, with an example, in ``docs/domains.md``.
Literals are lists of strings, like the world's facts: ``["at", "$person", "$destination"]``,
negated as ``["not", "following", "$person"]``; ``$name`` is a request argument,
``$robot`` the robot, ``$at:name`` the place where ``name`` is; ``?param`` (in
``[actions]``) a parameter of the PDDL action.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from planners.checks import DefinitionError
from planners.specreader import (
    DEFAULT_TREE,
    Branch,
    Literal,
    SpecReader,
    StageTemplate,
    as_definition_error,
    read_trees,
)
from tasker.errors import BadRequest, ConfigError, UnknownName
from tasker.meaning import BINDING_KINDS, ROLES, Binding, Hazard, Meaning, People
from tasker.stage import StageKind
from tasker.support import reader
from tasker.task import ArgSpec

SKILLS = ("navigate", "say", "manipulate", "wait")

RESERVED_ARGS = {
    "robot": "$robot is the robot",
    "deadline": "a request field every task type takes (experiments.inputs.request_fields)",
    "priority": "a request field every task type takes (experiments.inputs.request_fields)",
    "death_at": "a request field every task type takes (experiments.inputs.request_fields)",
}
"""Argument names a task folder may not declare: the request fields would strip them from its own
arguments (every request would then lack them), and ``$robot`` names the robot."""

MAX_TIMEOUT_S = 24 * 3600.0
"""The longest wall-clock limit of one planner call: a larger one (1e300) overflowed the clock."""
"""Skills the core agent offers (the contract with ``robot/``)."""

COST_MODEL_ARG = "cost_model"
"""The request argument that chooses a task's cost model, when its folder offers a choice."""
COST_MODELS = ("seconds", "taskER-2019")
"""Cost models (``docs/model.md``): ``seconds``, ours and the default (costs that add, in
seconds); ``taskER-2019``, the original TaskER code's (path metres weighted per person),
offered by a folder that declares ``[schedule.taskER-2019]``."""
ORIGINAL = COST_MODELS[1]



@dataclass(frozen=True, slots=True)
class ActionSpec:
    """How one PDDL action runs: skill, blocking or not, expected duration, skill parameters."""

    name: str
    skill: str
    kind: StageKind = StageKind.SUSPENDABLE
    duration: float | None = None
    travel: tuple[str, str] | None = None
    to: str | None = None
    text: str | None = None


@dataclass(frozen=True, slots=True)
class OriginalCosts:
    """``[schedule.taskER-2019]``: what the original TaskER code's cost model measures for this task.

    ``person`` is whom the robot goes to (leg *a*, the robot's path to them); ``destination``,
    if any, where it then takes them (leg *g*, their path there; the task ends there, else
    at the person).  ``walk``: literals that hold while the person walks with the robot;
    ``sit``: literals that hold once the person was greeted (the 2019 code asked them to sit
    and wait).  ``factors``: the request arguments giving the cost per metre while walking,
    standing (not yet greeted) and sitting; without them every factor is 1.
    ``planners.pddl_task`` computes the parameters; ``docs/model.md`` gives the formulas.
    """

    person: str
    destination: str | None = None
    walk: tuple[Literal, ...] = ()
    sit: tuple[Literal, ...] = ()
    factors: tuple[str, str, str] | None = None

    @property
    def args(self) -> tuple[str, ...]:
        """The request arguments of the model: the choice and the factors."""
        return (COST_MODEL_ARG, *(f[1:] for f in self.factors or ()))


@dataclass(frozen=True, slots=True)
class ExampleWorld:
    """A world state and request shipped with the task: for ``tasker fsm``, tests and benchmarks."""

    args: Mapping[str, Any]
    objects: Mapping[str, str]
    facts: tuple[Literal, ...]
    poses: Mapping[str, tuple[float, float, float]]


@dataclass(frozen=True, slots=True)
class TaskSpec:
    """Everything ``task.toml`` declares about a task type."""

    folder: Path
    name: str
    description: str
    domain_file: Path
    args: tuple[ArgSpec, ...]
    goal: tuple[Literal, ...]
    facts: tuple[Literal, ...]
    suspended_facts: tuple[Literal, ...]
    suspension: tuple[Branch, ...]
    actions: Mapping[str, ActionSpec]
    static_update: tuple[StageTemplate, ...]
    cps: float
    travel_s: float
    planning_time_s: float
    static_time_s: float
    timeout_s: float = 10.0
    priority: int | None = None
    """``[schedule] priority``: the type's priority class, higher is more urgent (None: the lowest)."""
    example: ExampleWorld | None = None
    hooks: Mapping[str, Any] = field(default_factory=dict)
    hazards: tuple[Hazard, ...] = ()
    people: People | None = None
    bindings: tuple[RawBinding, ...] = ()
    invariants: tuple[Literal, ...] = ()
    """``[derived] invariants``: facts that must hold whenever the task is suspended (derived strategy)."""
    restore: tuple[Literal, ...] = ()
    """``[problem] restore``: patterns of facts the task leaves as it found them — a ground instance
    that did not hold when the task first planned must not hold at its goal (a door it opened is
    closed again)."""
    original_costs: OriginalCosts | None = None
    """``[schedule.taskER-2019]``: the folder offers the original TaskER cost model."""
    lines: Mapping[str, int | None] = field(default_factory=dict)
    """Where each checked field is written (``"hazards[0].fact"`` -> line), for later checks."""
    trees: Mapping[str, tuple[Branch, ...]] = field(default_factory=dict)
    """``[[trees.NAME]]``: other decision trees besides ``[[suspension]]`` (the tree named
    :data:`DEFAULT_TREE`), written from other assumptions; ``Strategy.tree`` picks one."""

    @property
    def toml(self) -> Path:
        return self.folder / "task.toml"

    def tree(self, name: str | None) -> tuple[Branch, ...]:
        """The branches of tree ``name`` (None or :data:`DEFAULT_TREE`: ``[[suspension]]``)."""
        if name is None or name == DEFAULT_TREE:
            return self.suspension
        try:
            return self.trees[name]
        except KeyError:
            raise UnknownName(f"decision tree of task {self.name!r}", name, list(self.tree_names)) from None

    @property
    def tree_names(self) -> tuple[str, ...]:
        """Every tree's name, the default first."""
        return (DEFAULT_TREE, *sorted(self.trees))

    def all_trees(self) -> list[tuple[str, str, tuple[Branch, ...]]]:
        """``(name, where it is written, branches)`` of every tree: ``[[suspension]]`` first."""
        return [(DEFAULT_TREE, "suspension", self.suspension),
                *((n, f"trees.{n}", self.trees[n]) for n in sorted(self.trees))]

    def error(self, fieldname: str, message: str) -> DefinitionError:
        """A fault found after reading (against the domain), located like the reader's own."""
        return DefinitionError(self.toml, f"{fieldname}: {message}", self.lines.get(fieldname))

    def warn(self, fieldname: str, message: str) -> None:
        """Valid but doubtful, found after reading: an :class:`~tasker.support.reader.InputWarning`
        located like :meth:`error`."""
        reader.warn_at(self.toml, self.lines.get(fieldname), fieldname, message)


@dataclass(frozen=True, slots=True)
class RawBinding:
    """A ``[[bindings]]`` entry as written; the loader adds the object types from the domain."""

    kind: str
    fact: Literal
    object: str
    state: str = "on"
    otherwise: str = "off"

    def resolve(self, types: tuple[str, ...]) -> Binding:
        return Binding(self.kind, self.fact, self.object, types, self.state, self.otherwise)


def meaning_of(spec: TaskSpec, bindings: tuple[Binding, ...]) -> Meaning:
    """The :class:`~tasker.meaning.Meaning` a task type exposes."""
    return Meaning(spec.hazards, spec.people, bindings)


def _action(r: SpecReader, a: reader.Table, name: str) -> ActionSpec:
    skill = a.string("skill", choices=SKILLS)
    kind = StageKind(a.string("kind", "suspendable", choices=[k.value for k in StageKind]))
    travel = a.raw("travel", None)
    if travel is not None and (not isinstance(travel, list) or len(travel) != 2
                               or not all(isinstance(t, str) and t.startswith("?") for t in travel)):
        raise r.fail(a, "travel", f"expected two parameters [\"?from\", \"?to\"], got {travel!r}")
    travel = travel and [t.lower() for t in travel]  # PDDL parameters are case-insensitive
    duration = a.number("duration", None, min=0, max=reader.MAX_SECONDS)
    to = a.string("to", None)
    to = to.lower() if to and to.startswith("?") else to
    text = a.string("text", None)
    r.note(a)
    r.lines[f"actions.{name}.text"] = a.line("text")  # by the PDDL name: the loader checks the placeholders
    a.done()
    if skill == "navigate" and to is None:
        raise r.fail(a, None, "a navigate action needs 'to' (the parameter naming its target)")
    return ActionSpec(name, skill, kind, None if duration is None else float(duration),
                      tuple(travel) if travel else None, to, text)


def _args(r: SpecReader, top: reader.Table) -> tuple[ArgSpec, ...]:
    out: list[ArgSpec] = []
    first: dict[str, int | None] = {}
    for a in top.tables("args", []):
        name = a.string("name")
        if name in RESERVED_ARGS:
            raise r.fail(a, "name", f"{name!r} is reserved: {RESERVED_ARGS[name]}; name the argument otherwise")
        if name in first:  # a request's argument is one value: which declaration would it follow?
            where = f" (first at line {first[name]})" if first[name] else ""
            raise r.fail(a, "name", f"argument {name!r} is declared twice{where}")
        first[name] = a.line("name")
        choices = a.array("choices", nonempty=True) if "choices" in a else None
        try:
            out.append(ArgSpec(name=name, type=a.string("type", "str"), required=a.boolean("required", True),
                               default=a.raw("default", None), help=a.string("help", "", empty=True),
                               choices=tuple(choices) if choices is not None else None))
        except (ConfigError, TypeError) as exc:
            raise r.fail(a, None, str(exc)) from None
        for k, choice in enumerate(choices or ()):  # a choice of another type could never be given
            try:
                out[-1].coerce(name, choice)
            except BadRequest as exc:
                raise r.fail(a.at("choices", {}), k, str(exc).split(": ", 1)[-1].replace(
                    "expected one of", "a choice must be one of")) from None
        if choices is not None and len({repr(c) for c in choices}) != len(choices):
            dup = sorted({repr(c) for c in choices if [repr(x) for x in choices].count(repr(c)) > 1})
            a.warn("choices", f"{', '.join(dup)} listed more than once")
        if out[-1].default is not None:  # a request without the argument gets it: it must fit the type
            try:
                out[-1].coerce(name, out[-1].default)
            except BadRequest as exc:
                raise r.fail(a, "default", str(exc).split(": ", 1)[-1]) from None
        a.done()
    return tuple(out)


def _original_costs(r: SpecReader, schedule: reader.Table, top: reader.Table,
                    args: tuple[ArgSpec, ...]) -> OriginalCosts | None:
    """``[schedule.taskER-2019]``, checked against the declared request arguments: a folder that
    offers the model declares ``cost_model`` (choices: the models), and one that does not, does not."""
    by_name = {a.name: a for a in args}
    choice = by_name.get(COST_MODEL_ARG)
    if ORIGINAL not in schedule:
        if choice is not None:
            raise r.fail(top, "args", f"argument {COST_MODEL_ARG!r} chooses a cost model, and only a folder "
                                      f"with [schedule.{ORIGINAL}] offers another than {COST_MODELS[0]!r}")
        return None
    t = schedule.table(ORIGINAL)
    r.note(t)
    if choice is None or choice.required or choice.choices is None or set(choice.choices) != set(COST_MODELS):
        raise r.fail(t, None, f"a folder that offers the {ORIGINAL} cost model declares the optional argument "
                              f"{COST_MODEL_ARG!r} with choices = {list(COST_MODELS)}")

    def arg_token(key: str, kind: str) -> str:
        tok = t.string(key)
        if not tok.startswith("$") or tok[1:] not in by_name or by_name[tok[1:]].type != kind:
            raise r.fail(t, key, f"expected $name of a request argument of type {kind!r} "
                                 f"(declared: {', '.join('$' + a for a in by_name)}), got {tok!r}")
        return tok

    person = arg_token("person", "str")
    destination = arg_token("destination", "str") if "destination" in t else None
    factors: tuple[str, str, str] | None = None
    if "factors" in t:
        raw = t.raw("factors")
        if not isinstance(raw, list) or len(raw) != 3:
            raise r.fail(t, "factors", f"expected [\"$walk\", \"$stand\", \"$sit\"] (three request arguments), "
                                       f"got {raw!r}")
        names = []
        for k, tok in enumerate(raw):
            arg = by_name.get(tok[1:]) if isinstance(tok, str) and tok.startswith("$") else None
            if arg is None or arg.type != "float" or arg.required:
                raise r.fail(t, "factors", f"factors[{k}]: expected $name of an optional float argument, got {tok!r}")
            names.append(tok)
        factors = (names[0], names[1], names[2])
    out = OriginalCosts(person, destination, r.literals(t, "walk"), r.literals(t, "sit"), factors)
    t.done()
    return out


def _example(r: SpecReader, top: reader.Table) -> ExampleWorld | None:
    if "example" not in top:
        return None
    ex = top.table("example")
    r.note(ex)
    poses = {}
    for name, p in ex.table("poses", {}).items():
        if not isinstance(p, list) or len(p) not in (2, 3) or not all(isinstance(v, int | float) for v in p):
            raise r.fail(ex.table("poses"), name, f"a pose is [x, y] or [x, y, yaw], got {p!r}")
        poses[name] = (float(p[0]), float(p[1]), float(p[2]) if len(p) == 3 else 0.0)
    objects_t = ex.table("objects")
    objects = dict(objects_t.items())
    if not all(isinstance(v, str) for v in objects.values()):
        raise r.fail(ex, "objects", "maps object names to type names (strings)")
    facts = r.literals(ex, "facts")
    args = dict(ex.table("args", {}).items())
    ex.done()
    return ExampleWorld(args, objects, facts, poses)


def _hazards(r: SpecReader, top: reader.Table) -> tuple[Hazard, ...]:
    out = []
    for h in top.tables("hazards", []):
        name = h.string("name")
        fact_value = h.raw("fact")
        r.note(h, "fact")
        fact = r.literal(h, "fact", fact_value)
        if fact[0] == "not":
            raise r.fail(h, "fact", f"a hazard is a fact that holds (no 'not'), got {list(fact)}")
        budget = h.number("budget_s", min=0, max=reader.MAX_SECONDS)
        severity = h.number("severity", 1.0, min=0)
        try:
            out.append(Hazard(name, fact, float(budget), float(severity), h.string("label", "", empty=True)))
        except ValueError as exc:
            raise r.fail(h, "name", str(exc)) from None
        h.done()
    names = [x.name for x in out]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise r.fail(top, "hazards", f"duplicate hazard name(s) {dup}")
    facts = [x.fact for x in out]
    for k, x in enumerate(out):  # one unsafe condition declared twice would be counted twice by every metric
        if x.fact in facts[:k]:
            other = out[facts.index(x.fact)]
            raise r.fail(top.at("hazards", {}), k, f"hazard {x.name!r} has the fact of hazard {other.name!r} "
                                                   f"({list(x.fact)}): one condition, counted twice")
    return tuple(out)


def _people(r: SpecReader, top: reader.Table) -> People | None:
    if "people" not in top:
        return None
    p = top.table("people")
    person = p.string("person")
    r.note(p, "person")
    roles = {role: r.literals(p, role) for role in ROLES if role in p}
    safe = tuple(str(s) for s in p.array("safe", []))
    r.note(p, "safe")
    for k, role in enumerate(safe):
        if role not in roles:
            raise r.fail(p.at("safe", {}), k, f"{role!r} is not a role this [people] declares "
                                                f"({', '.join(sorted(roles)) or 'none'}){reader.suggest(role, roles)}")
    p.done()
    return People(person, roles, safe)


def _derived(r: SpecReader, top: reader.Table) -> tuple[Literal, ...]:
    """``[derived] invariants``: what must hold whenever the task is suspended (besides its hazards
    off and its person in a safe role), for the ``derived`` suspension strategy."""
    if "derived" not in top:
        return ()
    d = top.table("derived")
    invariants = r.literals(d, "invariants")
    d.done()
    return tuple(invariants)


def _bindings(r: SpecReader, top: reader.Table) -> tuple[RawBinding, ...]:
    out: list[RawBinding] = []
    where: dict[tuple[str, int], tuple[RawBinding, int | None]] = {}
    for b in top.tables("bindings", []):
        kind = b.string("kind", choices=BINDING_KINDS)
        fact = r.literal(b, "fact", b.raw("fact"))
        r.note(b, "fact")
        variables = [tok for tok in fact[1:] if tok.startswith("?")]
        if fact[0] == "not" or len(variables) != len(fact) - 1 or not variables:
            raise r.fail(b, "fact", f"a binding is a fact whose arguments are all ?variables, got {list(fact)}")
        obj = b.string("object", variables[-1])
        if obj not in variables:
            raise r.fail(b, "object", f"expected one of the fact's variables {variables}, got {obj!r}"
                                      f"{reader.suggest(obj, variables)}")
        state = b.string("state", "on") if kind == "device" else "on"
        otherwise = b.string("otherwise", "off") if kind == "device" else "off"
        if state == otherwise:  # removing the fact would leave it holding: the device could never say it ended
            raise r.fail(b, "otherwise" if "otherwise" in b else "state",
                         f"state and otherwise are both {state!r}: the fact would hold in either state, and a "
                         "stage that removes it would change nothing")
        b.done()
        raw = RawBinding(kind, fact, obj, state, otherwise)
        same = where.get((fact[0], len(fact)))
        if same is not None:  # the world reads a fact from one physical state: which one?
            other, line = same
            at = f" (line {line})" if line else ""
            if (other.kind, other.fact.index(other.object), other.state, other.otherwise) != (
                    kind, fact.index(obj), state, otherwise):
                raise r.fail(b, "fact", f"{fact[0]!r} is bound twice, differently: as {other.kind} of "
                                        f"{other.object}{at} and as {kind} of {obj}; a fact is one physical state")
            b.warn("fact", f"{fact[0]!r} is bound twice{at}, the same way: one [[bindings]] entry is enough")
            continue
        where[(fact[0], len(fact))] = (raw, b.line("fact"))
        out.append(raw)
    return tuple(out)


def read_task_toml(path: Path) -> TaskSpec:
    """Read and check one ``task.toml`` (the PDDL is checked by :mod:`planners.pddl_task`)."""
    r = SpecReader(path)
    with as_definition_error():
        top = reader.load(path)
        task = top.table("task")
        name = task.string("name")
        if not name.isidentifier():
            raise r.fail(task, "name", f"'name' must be an identifier, got {name!r}")
        description = task.string("description", "", empty=True)
        domain = task.string("domain", "domain.pddl")
        planning_time_s = task.number("planning_time_s", 0.5, min=0, max=reader.MAX_SECONDS)
        static_time_s = task.number("static_time_s", 0.05, min=0, max=reader.MAX_SECONDS)
        timeout_s = task.number("timeout_s", 10.0, min=0, max=MAX_TIMEOUT_S)
        r.note(task, "timeout_s")  # the [example]'s check may warn at it
        task.done()
        problem = top.table("problem")
        goal = r.literals(problem, "goal")
        facts = r.literals(problem, "facts")
        suspended_facts = r.literals(problem, "suspended_facts")
        restore = r.literals(problem, "restore")
        problem.done()
        actions_t = top.table("actions")
        actions = {}
        for n in actions_t.keys():  # PDDL names are case-insensitive: the domain's are read in lower case
            if n.lower() in actions:
                raise r.fail(actions_t, n, f"a second entry for action {n.lower()!r} (PDDL names ignore case)")
            actions[n.lower()] = _action(r, actions_t.table(n), n.lower())
        actions_t.done()
        static = top.table("static")
        static_update = r.templates(static, "update")
        if "suspension" in static:
            raise r.fail(static, "suspension", "[[static.suspension]] is gone: each [[suspension]] branch now has "
                                               "both `goal` (planned) and `stages` (static), see docs/domains.md")
        static.done()
        schedule = top.table("schedule", {})
        cps = schedule.number("cps", 1.0, min=0)
        travel_s = schedule.number("travel_s", 10.0, min=0, max=reader.MAX_SECONDS)
        priority = schedule.number("priority", None, integer=True)
        args = _args(r, top)
        original = _original_costs(r, schedule, top, args)
        schedule.done()
        spec = TaskSpec(
            folder=path.parent, name=name, description=description, domain_file=path.parent / domain,
            args=args, goal=goal, facts=facts, suspended_facts=suspended_facts,
            suspension=r.branches(top, "suspension"), actions=actions, static_update=static_update,
            cps=float(cps), travel_s=float(travel_s), planning_time_s=float(planning_time_s),
            static_time_s=float(static_time_s), timeout_s=float(timeout_s), example=_example(r, top),
            priority=None if priority is None else int(priority),
            hazards=_hazards(r, top), people=_people(r, top), bindings=_bindings(r, top),
            invariants=_derived(r, top), restore=tuple(restore), original_costs=original, lines=r.lines,
            trees=read_trees(r, top),
        )
        top.done()
    return spec
