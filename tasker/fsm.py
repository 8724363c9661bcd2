"""The dynamic agent's hierarchical FSM of Fig. 5: the one definition.

Everything about the FSM is derived from the tables of this module:

* :class:`FsmState` -- the leaf states, in the paper's names;
* :data:`PARENT` -- the superstate that holds each state (Fig. 5a-c), so
  ``FsmState.superstate`` and ``FsmState.in_cmd`` are read from it;
* :data:`TRANSITIONS` -- every transition as ``source --event [guards]--> target``;
* :data:`LATCHES` -- the initial conditions the harmoniser sets (``ic_start``,
  ``ic_susp``, ``ic_term``; Fig. 5 and eqs. 22-27): the agent *latches* each when its
  command arrives and holds it while it is in one of the states the latch names; in any
  other state it is void.  A guard of the table reads a latched condition by its name.

A row is taken in one of two ways.  An *event* row is fired by the source state's
behaviour when a hook is done (``planned``, ``finished``, ``stage_failed``, ...): the
runner fires the event (:func:`resolve`) and the table picks the row whose guards hold.
A *command* row (``auto``) is taken as soon as its guards hold: the runner asks
:func:`enabled` whenever it steps in the source state (in ``exeTsk`` also as each stage
begins, eq. 26), and the first such row, in table order, whose guards all hold is taken.
So what a ``susp`` does in a blocking stage, what a ``term`` does in ``cmd`` and when a
waiting agent secures its hazard are rows and latches here, not flags in the runner.

The runner (:mod:`tasker.agent`) never names a target state, and evaluates every guard
named here (it checks, on import, that it knows them all).  The checks
(:func:`check`, :func:`check_table`) and the diagrams (:func:`to_mermaid`,
:func:`to_dot`) read the same tables, so the picture and the behaviour cannot drift
apart.  The definition stays data and the code that runs it stays apart, with guards
and conditions on the transitions, as python-statemachine and ``transitions`` keep them.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from enum import StrEnum

from tasker.errors import FSMError


class FsmState(StrEnum):
    """Leaf states of the dynamic agent's hierarchical FSM (Fig. 5)."""

    INIT_COMM = "initComm"
    COMP_SP = "compSP"
    UP_TSK = "upTsk"
    EXE_TSK = "exeTsk"
    GEN_SUSP = "genSusp"
    EXE_SUSP = "exeSusp"
    WAIT = "wait"
    END = "end"

    @property
    def superstate(self) -> str:
        """The top-level state of Fig. 5a that holds this leaf: ``init``, ``cmd``, ``wait`` or ``end``."""
        return _TOP[self]

    @property
    def in_cmd(self) -> bool:
        """True for the leaves of ``cmd``: the agent commands the robot (at most one may)."""
        return _TOP[self] == "cmd"


S = FsmState

PARENT: Mapping[str, str | None] = {
    "init": None, "cmd": None, "susp": "cmd",
    S.INIT_COMM: "init", S.COMP_SP: "init",
    S.UP_TSK: "cmd", S.EXE_TSK: "cmd", S.GEN_SUSP: "susp", S.EXE_SUSP: "susp",
    S.WAIT: None, S.END: None,
}
"""Each state's enclosing superstate (``None`` at the top level of Fig. 5a)."""

COMPOSITES: tuple[str, ...] = ("init", "cmd", "susp")
"""The composite states, outermost first."""


def _top(state: str) -> str:
    while (parent := PARENT[state]) is not None:
        state = parent
    return str(state)


_TOP = {s: _top(s) for s in FsmState}

HIERARCHY: dict[str, tuple[str, ...]] = {
    "init": tuple(s.value for s in FsmState if PARENT[s] == "init"),
    "cmd": tuple(s.value for s in FsmState if PARENT[s] == "cmd") + ("susp",),
    "susp": tuple(s.value for s in FsmState if PARENT[s] == "susp"),
    "wait": (),
    "end": (),
}
"""Superstates and their children (Fig. 5a-c), derived from :data:`PARENT`."""


@dataclass(frozen=True, slots=True)
class Transition:
    """``source --event [guards]--> target``: taken when every guard holds.

    ``auto`` marks a command row, taken as soon as its guards hold (see the module
    docstring); ``condition`` says in the paper's terms when the row is taken, for diagrams.
    """

    source: S
    event: str
    target: S
    guards: tuple[str, ...] = ()
    condition: str = ""
    auto: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.guards, tuple) or not all(isinstance(g, str) and g for g in self.guards):
            raise FSMError(f"transition {self.source} --{self.event}-->: guards must be a tuple of names, "
                           f"got {self.guards!r}")


@dataclass(frozen=True, slots=True)
class Latch:
    """An initial condition the agent latches: ``name`` (a guard), set by the command ``command``.

    The agent holds it while it is in one of ``held_in``.  Elsewhere it is void: a
    command that arrives there is dropped, and entering such a state drops a latched
    one -- which is how the row that acts on it takes it.
    """

    name: str
    command: str
    held_in: frozenset[S]
    condition: str = ""


TRANSITIONS: tuple[Transition, ...] = (
    Transition(S.INIT_COMM, "initialised", S.COMP_SP, condition="initialised"),
    # init and wait take a latched command at once (f^compSP, eqs. 22, 27): a term before a start
    Transition(S.COMP_SP, "term", S.END, ("ic_term",), auto=True),
    Transition(S.COMP_SP, "start", S.UP_TSK, ("ic_start",), auto=True),
    Transition(S.UP_TSK, "planned", S.EXE_TSK, ("has_stages",), "exeTsk built"),
    Transition(S.UP_TSK, "planned", S.END, ("no_stages",), "nothing left to do"),
    Transition(S.UP_TSK, "plan_failed", S.END, condition="planning failed"),
    # eq. 26: a suspendable stage ends for ic_susp; a blocking one runs to its goal with ic_susp held (eq. 25).
    # Not in Fig. 5: ic_term in exeTsk suspends safely the same way, then the task ends (docs/model.md, departures)
    Transition(S.EXE_TSK, "suspend", S.GEN_SUSP, ("ic_susp", "suspendable"), auto=True),
    Transition(S.EXE_TSK, "suspend", S.GEN_SUSP, ("ic_term", "suspendable"), "then end", auto=True),
    Transition(S.EXE_TSK, "finished", S.END, condition="ic_taskFinished"),
    # not in Fig. 5, where a failed stage ends the task as it stands: the failure latches ic_term and the
    # task is first made safe (docs/model.md, departures), then exeSusp --finished [ic_term]--> end
    Transition(S.EXE_TSK, "stage_failed", S.GEN_SUSP, condition="latches ic_term: suspend safely, then end"),
    Transition(S.GEN_SUSP, "planned", S.EXE_SUSP, condition="exeSusp built"),
    Transition(S.GEN_SUSP, "plan_failed", S.END, condition="suspension planning failed"),
    Transition(S.EXE_SUSP, "finished", S.WAIT, ("not_ic_term",), "exeSusp finished"),
    Transition(S.EXE_SUSP, "finished", S.END, ("ic_term",), "exeSusp finished"),
    # not in Fig. 5: under the fallback strategy a stage of exeSusp that cannot run is planned around once
    # (genSusp again, from the world as it is: docs/model.md, departures); otherwise the task ends
    Transition(S.EXE_SUSP, "stage_failed", S.GEN_SUSP, ("recovers",), "plan around it, once (fallback)"),
    Transition(S.EXE_SUSP, "stage_failed", S.END, condition="stage failed"),
    Transition(S.WAIT, "term", S.END, ("ic_term",), auto=True),
    # not in Fig. 5: hazard-aware waiting (docs/model.md) lets a waiting task secure its hazard,
    # then exeSusp --finished [not_ic_term]--> wait as after any suspension
    Transition(S.WAIT, "secure", S.GEN_SUSP, ("ic_start", "secure"), "a hazard's budget runs out", auto=True),
    Transition(S.WAIT, "start", S.UP_TSK, ("ic_start",), auto=True),
) + tuple(
    Transition(s, "error", S.END, condition="exception in a hook, a skill or the planner")
    for s in FsmState if s is not S.END
)
"""Every transition of Fig. 5, plus ``error`` from every state (a raising hook ends its task),
``exeTsk --suspend [ic_term, suspendable]--> genSusp`` and ``exeTsk --stage_failed--> genSusp``
(a term or a failure ends a task through its safe suspension) and ``wait --secure--> genSusp``
(hazard-aware waiting): departures documented in ``docs/model.md``."""

LATCHES: tuple[Latch, ...] = (
    Latch("ic_start", "start", frozenset({S.INIT_COMM, S.COMP_SP, S.WAIT}),
          "acts in init and wait; void in cmd, where the agent already commands the robot"),
    Latch("ic_susp", "susp", frozenset({S.UP_TSK, S.EXE_TSK}),
          "held through upTsk and blocking stages until a suspendable stage (eqs. 25-26); void elsewhere"),
    Latch("ic_term", "term", frozenset(FsmState) - {S.END},
          "held to the end; also latched by the task's own check_terminate and by a failed stage"),
)
"""What each command latches and where it is held (:class:`Latch`)."""

TERM_CAUSES: tuple[str, ...] = ("self", "term", "failed")
"""Who latched ``ic_term``, weakest first: the task's own ``check_terminate`` (in ``compSP``,
``wait`` and ``exeTsk``), the harmoniser's ``term``, a failed stage.  A later ``ic_term`` replaces
a latched one only if its cause ranks higher: a ``term`` overrides the task's own ``ic_term``;
nothing overrides a failure being made safe (the task ends with the failure's reason)."""

LATCH_DATA: Mapping[str, str] = {"secure": "ic_start"}
"""Guards that read the data of a latched command: ``secure`` is the latched start's
``secure`` (hazard-aware waiting), meaningful only with ``ic_start``."""

GUARD_MEANING: Mapping[str, str] = {
    "has_stages": "the plan upTsk built has stages",
    "no_stages": "the plan upTsk built has none: nothing is left to do (R6)",
    "ic_start": "a start is latched",
    "ic_susp": "a susp is latched",
    "ic_term": "ic_term is latched: the harmoniser's term, the task's own check_terminate or a failed stage",
    "not_ic_term": "no ic_term is latched",
    "secure": "the latched start asks to secure a hazard (hazard-aware waiting)",
    "suspendable": "the stage of exeTsk about to run or running is suspendable (eq. 26), not blocking (eq. 25)",
    "recovers": "the task plans around a stage of exeSusp that cannot run (the fallback strategy), not yet in "
                "this suspension",
}
"""What each guard means; the runner evaluates them."""

GUARDS: tuple[str, ...] = tuple(sorted({g for t in TRANSITIONS for g in t.guards}))
"""Guard names a runner must evaluate."""

_BY_EVENT: dict[tuple[S, str], tuple[Transition, ...]] = {}
for _t in TRANSITIONS:
    _BY_EVENT[(_t.source, _t.event)] = _BY_EVENT.get((_t.source, _t.event), ()) + (_t,)
_AUTO: dict[S, tuple[Transition, ...]] = {s: tuple(t for t in TRANSITIONS if t.auto and t.source is s)
                                         for s in FsmState}
_ALLOWED = {(t.source, t.target) for t in TRANSITIONS}
LATCH_OF: Mapping[str, Latch] = {latch.command: latch for latch in LATCHES}
"""The latch each command (``start``, ``susp``, ``term``) sets."""


def check_table(transitions: Iterable[Transition], latches: Iterable[Latch],
                meanings: Mapping[str, str], data: Mapping[str, str]) -> list[str]:
    """What is wrong with an FSM definition: an empty list for a sound one.

    Every state but ``end`` has an ``error`` row and is reachable from ``initComm``;
    ``end`` has no row; every guard has a meaning; a command row reads a latched
    condition; a row guarded by a latch leaves a state that holds it (else it could
    never be taken); every latch is read where it is held; no row is shadowed by an
    unguarded one before it.
    """
    rows, latch = tuple(transitions), {x.name: x for x in latches}
    problems: list[str] = []
    seen: set[S] = {S.INIT_COMM}
    frontier = [S.INIT_COMM]
    while frontier:
        s = frontier.pop()
        for t in rows:
            if t.source is s and t.target not in seen:
                seen.add(t.target)
                frontier.append(t.target)
    problems += [f"{s.value} cannot be reached from initComm" for s in FsmState if s not in seen]
    for s in FsmState:
        if s is not S.END and not any(t.source is s and t.event == "error" and t.target is S.END for t in rows):
            problems.append(f"{s.value} has no error row to end")
    problems += [f"end has a row: {t.event} -> {t.target.value}" for t in rows if t.source is S.END]
    for t in rows:
        name = f"{t.source.value} --{t.event}--> {t.target.value}"
        problems += [f"{name}: guard {g!r} has no meaning" for g in t.guards if g not in meanings]
        if t.auto and not any(g in latch for g in t.guards):
            problems.append(f"{name}: a command row must read a latched condition")
        for g in t.guards:
            held = latch.get(data.get(g, g))
            if held is not None and t.source not in held.held_in:
                problems.append(f"{name}: {held.name} is never held in {t.source.value}")
    for x in latch.values():
        if not any(t.auto and x.name in t.guards and t.source in x.held_in for t in rows):
            problems.append(f"latch {x.name}: no command row reads it where it is held")
    for i, t in enumerate(rows):
        for u in rows[:i]:
            if u.source is t.source and not u.guards and (u.event == t.event or (u.auto and t.auto)):
                problems.append(f"{t.source.value} --{t.event}--> {t.target.value} is shadowed by "
                                f"{u.source.value} --{u.event}--> {u.target.value}, which has no guard")
    return problems


_problems = check_table(TRANSITIONS, LATCHES, GUARD_MEANING, LATCH_DATA)
if _problems:
    raise FSMError("the dynamic-agent FSM is malformed: " + "; ".join(_problems))


def check(source: S, target: S) -> None:
    """Raise :class:`FSMError` unless Fig. 5 has a transition ``source -> target``."""
    if (source, target) not in _ALLOWED:
        raise FSMError(f"the dynamic-agent FSM has no transition {source.value} -> {target.value}")


def events_of(state: S) -> list[str]:
    """The events the FSM accepts in ``state``, in table order."""
    return list(dict.fromkeys(t.event for t in TRANSITIONS if t.source is state))


def _holds(t: Transition, guard: Callable[[str], bool]) -> bool:
    return all(guard(g) for g in t.guards)


def resolve(state: S, event: str, guard: Callable[[str], bool]) -> Transition:
    """The transition ``event`` takes from ``state``: the first in the table whose guards hold.

    Raises :class:`FSMError` if the state has no such event or no guard holds.
    """
    options = _BY_EVENT.get((state, event))
    if not options:
        raise FSMError(f"the dynamic-agent FSM has no event {event!r} in {state.value}; "
                       f"it accepts {events_of(state)}")
    for t in options:
        if _holds(t, guard):
            return t
    raise FSMError(f"event {event!r} in {state.value}: no guard holds among {[list(t.guards) for t in options]}")


def enabled(state: S, guard: Callable[[str], bool]) -> Transition | None:
    """The command row to take in ``state`` now: the first, in table order, whose guards all hold."""
    for t in _AUTO[state]:
        if _holds(t, guard):
            return t
    return None


def held_in(state: S) -> tuple[str, ...]:
    """The latched conditions ``state`` holds, in :data:`LATCHES` order."""
    return tuple(x.name for x in LATCHES if state in x.held_in)

def _label(t: Transition) -> str:
    label = t.event + (f" [{', '.join(t.guards)}]" if t.guards else "")
    return f"{label} / {t.condition}" if t.condition and t.condition != t.event else label


def _holding(state: str) -> str:
    """``holds ic_start, ic_term``: what a leaf holds latched, shown under its name in the diagrams."""
    held = held_in(FsmState(state))
    return f"holds {', '.join(held)}" if held else ""


def to_mermaid(*, errors: bool = False) -> str:
    """Fig. 5 as a Mermaid ``stateDiagram-v2`` with its composite states, from the tables.

    Each leaf shows the latched conditions it holds (:data:`LATCHES`), each arrow its
    event and guards.  ``errors`` adds the ``error`` transitions (one from every state),
    left out by default to keep the figure readable.
    """
    lines = ["stateDiagram-v2", "    [*] --> initComm"]

    def leaf(name: str, indent: str) -> None:
        held = _holding(name)
        lines.append(f"{indent}{name} : {held}" if held else f"{indent}{name}")

    def block(name: str, indent: str) -> None:
        lines.append(f"{indent}state {name} {{")
        for child in PARENT:
            if PARENT[child] == name:
                if child in COMPOSITES:
                    block(str(child), indent + "    ")
                else:
                    leaf(str(child), indent + "    ")
        lines.append(f"{indent}}}")

    for c in COMPOSITES:
        if PARENT[c] is None:
            block(c, "    ")
    for child in PARENT:
        if PARENT[child] is None and child not in COMPOSITES and _holding(str(child)):
            leaf(str(child), "    ")  # a top-level leaf appears with its transitions; named here for what it holds
    for t in TRANSITIONS:
        if errors or t.event != "error":
            lines.append(f"    {t.source.value} --> {t.target.value} : {_label(t)}")
    lines.append("    end --> [*]")
    return "\n".join(lines) + "\n"


def to_dot(*, errors: bool = False) -> str:
    """Fig. 5 as Graphviz DOT with clusters for the composite states, from the tables."""
    lines = ["digraph FSM_dy {", "    compound=true;", "    start [shape=point];"]

    def leaf(name: str, indent: str, *attrs: str) -> None:
        held = _holding(name)
        attrs = ((f"label={json.dumps(name + chr(10) + held)}",) if held else ()) + attrs
        lines.append(f"{indent}{json.dumps(name)}" + (f" [{', '.join(attrs)}]" if attrs else "") + ";")

    def block(name: str, indent: str) -> None:
        lines.append(f"{indent}subgraph cluster_{name} {{")
        lines.append(f"{indent}    label={json.dumps(name)};")
        for child in PARENT:
            if PARENT[child] == name:
                if child in COMPOSITES:
                    block(str(child), indent + "    ")
                else:
                    leaf(str(child), indent + "    ")
        lines.append(f"{indent}}}")

    for c in COMPOSITES:
        if PARENT[c] is None:
            block(c, "    ")
    leaf("wait", "    ")
    leaf("end", "    ", "shape=doublecircle")
    lines.append('    start -> "initComm";')
    for t in TRANSITIONS:
        if errors or t.event != "error":
            lines.append(f"    {json.dumps(t.source.value)} -> {json.dumps(t.target.value)} "
                         f"[label={json.dumps(_label(t))}];")
    lines.append("}")
    return "\n".join(lines) + "\n"
