"""The dynamic agent's hierarchical FSM of Fig. 5, as data.

The definition (states, their superstates, allowed transitions and the initial
condition that triggers each) is kept apart from the code that runs it
(:mod:`tasker.agent`): the runner asks :func:`check` before every transition, so a
transition the paper does not draw is an error, not a silent surprise.
"""

from __future__ import annotations

from dataclasses import dataclass

from tasker.errors import FSMError
from tasker.messages import FsmState as S

HIERARCHY: dict[str, tuple[str, ...]] = {
    "init": ("initComm", "compSP"),
    "cmd": ("upTsk", "exeTsk", "susp"),
    "susp": ("genSusp", "exeSusp"),
    "wait": (),
    "end": (),
}
"""Superstates and their children (Fig. 5a-c); leaves are the :class:`FsmState` values."""


@dataclass(frozen=True, slots=True)
class Transition:
    source: S
    target: S
    condition: str


TRANSITIONS: tuple[Transition, ...] = (
    Transition(S.INIT_COMM, S.COMP_SP, "initialised"),
    Transition(S.COMP_SP, S.UP_TSK, "ic_start"),
    Transition(S.COMP_SP, S.END, "ic_term"),
    Transition(S.UP_TSK, S.EXE_TSK, "exeTsk built"),
    Transition(S.UP_TSK, S.END, "planning failed | nothing left to do"),
    Transition(S.EXE_TSK, S.GEN_SUSP, "ic_susp at a suspendable stage"),
    Transition(S.EXE_TSK, S.END, "ic_taskFinished | ic_term | stage failed"),
    Transition(S.GEN_SUSP, S.EXE_SUSP, "exeSusp built"),
    Transition(S.GEN_SUSP, S.END, "suspension planning failed"),
    Transition(S.EXE_SUSP, S.WAIT, "exeSusp finished"),
    Transition(S.EXE_SUSP, S.END, "exeSusp finished after ic_term | stage failed"),
    Transition(S.WAIT, S.UP_TSK, "ic_start"),
    Transition(S.WAIT, S.END, "ic_term"),
)

_ALLOWED = {(t.source, t.target) for t in TRANSITIONS}


def check(source: S, target: S) -> None:
    """Raise :class:`FSMError` unless Fig. 5 has a transition ``source -> target``."""
    if (source, target) not in _ALLOWED:
        raise FSMError(f"the dynamic-agent FSM has no transition {source.value} -> {target.value}")


def to_mermaid() -> str:
    """Fig. 5 as a Mermaid ``stateDiagram-v2`` with its composite states."""
    lines = ["stateDiagram-v2", "    [*] --> initComm"]
    lines += ["    state init {", "        initComm", "        compSP", "    }"]
    lines += ["    state cmd {", "        upTsk", "        exeTsk", "        state susp {",
              "            genSusp", "            exeSusp", "        }", "    }"]
    for t in TRANSITIONS:
        lines.append(f"    {t.source.value} --> {t.target.value} : {t.condition}")
    lines.append("    end --> [*]")
    return "\n".join(lines) + "\n"
