"""Stages, and the stage FSMs ``exeTsk`` and ``exeSusp`` built at run time.

A plan crosses into the model through this neutral data model: a planner, a static
template or a decision tree produces a :class:`StagePlan`, a sequence of
:class:`Stage` objects; the dynamic agent runs it.  Stages are data; the agent is
the runner.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any


class StageKind(StrEnum):
    """Eqs. 25-26: may the task be suspended while this stage runs?"""

    SUSPENDABLE = "suspendable"
    BLOCKING = "blocking"


class Purpose(StrEnum):
    """Which state built a stage FSM: ``upTsk`` builds ``exeTsk``, ``genSusp`` builds ``exeSusp``."""

    UP_TSK = "upTsk"
    GEN_SUSP = "genSusp"


@dataclass(frozen=True, slots=True)
class Stage:
    """One state ``S^{stage,k}`` of ``exeTsk`` or ``exeSusp``.

    ``action`` and ``args`` name the plan step (e.g. ``navigate robot kitchen hall``);
    ``skill`` names the core-agent skill that executes it; ``duration`` is the
    expected time in seconds (used for estimates and by the timed executor);
    ``kind`` says whether a pending ``susp`` may end the stage early (eq. 26) or must
    wait for its goal (eq. 25); ``data`` carries skill parameters.
    """

    action: str
    args: tuple[str, ...] = ()
    kind: StageKind = StageKind.SUSPENDABLE
    skill: str = ""
    duration: float = 0.0
    data: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not self.action:
            raise ValueError("Stage.action must be a non-empty string")
        if not isinstance(self.kind, StageKind):
            raise TypeError(f"Stage.kind must be a StageKind, got {self.kind!r}")
        if not isinstance(self.args, tuple):
            raise TypeError(f"Stage.args must be a tuple, got {type(self.args).__name__}")
        if not isinstance(self.duration, int | float) or math.isnan(self.duration) or self.duration < 0:
            raise ValueError(f"Stage.duration must be a number >= 0, got {self.duration!r}")

    @property
    def blocking(self) -> bool:
        return self.kind is StageKind.BLOCKING

    @property
    def label(self) -> str:
        """``action(arg, ...)``, as shown in traces and diagrams."""
        return f"{self.action}({', '.join(self.args)})" if self.args else self.action

    def to_json(self) -> dict[str, Any]:
        return {"action": self.action, "args": list(self.args), "kind": self.kind.value}


@dataclass(frozen=True, slots=True)
class StagePlan:
    """An ``exeTsk`` or ``exeSusp`` FSM: a sequence of stages, and how it was made.

    ``strategy`` is ``"planned"``, ``"static"``, ``"derived"`` or ``"fallback"``; ``sim_time`` is
    the simulated time the agent spends in ``upTsk``/``genSusp`` producing it (from a
    deterministic model, never the wall clock, so traces are reproducible); ``note`` explains
    a fallback.  ``goal``, for an ``exeSusp``, is what it aims to leave true: ground literals
    (``("not", ...)`` for a fact that must not hold), checked against the world when the
    suspension ends (:class:`tasker.events.GoalChecked`); None when the task type does not say.
    """

    stages: tuple[Stage, ...]
    purpose: Purpose
    strategy: str = "static"
    sim_time: float = 0.0
    note: str | None = None
    info: Mapping[str, Any] = field(default_factory=dict)
    goal: tuple[tuple[str, ...], ...] | None = None

    def __post_init__(self) -> None:
        if self.goal is not None and not (isinstance(self.goal, tuple) and all(
                isinstance(lit, tuple) and lit and all(isinstance(x, str) and x for x in lit) for lit in self.goal)):
            raise TypeError(f"StagePlan.goal must be a tuple of literals (tuples of strings), got {self.goal!r}")
        if not isinstance(self.stages, tuple):
            raise TypeError("StagePlan.stages must be a tuple of Stage")
        for s in self.stages:
            if not isinstance(s, Stage):
                raise TypeError(f"StagePlan.stages holds a {type(s).__name__}, expected Stage")
        if not isinstance(self.purpose, Purpose):
            raise TypeError(f"StagePlan.purpose must be a Purpose, got {self.purpose!r}")
        if self.sim_time < 0 or math.isnan(self.sim_time):
            raise ValueError(f"StagePlan.sim_time must be >= 0, got {self.sim_time}")

    @property
    def expected_duration(self) -> float:
        return sum(s.duration for s in self.stages)

    def to_mermaid(self, title: str | None = None) -> str:
        """The FSM as a Mermaid ``stateDiagram-v2``; blocking stages are marked."""
        name = title or self.purpose.value.replace("upTsk", "exeTsk").replace("genSusp", "exeSusp")
        lines = ["stateDiagram-v2", f"    %% {name} ({self.strategy})"]
        prev = "[*]"
        for k, s in enumerate(self.stages, start=1):
            sid = f"s{k}"
            mark = " [blocking]" if s.blocking else ""
            lines.append(f"    {sid} : {k}. {s.label}{mark}")
            lines.append(f"    {prev} --> {sid}")
            prev = sid
        lines.append(f"    {prev} --> [*]")
        return "\n".join(lines) + "\n"

    def to_dot(self, title: str | None = None) -> str:
        """The FSM as Graphviz DOT; blocking stages are drawn with a double border."""
        name = title or self.purpose.value.replace("upTsk", "exeTsk").replace("genSusp", "exeSusp")
        lines = [f"digraph {json.dumps(name)} {{", "    rankdir=LR;", "    start [shape=point];"]
        prev = "start"
        for k, s in enumerate(self.stages, start=1):
            periph = 2 if s.blocking else 1
            lines.append(f"    s{k} [shape=box, peripheries={periph}, label={json.dumps(f'{k}. {s.label}')}];")
            lines.append(f"    {prev} -> s{k};")
            prev = f"s{k}"
        lines.append("    done [shape=doublecircle, label=\"\"];")
        lines.append(f"    {prev} -> done;")
        lines.append("}")
        return "\n".join(lines) + "\n"


def plan_of(stages: Sequence[Stage], purpose: Purpose, **kw: Any) -> StagePlan:
    """Build a :class:`StagePlan` from any sequence of stages."""
    return StagePlan(tuple(stages), purpose, **kw)
