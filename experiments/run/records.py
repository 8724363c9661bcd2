"""The record a run writes, as frozen types: ``run.json``.

A run's record used to be built as a string-keyed dict where it was written and read back as a
dict wherever it was used.  :class:`RunRecord` names its fields once (each entry of
``problems/index.json`` is :class:`experiments.report.explain.ProblemEntry`); ``to_json`` gives
exactly the object the file held (same keys, same optional keys left out), so ``run.json`` stays
byte for byte what it was.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from tasker.errors import InputError


@dataclass(frozen=True)
class RunSettings:
    """What a run was asked to do (``run.json``'s ``settings``): the strategies, the scheduler, the variant.

    ``interruption`` and ``perturbation`` are the randomised variant's grid and perturbation in their
    JSON form, present only for a randomised run that has them; ``tree`` only when one was chosen."""

    scheduler: str
    mode: str
    update: str
    suspension: str
    randomized: bool
    policy: str | None
    hazard_waiting: bool
    tree: str | None = None
    interruption: Mapping[str, Any] | None = None
    perturbation: Mapping[str, Any] | None = None

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {"scheduler": self.scheduler, "mode": self.mode, "update": self.update,
                               "suspension": self.suspension, "randomized": self.randomized, "policy": self.policy,
                               "hazard_waiting": self.hazard_waiting}
        if self.tree is not None:
            out["tree"] = self.tree
        if self.interruption is not None:
            out["interruption"] = dict(self.interruption)
        if self.perturbation is not None:
            out["perturbation"] = dict(self.perturbation)
        return out

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> RunSettings:
        return cls(str(data["scheduler"]), str(data["mode"]), str(data["update"]), str(data["suspension"]),
                   bool(data["randomized"]), data.get("policy"), bool(data.get("hazard_waiting", False)),
                   data.get("tree"), data.get("interruption"), data.get("perturbation"))


@dataclass(frozen=True)
class PlannerConfig:
    """The planner a robot run used (``run.json``'s ``planner``): the engine and the packages' versions."""

    engine: str
    unified_planning: str | None
    up_fast_downward: str | None

    def to_json(self) -> dict[str, Any]:
        return {"engine": self.engine, "unified_planning": self.unified_planning,
                "up_fast_downward": self.up_fast_downward}


@dataclass(frozen=True)
class RunRecord:
    """``run.json``: what ran (the scenario as run, its seed and settings), with what (planner,
    host, Python, tasker), when, how long it took on the wall clock, and how it ended.

    ``status`` is None for a run that ended as its scenario does, ``"aborted"`` or
    ``"interrupted"`` otherwise, with ``error`` saying why."""

    scenario: Mapping[str, Any]
    seed: int
    settings: RunSettings
    planner: PlannerConfig | None
    host: str
    platform: str
    python: str
    date: str
    tasker_version: str
    wall_time_s: float
    status: str | None = None
    error: str | None = None
    extra: Mapping[str, Any] = field(default_factory=dict)
    """Keys a ``run.json`` of another version held that this one does not know (kept when read back)."""

    def to_json(self) -> dict[str, Any]:
        """The object ``run.json`` holds (written with ``sort_keys``: the order here does not matter)."""
        out: dict[str, Any] = {
            **self.extra,
            "scenario": dict(self.scenario), "seed": self.seed, "settings": self.settings.to_json(),
            "planner": None if self.planner is None else self.planner.to_json(),
            "host": self.host, "platform": self.platform, "python": self.python, "date": self.date,
            "tasker_version": self.tasker_version, "wall_time_s": self.wall_time_s,
        }
        if self.status is not None:
            out["status"] = self.status
        if self.error is not None:
            out["error"] = self.error
        return out

    @classmethod
    def from_json(cls, data: Any, file: str = "run.json") -> RunRecord:
        """A ``run.json`` read back; an :class:`~tasker.errors.InputError` naming the field that is wrong."""
        if not isinstance(data, Mapping):
            raise InputError(file, f"expected a run record (an object), got {type(data).__name__}")
        known = {"scenario", "seed", "settings", "planner", "host", "platform", "python", "date", "tasker_version",
                 "wall_time_s", "status", "error"}
        try:
            planner = data.get("planner")
            return cls(
                scenario=data["scenario"], seed=int(data["seed"]), settings=RunSettings.from_json(data["settings"]),
                planner=None if planner is None else PlannerConfig(str(planner["engine"]), planner.get(
                    "unified_planning"), planner.get("up_fast_downward")),
                host=str(data["host"]), platform=str(data["platform"]), python=str(data["python"]),
                date=str(data["date"]), tasker_version=str(data["tasker_version"]),
                wall_time_s=float(data["wall_time_s"]), status=data.get("status"), error=data.get("error"),
                extra={k: v for k, v in data.items() if k not in known})
        except KeyError as exc:
            raise InputError(file, f"the run record has no {exc.args[0]!r}", field=str(exc.args[0])) from None
        except (TypeError, ValueError, AttributeError) as exc:
            raise InputError(file, f"not a run record tasker writes: {exc}") from None
