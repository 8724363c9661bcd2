"""What a task type needs of a temporal domain, read from unified-planning's model of it.

The classical path reads a domain with Fast Downward's parser (:mod:`planners.schema`), which
knows no durative action.  A temporal domain is read here into the same
:class:`~planners.schema.DomainSchema`, so :class:`~planners.problem.DomainModel`, the stage
builder, the load checks and the estimates work on it unchanged.  A durative action becomes an
:class:`~planners.schema.ActionModel` whose

* ``effects`` are its net Boolean effects, at start then at end (PDDL's order: a fact added at
  start and deleted at end is deleted; within one instant, add wins over delete);
* ``precondition`` is what must hold as it starts: its ``at start`` conditions and its ``over
  all`` ones that its ``at start`` effects do not make true (None when either is more than a
  conjunction of literals, or an ``at end`` condition can fail: then applicability is not
  decided from it);
* ``constant_cost`` is its duration when that is a fixed number (``(= ?duration 5)``): the
  stage's duration when ``task.toml`` gives neither ``travel`` nor ``duration``
  (:meth:`planners.stages.StageBuilder.from_step`), None otherwise.
"""

from __future__ import annotations

from fractions import Fraction
from typing import TYPE_CHECKING, Any

from planners.schema import OBJECT_TYPE, ActionModel, DomainSchema, EffectTemplate

if TYPE_CHECKING:
    import unified_planning as up


def schema_of(model: up.model.Problem) -> DomainSchema:
    """The schema of a domain UP has read (its objects, if any, are the domain's constants)."""
    def chain(t: Any) -> frozenset[str]:
        names = set()
        while t is not None:
            names.add(t.name)
            t = t.father
        return frozenset(names)

    return DomainSchema(
        name=model.name,
        types=tuple((t.name, chain(t)) for t in model.user_types),
        predicates=tuple((f.name, tuple(_type(p.type) for p in f.signature))
                         for f in model.fluents if f.type.is_bool_type()),
        functions=frozenset(f.name for f in model.fluents if not f.type.is_bool_type()),
        actions=tuple(_action(a) for a in model.actions),
        constants=tuple((o.name, _type(o.type)) for o in model.all_objects),
    )


def _type(t: Any) -> str:
    return "" if t.name == OBJECT_TYPE else str(t.name)


def _arg(x: Any) -> str:
    return f"?{x.parameter().name}" if x.is_parameter_exp() else str(x)


def _literals(conditions: list[Any]) -> list[EffectTemplate] | None:
    """Conditions as a conjunction of literals, or None when one is more than a literal."""
    out: list[EffectTemplate] = []
    todo = list(conditions)
    while todo:
        c = todo.pop(0)
        if c.is_and():
            todo[:0] = list(c.args)
            continue
        positive = not c.is_not()
        atom = c.arg(0) if c.is_not() else c
        if atom.is_fluent_exp() and atom.fluent().type.is_bool_type():
            out.append(EffectTemplate(atom.fluent().name, tuple(_arg(a) for a in atom.args), positive))
        elif atom.is_equals() and all(a.is_parameter_exp() or a.is_object_exp() for a in atom.args):
            out.append(EffectTemplate("=", tuple(_arg(a) for a in atom.args), positive))
        elif atom.is_true() and positive:
            continue
        else:
            return None
    return out


def _effects(effects: list[Any]) -> tuple[set[tuple[str, tuple[str, ...]]], set[tuple[str, tuple[str, ...]]]]:
    """The unconditional Boolean effects as (added, deleted) atoms ``(fluent, args)``."""
    add: set[tuple[str, tuple[str, ...]]] = set()
    delete: set[tuple[str, tuple[str, ...]]] = set()
    for e in effects:
        if e.is_conditional() or e.is_forall() or not e.fluent.type.is_bool_type() or not e.value.is_bool_constant():
            continue
        atom = (e.fluent.fluent().name, tuple(_arg(a) for a in e.fluent.args))
        (add if e.value.bool_constant_value() else delete).add(atom)
    return add, delete


def _action(a: Any) -> ActionModel:
    import unified_planning as up

    params = tuple(p.name for p in a.parameters)
    types = tuple(_type(p.type) for p in a.parameters)
    if not isinstance(a, up.model.DurativeAction):  # an instantaneous action (ROSPlan's, PDDL+)
        add, delete = _effects(list(a.effects))
        plain = _literals(list(a.preconditions))
        return ActionModel(a.name, params, _templates(add, delete - add), None, types,
                           None if plain is None else tuple(plain))
    start_add: set[tuple[str, tuple[str, ...]]] = set()
    start_del: set[tuple[str, tuple[str, ...]]] = set()
    end_add: set[tuple[str, tuple[str, ...]]] = set()
    end_del: set[tuple[str, tuple[str, ...]]] = set()
    for timing, effects in a.effects.items():
        add, delete = _effects(effects)
        if timing.is_from_start() and timing.delay == 0:
            start_add |= add
            start_del |= delete
        else:
            end_add |= add
            end_del |= delete
    net_add = end_add | (start_add - end_del)
    net_del = (end_del - end_add) | (start_del - start_add - end_add)
    at_start: list[Any] = []
    over_all: list[Any] = []
    decidable = True
    for interval, conds in a.conditions.items():
        if interval.lower == interval.upper and interval.lower.is_from_start() and interval.lower.delay == 0:
            at_start += conds
        elif interval.lower.is_from_start() and interval.upper.is_from_end():
            over_all += conds
        else:
            decidable = False  # an at-end or intermediate condition: not known as the stage starts
    pre: list[EffectTemplate] | None = None
    start = _literals(at_start)
    during = _literals(over_all)
    if decidable and start is not None and during is not None:
        made = {(f, args) for f, args in start_add}
        pre = start + [c for c in during if not (c.positive and (c.fluent, c.args) in made)]
    return ActionModel(a.name, params, _templates(net_add, net_del), _fixed_duration(a), types,
                       None if pre is None else tuple(pre))


def _templates(add: set[tuple[str, tuple[str, ...]]],
               delete: set[tuple[str, tuple[str, ...]]]) -> tuple[EffectTemplate, ...]:
    return (*(EffectTemplate(f, args, True) for f, args in sorted(add)),
            *(EffectTemplate(f, args, False) for f, args in sorted(delete)))


def _fixed_duration(a: Any) -> float | None:
    """The duration of ``(= ?duration N)``, or None when it is an expression or a range."""
    d = a.duration
    if d.lower != d.upper or d.is_left_open() or d.is_right_open():
        return None
    x = d.lower
    if x.is_int_constant() or x.is_real_constant():
        return float(Fraction(x.constant_value()))
    return None
