"""Cross-references of a robot scenario, checked at load against the world and the task store.

A scenario names things that live elsewhere: people, places, doors and devices of the
world, task types and their arguments, agents (``d1``, ``d2``, … in request order).
Each name is checked here before anything runs, and a fault is a
:class:`~experiments.inputs.fields.ScenarioError` naming the file, the line, the field, what
was expected and "did you mean".

Request arguments are checked by one general rule, not a list of argument names: an
argument a task type uses as a PDDL object of type ``T`` (``$person`` in a literal of
its ``task.toml`` whose predicate declares that parameter ``- person``) must name a
world object whose type is ``T`` or a subtype of ``T`` in that task's domain.  So a
``guide_human`` whose destination is a person, or a ``human_fell`` of someone who is
not in the world, is refused at load, not deep in the PDDL translator.

What is valid but doubtful is an :class:`~tasker.support.reader.InputWarning` (also kept on
``RobotScenario.warnings``): an action after the horizon, two requests of the same
task type with identical arguments that may overlap in time, a task type's default
argument that names nothing in this world, a requested task type's ``[[bindings]]`` entry
that no thing of its kind in this world can satisfy.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

from experiments.inputs import fields
from experiments.inputs.actions import NO_REQUESTS, TimedAction, located
from experiments.inputs.fields import TASKS_HINT
from experiments.inputs.request_fields import FIELD_NAMES, asked_for, with_request_fields
from experiments.inputs.robot_scenario import RobotScenario
from tasker.errors import TaskerError
from tasker.support.reader import Table, check_name, suggest

if TYPE_CHECKING:
    from robot.spec import WorldSpec
    from tasker.task import TaskType


def world_objects(world: WorldSpec) -> dict[str, str]:
    """Every object of the world with its type, as the simulation gives them to the planner."""
    out = {"robot": "robot"}
    out |= {n: "place" for n in world.places}
    out |= {n: "person" for n in world.people}
    out |= {n: d.type for n, d in world.devices.items()}
    out |= {n: "door" for n in world.doors}
    out |= dict(world.objects)
    return out


def arg_types(task: TaskType) -> dict[str, set[str]]:
    """For each argument a task type uses as a PDDL object, the types it must have (``""``: any object).

    Read from the literals of its ``task.toml`` (goal, facts, suspension ``when`` and
    ``goal``) with the parameter types of the predicates in its domain, and from its
    static stages with the parameter types of their PDDL actions; ``$at:name`` makes
    ``name`` an object of any type.  A task type without a PDDL domain gives ``{}``.
    """
    spec, domain = getattr(task, "spec", None), getattr(task, "domain", None)
    predicates: Mapping[str, Sequence[str]] = getattr(domain, "predicates", {}) or {}
    if spec is None:
        return {}
    literals: list[Sequence[str]] = [*getattr(spec, "goal", ()), *getattr(spec, "facts", ()),
                                     *getattr(spec, "suspended_facts", ())]
    for branch in (*getattr(spec, "suspension", ()), *getattr(spec, "static_suspension", ())):
        literals.extend(branch.when)
        literals.extend(branch.goal)
    out: dict[str, set[str]] = {}
    actions: Mapping[str, Any] = getattr(domain, "actions", {}) or {}
    templates = [*getattr(spec, "static_update", ())]
    for branch in getattr(spec, "static_suspension", ()):
        templates.extend(branch.stages)
    for template in templates:  # static stages: the PDDL action's parameter types, by position
        try:
            params = list(actions[template.action].param_types)
        except (KeyError, AttributeError):  # no such action, or not a PDDL task type: the planner's checks say so
            continue
        for i, a in enumerate(template.args):
            if a.startswith("$at:") and a != "$at:robot":
                out.setdefault(a[4:], set()).add("")
            elif a.startswith("$") and a != "$robot" and i < len(params):
                out.setdefault(a[1:], set()).add(params[i])
    for lit in literals:
        lit = tuple(lit[1:]) if lit and lit[0] == "not" else tuple(lit)
        if not lit:
            continue
        signature = predicates.get(lit[0])
        for i, a in enumerate(lit[1:]):
            if a.startswith("$at:") and a != "$at:robot":
                out.setdefault(a[4:], set()).add("")
            elif a.startswith("$") and a != "$robot":
                wanted = signature[i] if signature is not None and i < len(signature) else ""
                out.setdefault(a[1:], set()).add(wanted)
    return out


def validate_request(f: Table, task: TaskType, args: Mapping[str, Any]) -> dict[str, Any]:
    """A request's (or change's) arguments checked by the task type, the fault located at ``f.args.NAME``."""
    try:
        return task.validate_args(args)
    except TaskerError as exc:
        msg = str(exc)
        known = [a.name for a in task.arg_specs]
        unknown = [k for k in args if k not in known]
        at = f.table("args", {})
        if unknown:
            fields = [n for n in FIELD_NAMES if n not in known]  # what any request may also give
            also = f"; any request may also give {', '.join(fields)}" if fields else ""
            raise at.error(unknown[0], f"task type {task.name!r} has no argument {unknown[0]!r}"
                                       f"{suggest(unknown[0], [*known, *fields])} "
                                       f"(arguments: {', '.join(known) or 'none'}{also})") from None
        bad = next((n for n in known if repr(n) in msg), None)
        raise (at.error(bad, msg) if bad else f.error("args", msg)) from None


def _most_specific(domain: Any, wanted: set[str]) -> set[str]:
    """``{"locatable", "person"}`` -> ``{"person"}``: drop a type that another wanted type already implies."""
    types: Mapping[str, set[str]] = getattr(domain, "types", {}) or {}
    out = {w for w in wanted if w}
    out = {w for w in out if not any(w != o and w in types.get(o, ()) for o in out)}
    return out or {""}


def _fits(domain: Any, obj_type: str, wanted: Iterable[str]) -> bool:
    if domain is None:
        return True
    return all(domain.has_type(obj_type, w) for w in wanted)


def arg_problem(task: TaskType, name: str, value: Any, types: Mapping[str, set[str]], objects: Mapping[str, str],
                world: str, default: bool = False) -> str | None:
    """Why argument ``name`` = ``value`` of ``task`` does not name an object of ``objects`` (name ->
    type) of a type its task uses it as (:func:`arg_types`), or ``None``."""
    wanted = types.get(name)
    if wanted is None:
        return None
    domain = getattr(task, "domain", None)
    wanted = _most_specific(domain, wanted)
    what = f"{'default of ' if default else ''}argument {name!r} of task type {task.name!r}"
    if not isinstance(value, str):
        return f"expected the name of an object of the world (the {what}), got {value!r}"
    if value in objects and _fits(domain, objects[value], wanted):
        return None
    known = sorted(n for n, ty in objects.items() if _fits(domain, ty, wanted))
    if value not in objects:
        return (f"no {' or '.join(sorted(w for w in wanted if w)) or 'object'} {value!r} in world "
                f"{world!r}{suggest(value, known)} (the {what}; known: {', '.join(known) or 'none'})")
    return (f"{value!r} is a {objects[value]}, expected a {' and '.join(sorted(wanted))} "
            f"(the {what}){suggest(value, known)} (known: {', '.join(known) or 'none'})")


def check_template(t: Table, task: TaskType, args: Mapping[str, str], variables: Mapping[str, str],
                   world: WorldSpec) -> None:
    """The arguments of a request template (``t.args``, e.g. a day protocol's robot task), checked
    like a request's: names, required ones, and each one a task uses as a PDDL object naming an
    object of its type, where a variable (a key of ``variables``, e.g. ``$person``) stands for an
    object of the type ``variables`` gives it."""
    validate_request(t, task, args)
    objects = {**world_objects(world), **variables}
    types = arg_types(task)
    at = t.table("args", {})
    for name, value in args.items():
        problem = arg_problem(task, name, value, types, objects, world.name)
        if problem is not None:
            raise at.error(name, problem)


class _Checker:
    """Checks one scenario; collects its warnings."""

    def __init__(self, scn: RobotScenario, top: Table, world: WorldSpec, tasks: Mapping[str, TaskType]) -> None:
        self.scn, self.top, self.world, self.tasks = scn, top, world, tasks
        self.objects = world_objects(world)
        self.warnings: list[str] = []
        domains = [d for t in tasks.values() if (d := getattr(t, "domain", None)) is not None]
        self.types: set[str] = {ty for d in domains for ty in getattr(d, "types", {})}
        self.predicates: dict[str, set[int]] = {}
        for d in domains:
            for name, sig in getattr(d, "predicates", {}).items():
                self.predicates.setdefault(name, set()).add(len(sig))

    @property
    def devices(self) -> dict[str, tuple[str, str]]:
        """Every device, the world's and the scenario's: name -> (type, state at the start)."""
        out = {n: (d.type, d.state) for n, d in self.world.devices.items()}
        return out | {n: (d["type"], d["state"]) for n, d in self.scn.devices.items()}

    def warn(self, t: Table, key: str | int | None, message: str) -> None:
        self.warnings.append(t.warn(key, message))

    # -- the parts ------------------------------------------------------------------------
    def settings(self) -> None:
        s = self.top.table("settings", {})
        names = sorted(self.tasks)
        fields.scheduler_options(s, self.scn.scheduler, names)
        st = s.table("strategies", {})
        for task in self.scn.strategies:
            check_name(st, task, task, names, "task type", TASKS_HINT)

    def scenario_objects(self) -> None:
        ot = self.top.table("objects", {})
        for name, entry in self.scn.objects.items():
            self._new_thing(ot, name, entry, "object", "")
        self.scenario_devices()
        for name, entry in self.scn.objects.items():
            t = ot.at(name, ot.data[name])
            for i, fact in enumerate(entry["facts"]):
                self.fact(t.at("facts", {}), i, fact)

    def scenario_devices(self) -> None:
        """``[devices.NAME]``: a new name, a type of the task types' domains, a place of the world."""
        dt = self.top.table("devices", {})
        for name, entry in self.scn.devices.items():
            self._new_thing(dt, name, entry, "device", " or of this scenario's [objects]")

    def _new_thing(self, table: Table, name: str, entry: Mapping[str, Any], kind: str, also: str) -> None:
        """One ``[objects.NAME]`` or ``[devices.NAME]``: a new name, a type of the task types'
        domains, a place of the world; recorded in :attr:`objects`."""
        from robot.spec import name_problem

        t = table.at(name, table.data[name])
        if name in self.objects:
            raise table.error(name, f"the name {name!r} is already a {self.objects[name]} of world "
                                    f"{self.world.name!r}{also}; expected a new name")
        bad = name_problem(name)
        if bad:
            raise table.error(name, bad)
        if self.types:
            check_name(t, "type", entry["type"], self.types, f"{kind} type")
        check_name(t, "place", entry["place"], self.world.places, f"place of world {self.world.name!r}")
        self.objects[name] = entry["type"]

    def fact(self, t: Table, key: str | int, fact: Sequence[str]) -> None:
        """A fact names a known predicate with its arity, over objects of the world."""
        if self.predicates:
            pred = fact[0]
            if pred not in self.predicates:
                raise t.error(key, f"no predicate {pred!r}{suggest(pred, self.predicates)} in the task types' "
                                   f"domains (known: {', '.join(sorted(self.predicates))})")
            if len(fact) - 1 not in self.predicates[pred]:
                arity = " or ".join(str(n) for n in sorted(self.predicates[pred]))
                raise t.error(key, f"{pred!r} takes {arity} argument(s), got {len(fact) - 1} in {list(fact)!r}")
        for a in fact[1:]:
            check_name(t, key, a, self.objects, f"object of world {self.world.name!r}")

    def people(self) -> None:
        from robot.spec import check_point

        pt = self.top.table("people", {})
        for name, entry in self.scn.people.items():
            check_name(pt, name, name, self.world.people, f"person of world {self.world.name!r}")
            t = pt.at(name, pt.data[name])
            if "pose" in entry:
                check_point(self.world, t, "pose", entry["pose"][0], entry["pose"][1])
            for i, (_, x, y) in enumerate(entry.get("walk", ())):
                check_point(self.world, t.at("walk", {}), i, x, y)

    def arg(self, t: Table, task: TaskType, name: str, value: Any, types: Mapping[str, set[str]],
            default: bool = False) -> None:
        """One argument used as a PDDL object must name a world object of its type."""
        problem = arg_problem(task, name, value, types, self.objects, self.world.name, default)
        if problem is None:
            return
        if default:
            self.warn(t, None, problem)
        else:
            raise t.error(name, problem)

    def args(self, f: Table, task: TaskType, given: Mapping[str, Any], checked: Mapping[str, Any]) -> None:
        types = arg_types(task)
        at = f.table("args", {})
        for name, value in checked.items():
            if name in given:
                self.arg(at, task, name, value, types)
            elif value is not None:
                self.arg(f, task, name, value, types, default=True)

    def validate(self, f: Table, task: TaskType, args: Mapping[str, Any]) -> dict[str, Any]:
        return validate_request(f, task, args)

    def actions(self) -> None:
        from robot.spec import POSTURES

        requests: list[tuple[TimedAction, dict[str, Any]]] = []
        names = sorted(self.tasks)
        for a in self.scn.actions:
            f = located(self.top, a)
            if a.t > self.scn.horizon:
                self.warn(f, "t", f"t={a.t:g} is after the horizon ({self.scn.horizon:g} s): it never happens")
            if a.kind == "request":
                check_name(f, "task", a.fields["task"], names, "task type", TASKS_HINT)
                task = self.tasks[a.fields["task"]]
                checked = self.validate(f, task, a.fields["args"])
                self.args(f, task, a.fields["args"], checked)
                self.times(f, a, checked)
                requests.append((a, checked))
            elif a.kind == "change":
                k = int(a.fields["agent"][1:])
                req, before = requests[k - 1] if k <= len(requests) else self._request(k)
                task = self.tasks[req.fields["task"]]
                merged = {**before, **a.fields["args"]}
                self.validate(f, task, merged)
                self.args(f, task, a.fields["args"], {n: merged[n] for n in a.fields["args"]})
            elif a.kind == "world":
                what, value = a.fields["what"], a.fields["value"]
                if what == "posture":
                    check_name(f, what, value[0], self.world.people, f"person of world {self.world.name!r}")
                    check_name(f, what, value[1], POSTURES, "posture")
                elif what == "door":
                    check_name(f, what, value[0], self.world.doors, f"door of world {self.world.name!r}")
                elif what == "walk":
                    from robot.spec import check_point

                    check_name(f, what, value[0], self.world.people, f"person of world {self.world.name!r}")
                    check_point(self.world, f, what, float(value[1]), float(value[2]))
                elif what == "device":
                    check_name(f, what, value[0], self.devices, f"device of world {self.world.name!r} or the scenario")
                elif what == "move":
                    things = {**self.world.objects, **{n: o["type"] for n, o in self.scn.objects.items()}}
                    check_name(f, what, value[0], things, f"object of world {self.world.name!r} or the scenario")
                    check_name(f, what, value[1], self.world.places, f"place of world {self.world.name!r}")
                else:
                    for fact in value:
                        self.fact(f, what, fact)
        if not requests:
            self.warn(self.top, "requests", NO_REQUESTS)
        self.overlaps(requests)
        for a in {a.fields["task"]: a for a, _ in reversed(requests)}.values():  # the first request of each type
            self.bindings(located(self.top, a), self.tasks[a.fields["task"]])

    def times(self, f: Table, a: TimedAction, checked: Mapping[str, Any]) -> None:
        """A deadline or death time no later than the request itself has passed before the task exists."""
        for name in ("deadline", "death_at"):
            value = checked.get(name)
            if name in a.fields["args"] and isinstance(value, int | float) and value <= a.t:
                self.warn(f.table("args", {}), name, f"{name}={value:g} is not after the request (t={a.t:g}): "
                                                     "it has passed before the task is requested (an absolute "
                                                     "simulated time, not one relative to the request)")

    def bindings(self, f: Table, task: TaskType) -> None:
        """A ``[[bindings]]`` entry whose objects in this world are none of its kind (an item bound as a
        ``device``) never applies: the robot would, say, "hold" the item only symbolically.  A device
        in a state its binding does not name (``"On"`` for ``"on"``) reads as the fact not holding."""
        meaning = getattr(task, "meaning", None)
        things = {"device": set(self.devices), "door": set(self.world.doors),
                  "held": set(self.world.objects) | set(self.scn.objects),
                  "follower": set(self.world.people), "waiting": set(self.world.people)}
        for b in getattr(meaning, "bindings", ()):
            if not b.types:
                continue
            covered = sorted(n for n, ty in self.objects.items() if ty in b.types)
            if covered and not any(n in things[b.kind] for n in covered):
                fits = sorted({k for k, names in things.items() if any(n in names for n in covered)})
                self.warn(f, "task", f"task type {task.name!r}: its {b.kind} binding of {list(b.fact)} covers "
                                     f"{', '.join(covered)} here, and none is a {b.kind} thing of world "
                                     f"{self.world.name!r}, so the fact stays symbolic"
                                     + (f" (kind = {' or '.join(map(repr, fits))}?)" if fits else ""))
            if b.kind == "device":
                for n, (ty, state) in sorted(self.devices.items()):
                    if ty in b.types and state not in (b.state, b.otherwise):
                        self.warn(f, "task", f"device {n!r} of world {self.world.name!r} starts in state "
                                             f"{state!r}, and task type {task.name!r} reads {list(b.fact)} from "
                                             f"state {b.state!r} (else {b.otherwise!r}): it starts as not holding; "
                                             f"expected state = {b.state!r} or {b.otherwise!r}")

    def _request(self, k: int) -> tuple[TimedAction, dict[str, Any]]:
        req = [a for a in self.scn.actions if a.kind == "request"][k - 1]
        return req, self.tasks[req.fields["task"]].validate_args(req.fields["args"])

    def overlaps(self, requests: list[tuple[TimedAction, dict[str, Any]]]) -> None:
        """Two requests of one task type with the same arguments, the first not terminated before the
        second, nor changed (``[[changes]]``) into another request by then."""
        ends = {int(a.fields["agent"][1:]): a.t for a in self.scn.actions if a.kind == "terminate"}
        changes = [a for a in self.scn.actions if a.kind == "change"]
        for j, (later, args_j) in enumerate(requests):
            for i in range(j):
                earlier, args_i = requests[i]
                if earlier.fields["task"] != later.fields["task"] or ends.get(i + 1, float("inf")) <= later.t:
                    continue
                given = [c.fields["args"] for c in changes if c.fields["agent"] == f"d{i + 1}" and c.t < later.t]
                if given:  # its arguments when the second comes (the changes were checked above)
                    args_i = self.tasks[earlier.fields["task"]].validate_args({k: v for g in [args_i, *given]
                                                                               for k, v in g.items()})
                if args_i != args_j:
                    continue
                self.warn(located(self.top, later), "task",
                          f"the same request as d{i + 1} (requests[{earlier.origin[1]}], t={earlier.t:g}: "
                          f"{earlier.fields['task']} {args_i}) while d{i + 1} may still run: two agents would "
                          f"pursue one goal and preempt each other; terminate d{i + 1} first or drop one")
                break


def check_robot(scn: RobotScenario, top: Table, tasks: Iterable[TaskType] | None = None) -> RobotScenario:
    """Check every cross-reference of a read robot scenario; return it with its warnings."""
    from robot.spec import load_world

    if tasks is None:
        from planners.bundled import task_types

        tasks = task_types()
    if asked_for(scn.actions):  # the file gives a deadline, priority or death time: every type takes them
        tasks = [with_request_fields(t) for t in tasks]
    world = load_world(scn.world)
    c = _Checker(scn, top, world, {t.name: t for t in tasks})
    c.settings()
    c.scenario_objects()
    c.people()
    c.actions()
    return dataclasses.replace(scn, warnings=tuple(c.warnings))
