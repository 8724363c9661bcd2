"""What a task type needs of a domain, read with Fast Downward's own PDDL parser.

:class:`DomainSchema` holds a domain's name, types (each with its ancestors),
predicates (argument types), numeric functions and, per action, its parameters, its
unconditional Boolean effects and its constant cost.  :mod:`planners.problem` builds
problems from it; :mod:`planners.loader` checks ``task.toml`` against it.

It is read by the parser of the installed ``fast_downward.translate`` package — the
one that reads every problem this package solves — so it needs neither
unified-planning nor pyparsing: a process whose task folders passed their checks
before (:mod:`planners.cache`) loads them without importing either (about a second
of start-up).  unified-planning's reader stays the *checker* of a domain
(:func:`planners.checks.load_domain`: errors with file, line and column); the schema
is always read this way, checked or remembered, so the two paths cannot disagree.

The translator's parser consults its module-global options (``--keep-no-ops``: an
action without effects is kept, as PDDL and unified-planning keep it), so a read
holds :data:`planners.translate.TRANSLATE_LOCK` like a translation does.
"""

from __future__ import annotations

import contextlib
import functools
import io
from dataclasses import dataclass

from planners.translate import TRANSLATE_LOCK, domain_sexp
from tasker.errors import SchemaError as SchemaError  # defined there; re-exported here

OBJECT_TYPE = "object"
"""PDDL's root type; a type of the schema only in domains that use it (see :func:`read_schema`)."""


@dataclass(frozen=True, slots=True)
class EffectTemplate:
    """One unconditional Boolean effect of an action: ``(fluent, args, positive)``.

    ``args`` holds parameter names prefixed with ``?`` or object names.
    """

    fluent: str
    args: tuple[str, ...]
    positive: bool


@dataclass(frozen=True, slots=True)
class ActionModel:
    """What a task type needs of one PDDL action: ``param_types`` are the parameters'
    declared types, by position (``""`` for an untyped one)."""

    name: str
    params: tuple[str, ...]
    effects: tuple[EffectTemplate, ...]
    constant_cost: float | None
    param_types: tuple[str, ...] = ()
    precondition: tuple[EffectTemplate, ...] | None = ()
    """The precondition as a conjunction of literals (``positive`` False: a negated one; ``=`` may
    appear as a fluent), or None when it is more than that (a disjunction, a quantifier): then
    applicability is not decided from it (:meth:`planners.problem.DomainModel.unmet`)."""


@dataclass(frozen=True, slots=True)
class DomainSchema:
    """A domain as task types see it (see the module docstring)."""

    name: str
    types: tuple[tuple[str, frozenset[str]], ...]
    predicates: tuple[tuple[str, tuple[str, ...]], ...]
    functions: frozenset[str]
    actions: tuple[ActionModel, ...]
    constants: tuple[tuple[str, str], ...] = ()
    """The domain's ``(:constants ...)``: ``(name, type)``, ``""`` for an untyped one."""


def read_schema(text: str) -> DomainSchema:
    """The schema of a domain given as PDDL text (memoised per process: it is immutable)."""
    return _read(text)


@functools.lru_cache(maxsize=64)
def _read(text: str) -> DomainSchema:
    from fast_downward.translate import options as fd_options
    from fast_downward.translate import pddl
    from fast_downward.translate.pddl_parser import parsing_functions
    from fast_downward.translate.pddl_parser.parse_error import ParseError

    with TRANSLATE_LOCK, contextlib.redirect_stdout(io.StringIO()):
        fd_options.set_options(["domain.pddl", "problem.pddl", "--keep-no-ops"])
        try:
            nested = domain_sexp(text)  # read once per process, shared with the translator
            (name, _req, types, _type_dict, constants, predicates, _pred_dict, functions, actions,
             _axioms) = parsing_functions.parse_domain_pddl(parsing_functions.Context(), nested)
        except (ParseError, SystemExit) as exc:  # the translator reports bad input both ways
            raise SchemaError(" ".join(str(exc).split())) from None
        except Exception as exc:  # noqa: BLE001 - e.g. an assertion on an effect it cannot represent
            raise SchemaError(f"{type(exc).__name__}: {' '.join(str(exc).split())}") from None

    # as unified-planning reads PDDL: ``object`` is a user type (the root of all others) only
    # when something is untyped or typed ``object``; otherwise it is no type of the domain
    typed = [*(a for p in predicates if p.name != "=" for a in p.arguments),
             *(a for f in functions for a in f.arguments), *constants, *(p for a in actions for p in a.parameters)]
    rooted = any(t.type_name == OBJECT_TYPE for t in typed)

    def type_of(t: str) -> str:
        return "" if t == OBJECT_TYPE and not rooted else t

    def conjunction(c: pddl.Condition) -> tuple[EffectTemplate, ...] | None:
        if isinstance(c, pddl.Truth):
            return ()
        if isinstance(c, pddl.Literal):
            return (EffectTemplate(c.predicate, tuple(str(x) for x in c.args), not c.negated),)
        if isinstance(c, pddl.Conjunction):
            out: list[EffectTemplate] = []
            for part in c.parts:
                lits = conjunction(part)
                if lits is None:
                    return None
                out += lits
            return tuple(out)
        return None  # a disjunction or a quantifier: not a plain conjunction of literals

    def action(a: pddl.Action) -> ActionModel:
        effects = tuple(
            EffectTemplate(e.literal.predicate, tuple(e.literal.args), not e.literal.negated)
            for e in a.effects if not e.parameters and isinstance(e.condition, pddl.Truth)
        )
        cost = a.cost.expression.value if isinstance(getattr(a.cost, "expression", None),
                                                     pddl.NumericConstant) else None
        return ActionModel(a.name, tuple(p.name.lstrip("?") for p in a.parameters), effects,
                           None if cost is None else float(cost), tuple(type_of(p.type_name) for p in a.parameters),
                           conjunction(a.precondition))

    return DomainSchema(
        name=name,
        types=tuple((t.name, frozenset({t.name, *t.supertype_names}) - (set() if rooted else {OBJECT_TYPE}))
                    for t in types if rooted or t.name != OBJECT_TYPE),
        predicates=tuple((p.name, tuple(type_of(arg.type_name) for arg in p.arguments))
                         for p in predicates if p.name != "="),
        functions=frozenset(f.name for f in functions),
        actions=tuple(action(a) for a in actions),
        constants=tuple((c.name, type_of(c.type_name)) for c in constants),
    )

