"""The dynamic agent's hierarchical FSM of Fig. 5: the one definition.

Everything about the FSM is derived from the three tables of this module:

* :class:`FsmState` -- the leaf states, in the paper's names;
* :data:`PARENT` -- the superstate that holds each state (Fig. 5a-c), so
  ``FsmState.superstate`` and ``FsmState.in_cmd`` are read from it;
* :data:`TRANSITIONS` -- every transition as ``source --event [guard]--> target``.

The agent (:mod:`tasker.agent`) never names a target state: it *fires an event*
(:meth:`Machine.fire`), and the table picks the transition whose guard holds.  The
checks (:func:`check`) and the diagrams (:func:`to_mermaid`, :func:`to_dot`) read the
same table, so the picture and the behaviour cannot drift apart.  Guards are named
here and evaluated by the runner (the agent supplies a predicate per guard name):
the definition stays data, the code that runs it stays apart (python-statemachine
keeps guards on transitions the same way).
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping
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
    """``source --event [guard]--> target``; ``condition`` is the paper's initial condition, for diagrams."""

    source: S
    event: str
    target: S
    guard: str | None = None
    condition: str = ""


TRANSITIONS: tuple[Transition, ...] = (
    Transition(S.INIT_COMM, "initialised", S.COMP_SP, condition="initialised"),
    Transition(S.COMP_SP, "start", S.UP_TSK, condition="ic_start"),
    Transition(S.COMP_SP, "term", S.END, condition="ic_term"),
    Transition(S.UP_TSK, "planned", S.EXE_TSK, guard="has_stages", condition="exeTsk built"),
    Transition(S.UP_TSK, "planned", S.END, guard="no_stages", condition="nothing left to do"),
    Transition(S.UP_TSK, "plan_failed", S.END, condition="planning failed"),
    Transition(S.EXE_TSK, "suspend", S.GEN_SUSP, condition="ic_susp | ic_term at a suspendable stage"),
    Transition(S.EXE_TSK, "finished", S.END, condition="ic_taskFinished"),
    # not in Fig. 5, where a failed stage ends the task as it stands: it is first made safe
    # (docs/model.md, departures), then exeSusp --finished [terminating]--> end
    Transition(S.EXE_TSK, "stage_failed", S.GEN_SUSP, condition="stage failed: suspend safely, then end"),
    Transition(S.GEN_SUSP, "planned", S.EXE_SUSP, condition="exeSusp built"),
    Transition(S.GEN_SUSP, "plan_failed", S.END, condition="suspension planning failed"),
    Transition(S.EXE_SUSP, "finished", S.WAIT, guard="not_terminating", condition="exeSusp finished"),
    Transition(S.EXE_SUSP, "finished", S.END, guard="terminating", condition="exeSusp finished after ic_term"),
    Transition(S.EXE_SUSP, "stage_failed", S.END, condition="stage failed"),
    Transition(S.WAIT, "start", S.UP_TSK, condition="ic_start"),
    Transition(S.WAIT, "term", S.END, condition="ic_term"),
    # not in Fig. 5: hazard-aware waiting (docs/model.md) lets a waiting task secure its hazard,
    # then exeSusp --finished--> wait as after any suspension
    Transition(S.WAIT, "secure", S.GEN_SUSP, condition="secure: a hazard's budget runs out"),
) + tuple(
    Transition(s, "error", S.END, condition="exception in a hook, a skill or the planner")
    for s in FsmState if s is not S.END
)
"""Every transition of Fig. 5, plus ``error`` from every state (a raising hook ends its task) and
``wait --secure--> genSusp`` (hazard-aware waiting, a departure documented in ``docs/model.md``)."""

GUARDS: tuple[str, ...] = tuple(sorted({t.guard for t in TRANSITIONS if t.guard is not None}))
"""Guard names a runner must evaluate."""

_BY_EVENT: dict[tuple[S, str], tuple[Transition, ...]] = {}
for _t in TRANSITIONS:
    _BY_EVENT[(_t.source, _t.event)] = _BY_EVENT.get((_t.source, _t.event), ()) + (_t,)
_ALLOWED = {(t.source, t.target) for t in TRANSITIONS}


def check(source: S, target: S) -> None:
    """Raise :class:`FSMError` unless Fig. 5 has a transition ``source -> target``."""
    if (source, target) not in _ALLOWED:
        raise FSMError(f"the dynamic-agent FSM has no transition {source.value} -> {target.value}")


def events_of(state: S) -> list[str]:
    """The events the FSM accepts in ``state``, in table order."""
    return list(dict.fromkeys(t.event for t in TRANSITIONS if t.source is state))


def resolve(state: S, event: str, guard: Callable[[str], bool]) -> Transition:
    """The transition ``event`` takes from ``state``: the first in the table whose guard holds.

    Raises :class:`FSMError` if the state has no such event or no guard holds.
    """
    options = _BY_EVENT.get((state, event))
    if not options:
        raise FSMError(f"the dynamic-agent FSM has no event {event!r} in {state.value}; "
                       f"it accepts {events_of(state)}")
    for t in options:
        if t.guard is None or guard(t.guard):
            return t
    raise FSMError(f"event {event!r} in {state.value}: no guard holds among {[t.guard for t in options]}")


def _label(t: Transition) -> str:
    label = t.event + (f" [{t.guard}]" if t.guard else "")
    return f"{label} / {t.condition}" if t.condition and t.condition != t.event else label


def to_mermaid(*, errors: bool = False) -> str:
    """Fig. 5 as a Mermaid ``stateDiagram-v2`` with its composite states, from the table.

    ``errors`` adds the ``error`` transitions (one from every state), left out by
    default to keep the figure readable.
    """
    lines = ["stateDiagram-v2", "    [*] --> initComm"]

    def block(name: str, indent: str) -> None:
        lines.append(f"{indent}state {name} {{")
        for child in PARENT:
            if PARENT[child] == name:
                if child in COMPOSITES:
                    block(str(child), indent + "    ")
                else:
                    lines.append(f"{indent}    {child}")
        lines.append(f"{indent}}}")

    for c in COMPOSITES:
        if PARENT[c] is None:
            block(c, "    ")
    for t in TRANSITIONS:
        if errors or t.event != "error":
            lines.append(f"    {t.source.value} --> {t.target.value} : {_label(t)}")
    lines.append("    end --> [*]")
    return "\n".join(lines) + "\n"


def to_dot(*, errors: bool = False) -> str:
    """Fig. 5 as Graphviz DOT with clusters for the composite states, from the table."""
    lines = ["digraph FSM_dy {", "    compound=true;", "    start [shape=point];"]

    def block(name: str, indent: str) -> None:
        lines.append(f"{indent}subgraph cluster_{name} {{")
        lines.append(f"{indent}    label={json.dumps(name)};")
        for child in PARENT:
            if PARENT[child] == name:
                if child in COMPOSITES:
                    block(str(child), indent + "    ")
                else:
                    lines.append(f"{indent}    {json.dumps(str(child))};")
        lines.append(f"{indent}}}")

    for c in COMPOSITES:
        if PARENT[c] is None:
            block(c, "    ")
    lines.append('    "wait";')
    lines.append('    "end" [shape=doublecircle];')
    lines.append('    start -> "initComm";')
    for t in TRANSITIONS:
        if errors or t.event != "error":
            lines.append(f"    {json.dumps(t.source.value)} -> {json.dumps(t.target.value)} "
                         f"[label={json.dumps(_label(t))}];")
    lines.append("}")
    return "\n".join(lines) + "\n"
