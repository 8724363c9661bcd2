"""``tasker check PATH…``: every load-time check, on task folders, scenarios, worlds, sweep specs and day
protocols.

Each PATH is recognised by what it holds: a task folder (``task.toml``), a folder of
task folders, a folder of ``.toml`` files, or one file — a scenario (``kind = …``),
a sweep spec (``scenarios`` and ``seeds``), a day protocol (``[day]`` and ``[tasks]``),
a world (``places``), a ``task.toml`` or a PDDL domain.  Every problem is listed (not
only the first), one line each, and the command exits 1 when there is any (2 for bad
arguments).  A task folder's ``[example]`` is solved again even when the check cache
says it passed before.

Each task folder that loads also gets its suspension tree read (:mod:`planners.treecheck`):
per branch, at each ``exeTsk`` stage of its ``[example]``, whether the branch the tree chooses
there reaches its goal and leaves every declared hazard off, and which ``when`` conditions name
a fact the world never has (the worlds shipped, and those of the worlds and scenarios checked
in the same call, count as worlds it may have; the other task folders checked, as tasks that
may act on the same world).  Printed as ``tree`` lines; what fails is a
warning, not a problem (the exit status stays 0).
"""

from __future__ import annotations

import argparse
import functools
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from experiments.cli.args import EXIT_FAILED, EXIT_OK, error_text
from experiments.cli.run import add_path_option, task_paths
from tasker.support import reader
from tasker.support.reader import InputWarning

if TYPE_CHECKING:
    from experiments.inputs.robot_scenario import RobotScenario
    from robot.spec import WorldSpec

Fact = tuple[str, ...]

EXAMPLES = """\
examples:
  tasker check domains/cook                          # a task folder: PDDL, task.toml, the example solved
  tasker check ~/my_tasks                            # a folder of task folders
  tasker check experiments/inputs/scenarios experiments/sweep/specs robot/worlds experiments/days/protocols
  tasker check my_scenario.toml --path ~/my_tasks    # a scenario that requests your own task types"""


def _local(exc: reader.InputError) -> str:
    """A reader's error about the file a problem line already names: ``line N: field: what``."""
    return ": ".join(x for x in (f"line {exc.line}" if exc.line else "", exc.field, exc.message) if x)


class Checker:
    """Runs the checks and collects ``(path, problem)`` pairs and ``(path, what)`` successes."""

    def __init__(self, paths: list[str]) -> None:
        self.paths = paths
        self.problems: list[tuple[str, str]] = []
        self.passed: list[tuple[str, str]] = []
        self.loaded: dict[Path, bool] = {}  # task folder -> it passed its checks
        self.tasks: dict[Path, tuple[Path, Any]] = {}  # task folder -> (as named, its PddlTaskType): tree reports
        self.world_facts: list[Fact] = []  # what the worlds and scenarios checked state: trees may read it
        self._store: Any = None
        self._store_error: str | None = None

    def attempt(self, where: str | Path, what: str, fn: Callable[[], object]) -> bool:
        from tasker.errors import TaskerError

        try:
            fn()
        except (TaskerError, OSError, ValueError) as exc:
            self.problems.append((str(where), error_text(exc)))
            return False
        self.passed.append((str(where), what))
        return True

    # -- what a path is -------------------------------------------------------------------

    def check(self, raw: str) -> None:
        p = Path(raw)
        if not p.exists():
            self.problems.append((raw, "no such file or folder"))
        elif p.is_dir():
            self._folder(p)
        elif p.suffix == ".pddl":
            self._pddl(p)
        elif p.suffix == ".toml":
            self._toml(p)
        else:
            self.problems.append((raw, "expected a task folder, a .toml file (scenario, sweep spec, world, "
                                       "task.toml) or a PDDL domain"))

    def _folder(self, p: Path) -> None:
        if (p / "task.toml").is_file():
            self._task_folder(p)
            for extra in sorted(p.glob("*.toml")):  # e.g. the scenario 'tasker new' writes beside task.toml
                if extra.name != "task.toml":
                    self._toml(extra, also=[str(p.resolve())])
            return
        subs = [q for q in sorted(p.iterdir()) if (q / "task.toml").is_file()]
        files = sorted(p.glob("*.toml"))
        if not subs and not files:
            self.problems.append((str(p), "holds no task folder (a subfolder with task.toml) and no .toml file"))
        for q in subs:
            self._folder(q)
        for f in files:
            self._toml(f)

    def _task_folder(self, p: Path) -> None:
        from planners.loader import load_task

        loaded: list[Any] = []
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", InputWarning)
            ok = self.attempt(p, "task folder: PDDL, task.toml and the [example] solved",
                              lambda: loaded.append(load_task(p, use_cache=False)))
        self.loaded[p.resolve()] = ok
        if ok:
            self.tasks.setdefault(p.resolve(), (p, loaded[0]))
        for w in caught:  # shown as any other warning; they only change what "ok" claims
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        if ok and any(issubclass(w.category, InputWarning) for w in caught):
            self.passed[-1] = (str(p), "task folder: PDDL and task.toml (its [example]: see the warning)")

    def _pddl(self, p: Path) -> None:
        from planners.checks import load_domain

        try:
            text = reader.read_text(p).lower()
        except reader.InputError as exc:
            self.problems.append((str(p), _local(exc)))
            return
        if "(:domain" in text:
            self.problems.append((str(p), "a PDDL problem is checked with its domain: tasker plan DOMAIN PROBLEM"))
            return
        self.attempt(p, "PDDL domain", lambda: load_domain(p))

    def _toml(self, p: Path, also: list[str] | None = None) -> None:
        try:  # within the readers' limits, as every loader reads it
            raw = reader.loads(reader.read_text(p), p).data
        except reader.InputError as exc:
            self.problems.append((str(p), _local(exc)))
            return
        if p.name == "task.toml" or "task" in raw and "actions" in raw:
            self._task_folder(p.parent)
        elif "kind" in raw:
            self._scenario(p, also or [])
        elif "scenarios" in raw and "seeds" in raw:
            self._sweep(p)
        elif "day" in raw and "tasks" in raw:
            from experiments.days import protocol

            self.attempt(p, "day protocol", lambda: protocol.load(p))
        elif "places" in raw or "bounds" in raw:
            from robot.spec import load_world

            worlds: list[Any] = []
            if self.attempt(p, "world", lambda: worlds.append(load_world(p))):
                self.world_facts += world_facts(worlds[0])
        else:
            self.problems.append((str(p), "cannot tell what this is: a scenario has 'kind', a sweep spec "
                                          "'scenarios' and 'seeds', a day protocol '[day]' and '[tasks]', a world "
                                          "'places', a task.toml '[task]'"))

    # -- scenarios and sweeps -----------------------------------------------------------------

    def _tasks(self, also: list[str], request_fields: bool = False) -> Any:
        from experiments.inputs.request_fields import with_request_fields
        from planners.bundled import task_types
        from tasker.store import TaskStore

        loaded = task_types([*self.paths, *also])
        if request_fields:  # as the scenario's load and run take them (experiments.inputs.request_fields)
            loaded = [with_request_fields(t) for t in loaded]
        return TaskStore(loaded)

    def _scenario(self, p: Path, also: list[str]) -> None:
        from experiments.inputs import scenario as scenarios
        from experiments.inputs import synthetic

        if scenarios.kind_of(p) != "robot":
            self.attempt(p, "synthetic scenario", lambda: synthetic.load(p))
            return
        loaded: list[Any] = []
        paths = [*self.paths, *also]
        if not self.attempt(p, "robot scenario", lambda: loaded.append(scenarios.load(p, task_paths=paths))):
            return
        scn = loaded[0]
        world: list[Any] = []
        from robot.spec import load_world

        self.world_facts += scenario_facts(scn)
        if self.attempt(p, f"world {scn.world}", lambda: world.append(load_world(scn.world))):
            from experiments.cli.args import did_you_mean

            self.world_facts += world_facts(world[0])

            for name in scn.people:
                if name not in world[0].people:
                    self.problems.append((f"{p}: people.{name}", f"no such person in world {scn.world!r}"
                                                                 f"{did_you_mean(name, world[0].people)}; "
                                                                 f"known: {sorted(world[0].people)}"))
        from experiments.inputs.request_fields import asked_for

        stores: list[Any] = []
        wrap = asked_for(scn.actions)
        if not self.attempt(p, "its task types loaded", lambda: stores.append(self._tasks(also, wrap))):
            return
        for k, a in enumerate(scn.actions):
            if a.kind == "request":
                task, task_args = a.fields["task"], a.fields["args"]
                self.attempt(f"{p}: request {k} (t={a.t:g})", f"request {task}",
                             functools.partial(stores[0].validate, task, task_args))

    def _sweep(self, p: Path) -> None:
        from experiments.sweep.spec import load_spec

        specs: list[Any] = []
        if self.attempt(p, "sweep spec", lambda: specs.append(load_spec(p))):
            from experiments.inputs import scenario as scenarios

            for sc in specs[0].scenarios:  # a file (absolute in sources), or a shipped scenario's name
                src = specs[0].sources.get(sc) or str(scenarios.resolve(sc))
                if src.endswith(".toml") and Path(src).is_file():  # with the spec's own `paths`, as its runs load it
                    self._toml(Path(src), also=list(specs[0].task_paths))
                else:
                    self.check(src)

    # -- suspension trees ------------------------------------------------------------------------

    def trees(self) -> list[tuple[str, str]]:
        """``(path, line)`` of each loaded task folder's tree report (:mod:`planners.treecheck`); its
        findings are warnings.  A report that fails is a problem of its folder."""
        from planners import treecheck
        from robot.spec import load_world, shipped_worlds
        from tasker.errors import TaskerError

        if not self.tasks:
            return []
        known = [*self.world_facts, *(f for name in shipped_worlds() for f in world_facts(load_world(name)))]
        out: list[tuple[str, str]] = []
        for shown, task in self.tasks.values():
            others = [t for _, t in self.tasks.values() if t is not task]
            try:
                reports = treecheck.reports(task, world_facts=known, others=others)
            except (TaskerError, ValueError) as exc:
                self.problems.append((str(shown), f"its suspension tree cannot be read: {error_text(exc)}"))
                continue
            for report in reports:
                report.warn(task)
                out += [(str(shown), line) for line in report.lines()]
        return out


def world_facts(world: WorldSpec) -> list[Fact]:
    """What a world (:class:`robot.spec.WorldSpec`) can hold, as :class:`robot.sim.Simulation` reads it
    off: its facts, its devices at their places in their states, and its people's postures — any of
    whom may fall (a script or a world event), which the simulation says as ``(fallen name)``."""
    out = [tuple(f) for f in world.facts] + [("clear", p) for p in world.places]  # the world derives clear
    for d in world.devices.values():
        out += [("at", d.name, d.place), ("state", d.name, d.state)]
    for person in world.people.values():
        out += [("posture", person.name, person.posture), ("fallen", person.name)]
    return out


def scenario_facts(scn: RobotScenario) -> list[Fact]:
    """What a robot scenario adds to its world: its objects at their places with their facts, its devices."""
    out: list[Fact] = []
    for name, o in scn.objects.items():
        out += [("at", name, str(o["place"])), *(tuple(f) for f in o.get("facts", ()))]
    for name, d in scn.devices.items():
        out += [("at", name, str(d["place"])), ("state", name, str(d.get("state", "off")))]
    return out


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser("check", help="check task folders, scenarios, worlds, sweep specs and day protocols; list "
                                     "every problem",
                       description="Run every load-time check on each PATH (task folders with their examples "
                                   "solved, scenarios with their requests, worlds, sweep specs with their "
                                   "scenarios, day protocols with their robot backend) and list every problem "
                                   "found. Exits 1 if there is any. Each task folder's suspension tree is read "
                                   "too ('tree' lines): at each exeTsk stage of its [example], does the branch "
                                   "chosen reach its goal and leave every declared hazard off, and can each "
                                   "`when` match the world at all; what fails is a warning.",
                       epilog=EXAMPLES)
    p.add_argument("targets", metavar="PATH", nargs="+", help="a task folder, a folder, or a .toml / .pddl file")
    add_path_option(p)
    p.set_defaults(func=_check)


def _task_folders(targets: list[str]) -> list[Path]:
    """The targets that are task folders (or folders of them), resolved."""
    out = []
    for t in targets:
        p = Path(t)
        try:
            if (p / "task.toml").is_file() or (p.is_dir() and any((q / "task.toml").is_file() for q in p.iterdir())):
                out.append(p.resolve())
        except (OSError, ValueError):  # unreadable, or no file name: its own check says so
            continue
    return out


def _check(args: argparse.Namespace) -> int:
    checker = Checker(task_paths(args))
    folders = _task_folders(args.targets)
    first = [t for t in args.targets if "\x00" not in t and Path(t).resolve() in folders]
    for t in first:  # task folders first: a scenario checked with them requests their task types, as with --path
        checker.check(t)
    for f in folders:  # those that loaded (a broken one has said so already, once)
        subs = [f] if (f / "task.toml").is_file() else [q.resolve() for q in f.iterdir() if (q / "task.toml").is_file()]
        if all(checker.loaded.get(q) for q in subs) and str(f) not in checker.paths:
            checker.paths.append(str(f))
    for t in args.targets:
        if t not in first:
            checker.check(t)
    trees = checker.trees()
    if not args.quiet:
        for where, what in checker.passed:
            print(f"ok     {where}: {what}")
        for where, line in trees:
            print(f"tree   {where}: {line}")
    for where, problem in checker.problems:
        print(f"error  {where}: {problem}")
    n = len(checker.problems)
    print(f"{len(checker.passed)} checks passed, {n} problem{'s' if n != 1 else ''}")
    return EXIT_FAILED if n else EXIT_OK
