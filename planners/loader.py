"""Load task folders into task types, checking everything before any run.

A task folder holds ``task.toml``, ``domain.pddl`` and optionally ``task.py``.  Loading
checks the PDDL (syntax, predicates, arity, types, requirements), that ``task.toml``
and the domain agree (every action has a skill, literals use declared predicates with
the right arity, static templates name real actions with the right arity), and, when
the folder ships an ``[example]`` world, that the problem built from it is valid PDDL
and that Fast Downward solves it.

The checks with unified-planning (reading the domain, parsing the example problem) and the
planner call are the costly part; once they passed for a folder's exact content it is
recorded in the check cache (:mod:`planners.cache`) and later processes skip them — without
importing unified-planning at all: the :class:`~planners.problem.DomainModel` is always read
by Fast Downward's parser (:mod:`planners.schema`), checked or remembered.
"""

from __future__ import annotations

import functools
import importlib.util
import inspect
import string
import sys
import types
import warnings
from pathlib import Path
from typing import Any

from planners import cache, examplecheck
from planners.checks import DefinitionError, remembered_domain
from planners.pddl_task import PddlTaskType, hook_line
from planners.problem import DomainModel
from planners.results import PlanStatus
from planners.taskspec import TaskSpec, meaning_of, read_task_toml
from planners.temporal.folder import domain_model, load_domain, load_problem_text, planner_for
from tasker.errors import BadRequest
from tasker.errors import HookExited as HookExited  # defined there; re-exported here
from tasker.meaning import Binding
from tasker.support import reader
from tasker.world import WorldState

HOOK_NAMES = ("extra_facts", "check_args", "check_terminate")
_HOOK_PARAMS = {"extra_facts": "ctx, world", "check_args": "args", "check_terminate": "ctx, world"}
"""Functions a ``task.py`` may define (see ``docs/domains.md``).  There is no hook that changes
the suspension goal: that is declared in ``[[suspension]]``, so both strategies pursue it."""


def _file_parts(files: list[Path]) -> list[str | bytes]:
    """The names and bytes of the files the checks read (:func:`planners.cache.file_parts`), each read
    within the readers' limits: a device or a huge file is refused before it is hashed."""
    parts: list[str | bytes] = []
    for p in files:
        if not p.exists() and not p.is_symlink():
            parts += [p.name, b"\0absent"]
            continue
        try:
            parts += [p.name, reader.read_bytes(p)]
        except reader.InputError as exc:
            raise DefinitionError(p, exc.message) from None
    return parts


def _load_hooks(spec: TaskSpec) -> dict[str, Any]:
    path = spec.folder / "task.py"
    if not path.exists() and not path.is_symlink():
        return {}
    mod_name = f"tasker_tasks_{spec.name}"
    module_spec = importlib.util.spec_from_file_location(mod_name, path)
    assert module_spec is not None and module_spec.loader is not None
    module = importlib.util.module_from_spec(module_spec)
    try:
        module_spec.loader.exec_module(module)
    except SyntaxError as exc:
        if "can't decode" in str(exc.msg):  # Python's codec text has a byte offset, not the file's line
            try:
                reader.read_text(path)
            except reader.InputError as bad:
                raise DefinitionError(path, bad.message, bad.line) from None
        raise DefinitionError(path, f"syntax error: {exc.msg}", exc.lineno, exc.offset) from None
    except SystemExit as exc:  # it ended tasker with its code and no word
        raise DefinitionError(path, f"called sys.exit({'' if exc.code is None else repr(exc.code)}) on import: a "
                                    "task.py defines hooks, it does not end the program",
                              hook_line(exc, path)) from None
    except Exception as exc:  # noqa: BLE001 - any import-time failure is a definition error
        raise DefinitionError(path, f"failed to import: {type(exc).__name__}: {exc}", hook_line(exc, path)) from None
    sys.modules[mod_name] = module
    hooks = {n: getattr(module, n) for n in HOOK_NAMES if callable(getattr(module, n, None))}
    unknown = sorted(n for n in vars(module) if not n.startswith("_") and n not in HOOK_NAMES
                     and callable(vars(module)[n]) and getattr(vars(module)[n], "__module__", "") == mod_name)
    if unknown:
        raise DefinitionError(path, f"unknown hook(s) {unknown}; a task.py may define {list(HOOK_NAMES)}")
    for name, fn in hooks.items():
        params = _HOOK_PARAMS[name].split(", ")
        try:
            inspect.signature(fn).bind(*params)
        except (TypeError, ValueError):  # ValueError: no signature to inspect (a builtin): let it be
            if isinstance(fn, types.FunctionType):
                raise DefinitionError(path, f"{name}{inspect.signature(fn)}: a hook {name} takes "
                                            f"({_HOOK_PARAMS[name]})", fn.__code__.co_firstlineno) from None
    return {name: _guarded(fn, name, path) for name, fn in hooks.items()}


def _guarded(fn: Any, name: str, path: Path) -> Any:
    """``fn`` (a hook of ``path``) with ``sys.exit()`` turned into :class:`HookExited`, and the hook
    named in :mod:`tasker.support.hookmark` while it runs (a process it kills is reported with it)."""
    from tasker.support import hookmark

    where = f"{name} of {path}"

    @functools.wraps(fn)
    def hook(*args: Any, **kwargs: Any) -> Any:
        with hookmark.inside(where):
            try:
                return fn(*args, **kwargs)
            except SystemExit as exc:
                code = "" if exc.code is None else repr(exc.code)
                raise HookExited(path, f"{name} called sys.exit({code}): a hook returns or raises, it does not "
                                       "end the program", hook_line(exc, path)) from None

    return hook


def _cross_check(spec: TaskSpec, dm: DomainModel) -> None:
    toml = spec.folder / "task.toml"
    missing = sorted(set(dm.actions) - set(spec.actions))
    if missing:
        raise DefinitionError(toml, f"[actions] no entry for domain action(s) {missing}: say which skill runs each")
    extra = sorted(set(spec.actions) - set(dm.actions))
    if extra:
        raise DefinitionError(toml, f"[actions] {extra} not in {spec.domain_file.name}; "
                                    f"its actions: {sorted(dm.actions)}")
    for name, a in spec.actions.items():
        params = {f"?{p}" for p in dm.actions[name].params}
        for ref in [*(a.travel or ()), *([a.to] if a.to and a.to.startswith("?") else [])]:
            if ref not in params:
                raise DefinitionError(toml, f"[actions.{name}] {ref} is not a parameter of {name} {sorted(params)}")
    _check_texts(spec, dm)
    lits = [("problem.goal", spec.goal), ("problem.facts", spec.facts),
            ("problem.suspended_facts", spec.suspended_facts)]
    lits += [(f"{where}[{k}].{key}", getattr(b, key)) for _, where, tree in spec.all_trees()
             for k, b in enumerate(tree) for key in ("when", "goal")]
    for where, group in lits:
        for lit in group:
            try:
                dm.check_literal(lit, where)
            except DefinitionError as exc:  # located in task.toml, at the field's line
                raise DefinitionError(toml, exc.reason, spec.lines.get(where)) from None
    templates = [("static.update", t) for t in spec.static_update]
    templates += [(f"{where}[{k}].stages", t) for _, where, tree in spec.all_trees() for k, b in enumerate(tree)
                  for t in b.stages]
    tokens = [*((w, tok) for w, group in lits for lit in group for tok in lit),
              *((w, tok) for w, t in templates for tok in t.args)]
    _check_request_tokens(spec, tokens)
    for where, t in templates:
        for action in filter(None, (t.action, t.suspended)):
            if action not in dm.actions:
                raise DefinitionError(toml, f"[{where}] unknown action {action!r}; known: {sorted(dm.actions)}")
            if len(t.args) != len(dm.actions[action].params):
                raise DefinitionError(toml, f"[{where}] {action} takes {len(dm.actions[action].params)} "
                                            f"argument(s), got {len(t.args)}")


def _check_texts(spec: TaskSpec, dm: DomainModel) -> None:
    """A say action's ``text`` is a format string whose ``{placeholders}`` name a parameter of the
    action or a request argument: an unknown one was said as written ("{nowhere}"), a malformed one
    (a lone brace, ``{h.x}``, ``{h:d}``) failed the stage at run time."""
    for name, a in spec.actions.items():
        if a.text is None:
            continue
        where = f"actions.{name}.text"
        params = list(dm.actions[name].params)
        known = [*params, *(arg.name for arg in spec.args)]
        hint = (f"(placeholders name a parameter of {name} ({', '.join(params) or 'none'}) or a request "
                f"argument ({', '.join(arg.name for arg in spec.args) or 'none'}); write {{{{ and }}}} for braces)")
        try:
            fields = [(f, s) for _, f, s, _ in string.Formatter().parse(a.text) if f is not None]
        except ValueError as exc:
            raise spec.error(where, f"{exc} in {a.text!r} {hint}") from None
        for field, fmt in fields:
            if field not in known:
                shown = "{" + field + "}"
                raise spec.error(where, f"unknown placeholder {shown}"
                                        f"{reader.suggest(shown, ['{' + k + '}' for k in known])} {hint}")
            try:
                format("x", fmt or "")  # every value is a string
            except ValueError as exc:
                raise spec.error(where, f"{{{field}:{fmt}}}: {exc} (the values are strings)") from None


def _check_request_tokens(spec: TaskSpec, tokens: list[tuple[str, str]]) -> None:
    """Every ``$name`` is a request argument or ``$robot`` (``$at:x`` may name any object): a
    misspelt one would fail only when a request plans, or when a static strategy runs."""
    args = [a.name for a in spec.args] + ["robot"]
    for where, tok in tokens:
        if tok.startswith("$") and not tok.startswith("$at:") and tok[1:] not in args:
            raise spec.error(where, f"unknown request argument {tok!r}{reader.suggest(tok, ['$' + a for a in args])} "
                                    f"(this task's: {', '.join('$' + a for a in args)}; $at:NAME for a place)")


def _check_suspension(spec: TaskSpec, dm: DomainModel) -> None:
    """Strategies differ only in method: each branch's static ``stages`` must reach its
    ``goal`` from any state where its ``when`` holds.  The stages' PDDL effects are applied
    in order to what ``when`` says (facts it does not mention are unknown), so every goal
    literal must be stated by ``when`` or made so by a stage, and not undone later."""
    for b, where in ((b, f"{at}[{k}]") for _, at, tree in spec.all_trees() for k, b in enumerate(tree)):
        bound = {tok for lit in b.when if lit[0] != "not" for tok in lit if tok.startswith("?")}
        for lit in [*b.goal, *(("stage", *t.args) for t in b.stages)]:
            free = sorted(tok for tok in lit if tok.startswith("?") and tok not in bound)
            if free:
                raise spec.error(where, f"{free[0]} is not bound by a positive `when` literal of this branch")
        true = {lit for lit in b.when if lit[0] != "not"}
        false = {lit[1:] for lit in b.when if lit[0] == "not"}
        both = sorted(true & false)
        if both:  # no state has a fact and its negation: the branch could never be chosen
            raise spec.error(where, f"`when` asks for {list(both[0])} and for its negation, so no state satisfies it "
                                    f"and this branch is never chosen")
        for t in b.stages:
            add, delete = dm.ground(t.action, t.args)
            true -= set(delete)
            false |= set(delete)
            true |= set(add)
            false -= set(add)
        for lit in b.goal:
            ok = lit[1:] in false if lit[0] == "not" else lit in true
            if not ok:
                shown = " then ".join(f"{t.action}({', '.join(t.args)})" for t in b.stages) or "no stages"
                raise spec.error(where, f"static and planned must pursue the same goal, but {shown} does not "
                                        f"reach {list(lit)} from a state where `when` holds "
                                        f"(say it in `when`, or add the stage that achieves it)")


def _check_pattern(spec: TaskSpec, dm: DomainModel, where: str, lit: tuple[str, ...], variables: bool) -> None:
    """A declared pattern names a predicate of the domain with its arity, and only request
    arguments it has (``$robot`` too) or, where allowed, ``?variables``."""
    atom = lit[1:] if lit[0] == "not" else lit
    if atom[0] not in dm.predicates:
        raise spec.error(where, f"unknown predicate {atom[0]!r}{reader.suggest(atom[0], dm.predicates)} "
                                f"(the domain declares {', '.join(sorted(dm.predicates))})")
    arity = len(dm.predicates[atom[0]])
    if len(atom) - 1 != arity:
        raise spec.error(where, f"{atom[0]!r} takes {arity} argument(s), got {len(atom) - 1}: {list(lit)}")
    args = [a.name for a in spec.args] + ["robot"]
    for tok in atom[1:]:
        if tok.startswith("$") and tok[1:] not in args:
            raise spec.error(where, f"unknown request argument {tok!r}"
                                    f"{reader.suggest(tok, ['$' + a for a in args])} "
                                    f"(this task's: {', '.join('$' + a for a in args)})")
        if tok.startswith("?") and not variables:
            raise spec.error(where, f"{tok}: a ?variable is not allowed here")


def _check_meaning(spec: TaskSpec, dm: DomainModel) -> tuple[Binding, ...]:
    """Hazards, people's roles and bindings against the domain; bindings get their object types."""
    for k, h in enumerate(spec.hazards):
        _check_pattern(spec, dm, f"hazards[{k}].fact", h.fact, variables=True)
    if spec.people is not None:
        args = [a.name for a in spec.args]
        if spec.people.person not in args:
            raise spec.error("people.person", f"no request argument {spec.people.person!r}"
                                              f"{reader.suggest(spec.people.person, args)} (this task's: "
                                              f"{', '.join(args) or 'none'})")
        for role, lits in spec.people.roles.items():
            for lit in lits:
                _check_pattern(spec, dm, f"people.{role}", lit, variables=True)
    for lit in spec.invariants:
        _check_pattern(spec, dm, "derived.invariants", lit, variables=False)
    for lit in spec.restore:
        if lit[0] == "not":
            raise spec.error("problem.restore", f"a pattern of facts that hold (no 'not'), got {list(lit)}")
        _check_pattern(spec, dm, "problem.restore", lit, variables=True)
    out = []
    for k, b in enumerate(spec.bindings):
        _check_pattern(spec, dm, f"bindings[{k}].fact", b.fact, variables=True)
        wanted = dm.predicates[b.fact[0]][b.fact.index(b.object) - 1]
        types = tuple(sorted(t for t, chain in dm.types.items() if wanted in chain)) if wanted else ()
        out.append(b.resolve(types))
    return tuple(out)


def _check_example_types(task: PddlTaskType, world: WorldState, used: list[tuple[str, ...]]) -> None:
    """An [example] object the goal or a fact names must have a type of the domain: else the
    problem leaves it out and UP reports "unknown object" at a line of the generated problem."""
    names = {tok for lit in used for tok in lit}
    for name, typ in sorted(world.objects.items()):
        if name in names and typ not in task.domain.types:
            raise task.spec.error("example", f"objects.{name}: {typ!r} is not a type of {task.spec.domain_file.name}"
                                             f"{reader.suggest(typ, task.domain.types)} (its types: "
                                             f"{', '.join(sorted(task.domain.types)) or 'none'})")


def _check_example(task: PddlTaskType) -> None:
    from planners.examples import example_context

    hooks = task.spec.folder / "task.py"
    try:  # what upTsk plans from: task.py's hooks too (check_args, extra_facts, check_terminate)
        ctx = example_context(task)
        if ctx is None:
            return
        world, goal, extra = task.update_inputs(ctx)
        task.check_terminate(ctx)
    except BadRequest as exc:
        raise task.spec.error("example", f"args: {exc}") from None
    except Exception as exc:  # noqa: BLE001 - the folder's own hooks (DefinitionError: extra_facts' shape)
        # a warning, not a refusal: a task whose hook fails at run time ends alone, with its reason
        # in the trace, and the run goes on; the user hears of it before any run
        line = exc.line if isinstance(exc, DefinitionError) else hook_line(exc, hooks)
        why = exc.reason if isinstance(exc, DefinitionError) else f"{type(exc).__name__}: {exc}"
        reader.warn_at(hooks, line, "", f"a hook fails on the [example]: {why}; every request of this type "
                                        "will end with cause error")
        return
    _check_example_types(task, world, [*goal, *world.facts])
    text, init, _ = task.problem_text(ctx, world, goal, extra)
    where = f"{task.spec.folder / 'task.toml'} [example] problem"
    load_problem_text(task.domain.checked, text.problem, where)
    result = task.planner.solve(text, timeout=task.timeout)
    if result.status is PlanStatus.ERROR:  # e.g. a feature the optimal search cannot handle (axioms)
        raise DefinitionError(task.spec.domain_file, f"the planner fails on the {where}: {result.message}")
    if result.status is PlanStatus.UNSOLVABLE:  # tasker check promises a solvable example: say it is not
        left_out = [list(f) for f in sorted(world.facts) if tuple(f) not in init]
        task.spec.warn("example", f"no plan reaches the goal {[list(g) for g in goal]} from the [example] world"
                                  + (f"; left out of the problem (an object or predicate the domain or [example] "
                                     f"objects do not declare): {left_out}" if left_out else "")
                                  + "; a request like it will end 'upTsk unsolvable'")
    if result.solved and result.plan is not None:  # what the plan shows about the tree and the goal
        examplecheck.check(task, ctx, examplecheck.example_stages(task, ctx, result.plan))
    if result.status is PlanStatus.TIMEOUT:  # not solved, not proven unsolvable: say so, not "solved"
        task.spec.warn("task.timeout_s", f"the planner did not finish the [example] within timeout_s = "
                                         f"{task.timeout:g} s (raise it, or simplify the domain); a request like it "
                                         f"falls back to the [static] template for upTsk")


def load_task(folder: str | Path, *, use_cache: bool = True) -> PddlTaskType:
    """Load one task folder; raise :class:`~planners.checks.DefinitionError` naming the faulty file.

    ``use_cache=False`` solves the example even when the folder's content passed before
    (``tasker check`` does, so that it reports what the planner says today)."""
    folder = Path(folder)
    spec = read_task_toml(folder / "task.toml")
    # what the checks read: task.toml, the domain and task.py (not, e.g., a problem.pddl lying beside them)
    key = cache.content_key("task-folder", _file_parts([folder / "task.toml", spec.domain_file, folder / "task.py"]))
    remembered = cache.remembered("task-folder", key) if use_cache else None
    # a remembered folder skips unified-planning's reading of the domain (and its import, ~1 s);
    # the DomainModel is read the same way either way (planners.schema), so answers do not depend on it
    dm = domain_model(remembered_domain(spec.domain_file) if remembered is not None else load_domain(spec.domain_file))
    _cross_check(spec, dm)
    _check_suspension(spec, dm)
    bindings = _check_meaning(spec, dm)
    # a temporal folder's FolderPlanner has Planner's interface (name, solve) but is not one: hence the ignore
    task = PddlTaskType(spec, dm, hooks=_load_hooks(spec), planner=planner_for(spec, dm))  # type: ignore[arg-type]
    task.meaning = meaning_of(spec, bindings)
    task.priority = spec.priority
    if remembered is not None:  # what the checks found doubtful then is as true now: said again
        for w in remembered.get("warnings", []):
            if isinstance(w, dict):
                warnings.warn_explicit(reader.InputWarning(str(w.get("text"))), reader.InputWarning,
                                       str(w.get("file")), int(w.get("line") or 0), module="tasker.support.reader")
    else:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", reader.InputWarning)
            _check_example(task)
        said = [w for w in caught if issubclass(w.category, reader.InputWarning)]
        for w in caught:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno, module="tasker.support.reader")
        cache.record("task-folder", key, {"folder": str(folder.resolve()), "name": spec.name,
                                          "warnings": [{"text": str(w.message), "file": w.filename,
                                                        "line": w.lineno} for w in said]})
    return task


def load_task_folder(path: str | Path, *, use_cache: bool = True) -> list[PddlTaskType]:
    """Task types from ``path``: a task folder, or a folder of task folders (sorted by name)."""
    path = Path(path)
    if (path / "task.toml").is_file():
        return [load_task(path, use_cache=use_cache)]
    if not path.is_dir():
        raise DefinitionError(path, "not a task folder (no task.toml) nor a folder of task folders")
    tasks = [load_task(p, use_cache=use_cache) for p in sorted(path.iterdir()) if (p / "task.toml").is_file()]
    if not tasks:
        raise DefinitionError(path, "holds no task folder (a subfolder with a task.toml)")
    names = [t.name for t in tasks]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise DefinitionError(path, f"duplicate task name(s) {dup}")
    return tasks


def store_loader(folder: str | Path) -> list[PddlTaskType]:
    """The ``tasker.loaders`` entry point: task folders in ``folder``, or none (never an error
    for a folder holding only ``*.py`` task types); malformed task folders still raise."""
    path = Path(folder)
    if (path / "task.toml").is_file() or any((p / "task.toml").is_file() for p in path.iterdir() if p.is_dir()):
        return load_task_folder(path)
    return []
