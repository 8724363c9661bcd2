"""A checked robot scenario, as data: what :mod:`experiments.inputs.scenario` reads and
:mod:`experiments.inputs.crossref` checks against the world and the task store."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

from experiments.inputs.actions import TimedAction


@dataclass(frozen=True)
class RobotScenario:
    """A checked robot scenario.

    ``objects`` are the scenario's own things (``[objects.NAME]``):
    ``{name: {"type", "place", "facts"}}``; ``devices`` its own devices (``[devices.NAME]``),
    added to the world like a world file's ``[devices]``: ``{name: {"type", "place", "state"}}``;
    ``warnings`` what the loader accepted but
    doubts (a request after the horizon, two identical requests that overlap).
    """

    name: str
    source: str
    world: str
    actions: tuple[TimedAction, ...]
    scheduler: str = "alg2"
    scheduler_options: dict[str, Any] = field(default_factory=dict)
    mode: str = "IT"
    s_freq: float = 1.0
    rep_rate: float = 1.0
    task_exe_rate: float = 10.0
    sp_up_rate: float = 1.0
    update: str = "planned"
    suspension: str = "planned"
    strategies: dict[str, dict[str, str]] = field(default_factory=dict)
    seed: int = 1
    horizon: float = 1800.0
    people: dict[str, dict[str, Any]] = field(default_factory=dict)
    objects: dict[str, dict[str, Any]] = field(default_factory=dict)
    devices: dict[str, dict[str, Any]] = field(default_factory=dict)
    policy: str = "strict"
    secure_over_higher: bool = False
    """Hazard-aware waiting may preempt a task of a higher priority class to secure a hazard (off: the
    safety rule of ``docs/model.md``)."""
    request_fields: bool = False
    """Every task type takes the request fields ``deadline``, ``priority`` and ``death_at``
    (:mod:`experiments.inputs.request_fields`), as when a request gives one; ``tasker serve`` sessions set it."""
    warnings: tuple[str, ...] = field(default=(), compare=False)

    def to_json(self) -> dict[str, Any]:
        out = dataclasses.asdict(self)
        out["actions"] = [{"t": a.t, "kind": a.kind, **a.fields} for a in self.actions]
        out.pop("warnings", None)
        return out
