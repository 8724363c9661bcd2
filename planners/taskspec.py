"""``task.toml``: the declarative part of a task folder, read into frozen dataclasses.

Every fault is a :class:`~planners.checks.DefinitionError` naming ``task.toml`` and the
key at fault.  The format is documented, with an example, in ``docs/domains.md``.
Literals are lists of strings, like the world's facts: ``["at", "$person", "$destination"]``,
negated as ``["not", "following", "$person"]``; ``$name`` is a request argument,
``$robot`` the robot, ``$at:name`` the place where ``name`` is; ``?param`` (in
``[actions]``) a parameter of the PDDL action.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from planners.checks import DefinitionError
from tasker.errors import ConfigError
from tasker.stage import StageKind
from tasker.task import ArgSpec

SKILLS = ("navigate", "say", "manipulate", "wait")
"""Skills the core agent offers (the contract with ``robot/``)."""

Literal = tuple[str, ...]


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
class StageTemplate:
    """One stage of a static strategy: an action with argument templates."""

    action: str
    args: tuple[str, ...]
    suspended: str | None = None


@dataclass(frozen=True, slots=True)
class Branch:
    """One branch of a decision list: ``when`` all literals hold (and the interruption is
    at least ``min_interruption_s`` long), use ``goal`` (planned) or ``stages`` (static)."""

    when: tuple[Literal, ...] = ()
    min_interruption_s: float = 0.0
    goal: tuple[Literal, ...] = ()
    stages: tuple[StageTemplate, ...] = ()
    label: str = ""


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
    static_suspension: tuple[Branch, ...]
    cps: float
    travel_s: float
    planning_time_s: float
    static_time_s: float
    timeout_s: float = 10.0
    example: ExampleWorld | None = None
    hooks: Mapping[str, Any] = field(default_factory=dict)


class _Reader:
    """Typed access to a TOML table with errors that name the file and the key."""

    def __init__(self, file: Path) -> None:
        self.file = file

    def fail(self, key: str, reason: str) -> DefinitionError:
        return DefinitionError(self.file, f"[{key}] {reason}")

    def table(self, data: Mapping[str, Any], key: str, where: str, required: bool = False) -> dict[str, Any]:
        value = data.get(key)
        if value is None:
            if required:
                raise self.fail(where, f"missing table {key!r}")
            return {}
        if not isinstance(value, dict):
            raise self.fail(where, f"{key!r} must be a table")
        return value

    def number(self, data: Mapping[str, Any], key: str, where: str, default: float) -> float:
        value = data.get(key, default)
        if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value) or value < 0:
            raise self.fail(where, f"{key!r} must be a finite number >= 0, got {value!r}")
        return float(value)

    def literals(self, value: Any, where: str) -> tuple[Literal, ...]:
        if not isinstance(value, list):
            raise self.fail(where, f"expected a list of literals such as [[\"at\", \"$x\", \"$place\"]], got {value!r}")
        out: list[Literal] = []
        for lit in value:
            if not isinstance(lit, list) or not lit or not all(isinstance(s, str) and s for s in lit):
                raise self.fail(where, f"a literal is a non-empty list of strings, got {lit!r}")
            if lit[0] == "not" and len(lit) < 2:
                raise self.fail(where, f"'not' needs a predicate: {lit!r}")
            out.append(tuple(lit))
        return tuple(out)

    def templates(self, value: Any, where: str) -> tuple[StageTemplate, ...]:
        if not isinstance(value, list):
            raise self.fail(where, "stages must be a list of {action = ..., args = [...]} tables")
        out = []
        for st in value:
            if not isinstance(st, dict) or not isinstance(st.get("action"), str):
                raise self.fail(where, f"a stage needs an 'action' string, got {st!r}")
            args = st.get("args", [])
            if not isinstance(args, list) or not all(isinstance(a, str) for a in args):
                raise self.fail(where, f"stage {st['action']!r}: 'args' must be a list of strings")
            sus = st.get("suspended")
            if sus is not None and not isinstance(sus, str):
                raise self.fail(where, f"stage {st['action']!r}: 'suspended' must be an action name")
            out.append(StageTemplate(st["action"], tuple(args), sus))
        return tuple(out)

    def branches(self, value: Any, where: str, static: bool) -> tuple[Branch, ...]:
        if not isinstance(value, list):
            raise self.fail(where, "must be an array of tables ([[...]])")
        out = []
        for k, b in enumerate(value):
            w = f"{where}[{k}]"
            if not isinstance(b, dict):
                raise self.fail(w, "must be a table")
            when = self.literals(b.get("when", []), w)
            mi = self.number(b, "min_interruption_s", w, 0.0)
            goal = () if static else self.literals(b.get("goal", []), w)
            stages = self.templates(b.get("stages", []), w) if static else ()
            out.append(Branch(when, mi, goal, stages, str(b.get("label", ""))))
        if not out or out[-1].when or out[-1].min_interruption_s:
            raise self.fail(where, "the last branch must have no 'when' (the default case)")
        return tuple(out)


def _action(r: _Reader, name: str, a: Any) -> ActionSpec:
    where = f"actions.{name}"
    if not isinstance(a, dict):
        raise r.fail(where, "must be a table")
    skill = a.get("skill")
    if skill not in SKILLS:
        raise r.fail(where, f"'skill' must be one of {list(SKILLS)}, got {skill!r}")
    try:
        kind = StageKind(a.get("kind", "suspendable"))
    except ValueError:
        raise r.fail(where, f"'kind' must be 'suspendable' or 'blocking', got {a.get('kind')!r}") from None
    travel = a.get("travel")
    if travel is not None and (not isinstance(travel, list) or len(travel) != 2
                               or not all(isinstance(t, str) and t.startswith("?") for t in travel)):
        raise r.fail(where, f"'travel' must be two parameters [\"?from\", \"?to\"], got {travel!r}")
    duration = r.number(a, "duration", where, 0.0) if "duration" in a else None
    for key in ("to", "text"):
        if key in a and not isinstance(a[key], str):
            raise r.fail(where, f"{key!r} must be a string")
    if skill == "navigate" and "to" not in a:
        raise r.fail(where, "a navigate action needs 'to' (the parameter naming its target)")
    return ActionSpec(name, skill, kind, duration, tuple(travel) if travel else None, a.get("to"), a.get("text"))


def _args(r: _Reader, raw: Any) -> tuple[ArgSpec, ...]:
    if not isinstance(raw, list):
        raise r.fail("args", "must be an array of tables ([[args]])")
    out = []
    for k, a in enumerate(raw):
        if not isinstance(a, dict) or "name" not in a:
            raise r.fail(f"args[{k}]", "needs a 'name'")
        try:
            out.append(ArgSpec(name=a["name"], type=a.get("type", "str"), required=a.get("required", True),
                               default=a.get("default"), help=a.get("help", ""),
                               choices=tuple(a["choices"]) if "choices" in a else None))
        except (ConfigError, TypeError) as exc:
            raise r.fail(f"args[{k}]", str(exc)) from None
    return tuple(out)


def _example(r: _Reader, ex: dict[str, Any]) -> ExampleWorld | None:
    if not ex:
        return None
    poses = {}
    for name, p in r.table(ex, "poses", "example").items():
        if not isinstance(p, list) or len(p) not in (2, 3) or not all(isinstance(v, int | float) for v in p):
            raise r.fail("example.poses", f"{name}: a pose is [x, y] or [x, y, yaw], got {p!r}")
        poses[name] = (float(p[0]), float(p[1]), float(p[2]) if len(p) == 3 else 0.0)
    objects = r.table(ex, "objects", "example", required=True)
    if not all(isinstance(v, str) for v in objects.values()):
        raise r.fail("example.objects", "maps object names to type names (strings)")
    facts = r.literals(ex.get("facts", []), "example.facts")
    return ExampleWorld(r.table(ex, "args", "example"), objects, facts, poses)


def read_task_toml(path: Path) -> TaskSpec:
    """Read and check one ``task.toml`` (the PDDL is checked by :mod:`planners.pddl_task`)."""
    r = _Reader(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise DefinitionError(path, "no such file") from None
    except tomllib.TOMLDecodeError as exc:
        line = int(exc.args[0].rsplit("line ", 1)[1].split(",")[0]) if "line " in str(exc) else None
        raise DefinitionError(path, f"TOML syntax error: {exc}", line) from None
    task = r.table(data, "task", "task", required=True)
    name = task.get("name")
    if not isinstance(name, str) or not name.isidentifier():
        raise r.fail("task", f"'name' must be an identifier, got {name!r}")
    problem = r.table(data, "problem", "problem", required=True)
    raw_actions = r.table(data, "actions", "actions", required=True)
    static = r.table(data, "static", "static", required=True)
    schedule = r.table(data, "schedule", "schedule")
    return TaskSpec(
        folder=path.parent,
        name=name,
        description=str(task.get("description", "")),
        domain_file=path.parent / str(task.get("domain", "domain.pddl")),
        args=_args(r, data.get("args", [])),
        goal=r.literals(problem.get("goal", []), "problem.goal"),
        facts=r.literals(problem.get("facts", []), "problem.facts"),
        suspended_facts=r.literals(problem.get("suspended_facts", []), "problem.suspended_facts"),
        suspension=r.branches(data.get("suspension", [{}]), "suspension", static=False),
        actions={n: _action(r, n, a) for n, a in raw_actions.items()},
        static_update=r.templates(static.get("update", []), "static.update"),
        static_suspension=r.branches(static.get("suspension", [{}]), "static.suspension", static=True),
        cps=r.number(schedule, "cps", "schedule", 1.0),
        travel_s=r.number(schedule, "travel_s", "schedule", 10.0),
        planning_time_s=r.number(task, "planning_time_s", "task", 0.5),
        static_time_s=r.number(task, "static_time_s", "task", 0.05),
        timeout_s=r.number(task, "timeout_s", "task", 10.0),
        example=_example(r, r.table(data, "example", "example")),
    )
