"""Reading ``task.toml``'s fields through :class:`tasker.support.reader.Table`, with their lines:
literals, stage templates and decision trees (``[[suspension]]``, ``[[trees.NAME]]``).

:mod:`planners.taskspec` reads a whole ``task.toml`` with it; every fault is a
:class:`~planners.checks.DefinitionError` naming the file, the line and the field."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from planners.checks import DefinitionError
from tasker.support import reader
from tasker.task import POLICIES

Literal = tuple[str, ...]


@dataclass(frozen=True, slots=True)
class StageTemplate:
    """One stage of a static strategy: an action with argument templates."""

    action: str
    args: tuple[str, ...]
    suspended: str | None = None


@dataclass(frozen=True, slots=True)
class Branch:
    """One branch of the suspension decision list (eq. 47), shared by both strategies.

    It applies when every ``when`` literal holds (``?vars`` are bound by the first match,
    in sorted order, and may be used in ``goal`` and ``stages``); ``planned`` plans to
    ``goal``, ``static`` runs ``stages`` — the load check proves the stages reach the goal.
    A ``policy = "conditional"`` branch trades safety for time: it is eligible only under
    that policy and when the expected interruption is at most ``max_interruption_s``."""

    when: tuple[Literal, ...] = ()
    goal: tuple[Literal, ...] = ()
    stages: tuple[StageTemplate, ...] = ()
    label: str = ""
    policy: str = "strict"
    max_interruption_s: float | None = None


DEFAULT_TREE = "default"
"""The name of the decision tree written as ``[[suspension]]``."""


def object_token(token: str) -> str:
    """A literal's argument as the domain reads it: an object name in lower case (``$at:NAME``'s
    name too); a request argument ``$name`` as written."""
    if token.startswith("$at:"):
        return "$at:" + token[4:].lower()
    return token if token.startswith("$") else token.lower()


class SpecReader:
    """Reads ``task.toml`` through :class:`tasker.support.reader.Table`; remembers field lines."""

    def __init__(self, file: Path) -> None:
        self.file = file
        self.lines: dict[str, int | None] = {}

    def fail(self, t: reader.Table, key: str | int | None, reason: str) -> DefinitionError:
        return definition_error(t.error(key, reason))

    def note(self, t: reader.Table, key: str | int | None = None) -> str:
        name = t.field(key)
        self.lines[name] = t.line(key)
        return name

    def literals(self, t: reader.Table, key: str, default: Any = None) -> tuple[Literal, ...]:
        value = t.raw(key, [] if default is None else default)
        self.note(t, key)
        if not isinstance(value, list):
            raise self.fail(t, key, 'expected a list of literals such as [["at", "$x", "$place"]], '
                                    f"got {value!r}")
        out: list[Literal] = []
        for lit in value:
            out.append(self.literal(t, key, lit))
        return tuple(out)

    def literal(self, t: reader.Table, key: str, lit: Any) -> Literal:
        if not isinstance(lit, list) or not lit or not all(isinstance(s, str) and s for s in lit):
            raise self.fail(t, key, f"a literal is a non-empty list of strings, got {lit!r}")
        if lit[0].lower() == "not" and len(lit) < 2:
            raise self.fail(t, key, f"'not' needs a predicate: {lit!r}")
        # PDDL names are case-insensitive and the domain is read in lower case: so are a predicate
        # and an object named here (a world's names are lower case); $arguments keep theirs
        head = 2 if lit[0].lower() == "not" else 1
        return (*(s.lower() for s in lit[:head]), *(object_token(s) for s in lit[head:]))

    def templates(self, t: reader.Table, key: str) -> tuple[StageTemplate, ...]:
        value = t.raw(key, [])
        self.note(t, key)
        if not isinstance(value, list):
            raise self.fail(t, key, "stages must be a list of {action = ..., args = [...]} tables")
        out = []
        for i, raw in enumerate(value):
            if not isinstance(raw, dict):
                raise self.fail(t, key, f"a stage is a table {{action = ..., args = [...]}}, got {raw!r}")
            st = reader.Table(self.file, raw, (*t.path, key, i), t._index)
            action = st.string("action").lower()  # PDDL names are case-insensitive
            args = st.raw("args", [])
            if not isinstance(args, list) or not all(isinstance(a, str) for a in args):
                raise self.fail(st, "args", f"stage {action!r}: expected a list of strings")
            sus = st.string("suspended", None)
            sus = None if sus is None else sus.lower()
            st.done()
            out.append(StageTemplate(action, tuple(object_token(a) for a in args), sus))
        return tuple(out)

    def branches(self, t: reader.Table, key: str) -> tuple[Branch, ...]:
        if key not in t:
            out = [Branch()]
        else:
            out = []
            tables = t.tables(key)
            for b in tables:
                policy = b.string("policy", "strict", choices=POLICIES)
                limit = b.number("max_interruption_s", None, min=0, max=reader.MAX_SECONDS)
                if (policy == "conditional") != (limit is not None):
                    raise self.fail(b, "max_interruption_s" if limit is not None else "policy",
                                    'a branch that trades safety for time has policy = "conditional" and '
                                    "max_interruption_s (the longest interruption it accepts), and only such a branch")
                out.append(Branch(self.literals(b, "when"), self.literals(b, "goal"), self.templates(b, "stages"),
                                  b.string("label", "", empty=True), policy,
                                  None if limit is None else float(limit)))
                self.note(b)
                b.done()
            if not out:
                raise self.fail(t, key, "needs at least one branch (the default case, with no 'when')")
            for k, branch in enumerate(out[:-1]):  # the first branch that holds is chosen: this one always does
                if not branch.when and branch.policy == "strict":
                    later = ", ".join(repr(x.label or f"suspension[{j}]") for j, x in enumerate(out[k + 1:], k + 1))
                    raise self.fail(tables[k], None, f"no 'when': it always holds, so the branches after it ({later}) "
                                                     "are never chosen; give it a 'when' or make it the last")
        last = out[-1]
        if last.when or last.policy != "strict":
            raise self.fail(t, key, "the last branch must have no 'when' and the strict policy (the default case)")
        return tuple(out)


def definition_error(exc: reader.InputError) -> DefinitionError:
    return DefinitionError(exc.file, f"{exc.field}: {exc.message}" if exc.field else exc.message, exc.line)


@contextmanager
def as_definition_error() -> Iterator[None]:
    try:
        yield
    except reader.InputError as exc:
        raise definition_error(exc) from None


def read_trees(r: SpecReader, top: reader.Table) -> dict[str, tuple[Branch, ...]]:
    """``[[trees.NAME]]``: more decision trees, each a list of branches like ``[[suspension]]``."""
    if "trees" not in top:
        return {}
    t = top.table("trees")
    out = {}
    for name in t.keys():
        if not name.isidentifier() or name == DEFAULT_TREE:
            raise r.fail(t, name, f"a tree's name is an identifier other than {DEFAULT_TREE!r} (the name of "
                                  f"[[suspension]]), got {name!r}")
        if not isinstance(t.raw(name), list):
            raise r.fail(t, name, f"expected branches as [[trees.{name}]] tables, like [[suspension]]")
        out[name] = r.branches(t, name)
    t.done()
    return out


