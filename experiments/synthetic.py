"""Synthetic scenarios: the TaskER model on timed stages, no robot.

A synthetic scenario file (TOML or JSON) defines task types as stage templates,
the requests with their times, changes during the run, and the harmonisation
settings.  Every field is checked when the file is loaded; an error names the file
and the field.  See ``docs/scenarios.md`` for the format.
"""

from __future__ import annotations

import json
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tasker import schedulers
from tasker.agent import Rates
from tasker.errors import TaskerError
from tasker.harmoniser import Mode
from tasker.loop import SimulationLoop
from tasker.stage import Stage, StageKind
from tasker.store import TaskStore
from tasker.synthetic import SyntheticTask, TimedExecutor
from tasker.trace import Trace


class ScenarioError(TaskerError, ValueError):
    """A scenario file is malformed; the message names the file and the field."""


@dataclass(frozen=True)
class TimedAction:
    t: float
    kind: str  # request | terminate | change | mode
    fields: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class SyntheticScenario:
    """A checked synthetic scenario, ready to run with :func:`run`."""

    name: str
    tasks: tuple[SyntheticTask, ...]
    actions: tuple[TimedAction, ...]
    scheduler: str = "alg2"
    scheduler_options: dict[str, Any] = field(default_factory=dict)
    mode: str = "IT"
    s_freq: float = 1.0
    rates: Rates = field(default_factory=Rates)
    jitter: float = 0.0
    seed: int = 0
    horizon: float = 24 * 3600.0


class _Fields:
    """Reads one table of a scenario file, naming ``file: path.to.field`` in every error."""

    def __init__(self, source: str, where: str, table: Any) -> None:
        if not isinstance(table, dict):
            raise ScenarioError(f"{source}: {where or 'top level'}: expected a table, got {type(table).__name__}")
        self.source, self.where, self.table = source, where, table
        self.used: set[str] = set()

    def path(self, key: str) -> str:
        return f"{self.where}.{key}" if self.where else key

    def error(self, key: str, msg: str) -> ScenarioError:
        return ScenarioError(f"{self.source}: {self.path(key)}: {msg}")

    def get(self, key: str, kind: type | tuple[type, ...], default: Any = ..., *, positive: bool = False) -> Any:
        self.used.add(key)
        if key not in self.table:
            if default is ...:
                raise self.error(key, "missing (required)")
            return default
        value = self.table[key]
        if kind is float and isinstance(value, int) and not isinstance(value, bool):
            value = float(value)
        if isinstance(value, bool) and kind is not bool or not isinstance(value, kind):
            names = kind.__name__ if isinstance(kind, type) else " or ".join(k.__name__ for k in kind)
            raise self.error(key, f"expected {names}, got {value!r}")
        if positive and value <= 0:
            raise self.error(key, f"expected a positive number, got {value!r}")
        return value

    def sub(self, key: str, default: Any = ...) -> _Fields:
        return _Fields(self.source, self.path(key), self.get(key, dict, default))

    def done(self) -> None:
        extra = sorted(set(self.table) - self.used)
        if extra:
            raise self.error(extra[0], f"unknown field; expected one of {sorted(self.used)}")


def _stage(f: _Fields) -> Stage:
    kind = f.get("kind", str, "suspendable")
    if kind not in ("suspendable", "blocking"):
        raise f.error("kind", f"expected 'suspendable' or 'blocking', got {kind!r}")
    duration = f.get("duration", float)
    if duration < 0:
        raise f.error("duration", f"expected >= 0, got {duration}")
    data: dict[str, Any] = {}
    site = f.get("site", list, None)
    if site is not None:
        data["site"] = tuple(site)
    fail = f.get("fail", str, None)
    if fail:
        data["fail"] = fail
    stage = Stage(f.get("action", str), kind=StageKind(kind), duration=duration, skill="timed", data=data)
    f.done()
    return stage


def _stages(f: _Fields, key: str) -> list[Stage]:
    items = f.get(key, list)
    if not items:
        raise f.error(key, "expected at least one stage")
    return [_stage(_Fields(f.source, f"{f.path(key)}[{i}]", s)) for i, s in enumerate(items)]


def load(path: str | Path) -> SyntheticScenario:
    """Read and check a synthetic scenario file (``.toml`` or ``.json``)."""
    p = Path(path)
    source = str(p)
    try:
        text = p.read_text(encoding="utf-8")
    except OSError as exc:
        raise ScenarioError(f"{source}: cannot read: {exc.strerror}") from None
    try:
        raw = json.loads(text) if p.suffix == ".json" else tomllib.loads(text)
    except (json.JSONDecodeError, tomllib.TOMLDecodeError) as exc:
        raise ScenarioError(f"{source}: not valid {'JSON' if p.suffix == '.json' else 'TOML'}: {exc}") from None
    top = _Fields(source, "", raw)
    kind = top.get("kind", str, "synthetic")
    if kind != "synthetic":
        raise top.error("kind", f"this loader reads kind = 'synthetic', got {kind!r}")
    settings = top.sub("settings", {})
    tasks_f = top.sub("tasks")
    tasks = []
    for name in tasks_f.table:
        t = tasks_f.sub(name)
        susp_f = t.sub("suspension", {})
        suspension = {action: _stages(susp_f, action) for action in list(susp_f.table)}
        tasks.append(SyntheticTask(
            name, _stages(t, "stages"),
            weight=t.get("weight", float, 1.0), speed=t.get("speed", float, 1.0, positive=True),
            site=tuple(t.get("site", list)) if "site" in t.table else None,
            suspension=suspension or None,
            resume_prefix=_stages(t, "resume_prefix") if "resume_prefix" in t.table else (),
            planning_time=t.get("planning_time", float, 0.0),
        ))
        t.done()
    names = {t.name for t in tasks}
    actions: list[TimedAction] = []
    for key, kind_name in (("requests", "request"), ("terminations", "terminate"), ("changes", "change"),
                           ("mode_changes", "mode")):
        for i, item in enumerate(top.get(key, list, [])):
            f = _Fields(source, f"{key}[{i}]", item)
            t_ = f.get("t", float)
            if t_ < 0:
                raise f.error("t", f"expected >= 0, got {t_}")
            fields: dict[str, Any] = {}
            if kind_name == "request":
                fields["task"] = f.get("task", str)
                if fields["task"] not in names:
                    raise f.error("task", f"unknown task type {fields['task']!r}; defined: {sorted(names)}")
                fields["args"] = f.get("args", dict, {})
            elif kind_name in ("terminate", "change"):
                fields["agent"] = f.get("agent", str)
                if kind_name == "change":
                    fields["args"] = f.get("args", dict)
                else:
                    fields["reason"] = f.get("reason", str, "terminated by the requester")
            else:
                fields["mode"] = f.get("mode", str)
                if fields["mode"] not in ("IT", "CT"):
                    raise f.error("mode", f"expected 'IT' or 'CT', got {fields['mode']!r}")
            f.done()
            actions.append(TimedAction(t_, kind_name, fields))
    request_times = [a.t for a in sorted(actions, key=lambda a: a.t) if a.kind == "request"]
    for a in actions:
        if a.kind in ("terminate", "change"):
            agent = a.fields["agent"]
            k = int(agent[1:]) if agent[:1] == "d" and agent[1:].isdigit() else 0
            key = "terminations" if a.kind == "terminate" else "changes"
            if not 1 <= k <= len(request_times) or request_times[k - 1] > a.t:
                raise ScenarioError(
                    f"{source}: {key}: agent {agent!r} at t={a.t}: agents are d1..d{len(request_times)} "
                    "in request order, and must be requested before they are changed or terminated"
                )
    mode = settings.get("mode", str, "IT")
    if mode not in ("IT", "CT"):
        raise settings.error("mode", f"expected 'IT' or 'CT', got {mode!r}")
    scheduler = settings.get("scheduler", str, "alg2")
    if scheduler not in schedulers.names():
        raise settings.error("scheduler", f"unknown scheduler {scheduler!r}; known: {schedulers.names()}")
    scenario = SyntheticScenario(
        name=top.get("name", str, p.stem),
        tasks=tuple(tasks),
        actions=tuple(sorted(actions, key=lambda a: a.t)),
        scheduler=scheduler,
        scheduler_options=settings.get("scheduler_options", dict, {}),
        mode=mode,
        s_freq=settings.get("s_freq", float, 1.0, positive=True),
        rates=Rates(settings.get("rep_rate", float, 1.0, positive=True),
                    settings.get("task_exe_rate", float, 10.0, positive=True),
                    settings.get("sp_up_rate", float, 1.0, positive=True)),
        jitter=settings.get("jitter", float, 0.0),
        seed=top.get("seed", int, 0),
        horizon=settings.get("horizon", float, 24 * 3600.0, positive=True),
    )
    settings.done()
    top.done()
    build(scenario, seed=scenario.seed)  # checks request arguments and scheduler options now, before any run
    return scenario


def build(scenario: SyntheticScenario, *, seed: int, scheduler: str | None = None, mode: str | None = None,
          trace: Trace | None = None) -> SimulationLoop:
    """A ready-to-run loop for ``scenario`` (requests and changes scheduled)."""
    store = TaskStore(scenario.tasks)
    options = scenario.scheduler_options if scheduler in (None, scenario.scheduler) else {}
    loop = SimulationLoop(
        store, schedulers.create(scheduler or scenario.scheduler, **options), seed=seed, trace=trace,
        mode=Mode(mode or scenario.mode), s_freq=scenario.s_freq, rates=scenario.rates,
        core=TimedExecutor(seed=seed, jitter=scenario.jitter), horizon=scenario.horizon,
    )
    from tasker.requester import Requester

    requester = Requester(store, loop.harmoniser, "scenario")
    for a in scenario.actions:
        if a.kind == "request":
            loop.request(a.t, a.fields["task"], a.fields["args"], requester="scenario")
        elif a.kind == "terminate":
            agent, reason = a.fields["agent"], a.fields["reason"]
            loop.at(a.t, lambda agent=agent, reason=reason: requester.terminate(agent, reason))
        elif a.kind == "change":
            agent, args = a.fields["agent"], a.fields["args"]
            loop.at(a.t, lambda agent=agent, args=args: _change(loop, requester, agent, args))
        else:
            m = a.fields["mode"]
            loop.at(a.t, lambda m=m: loop.harmoniser.set_mode(m))
    return loop


def _change(loop: SimulationLoop, requester: Any, agent: str, args: dict[str, Any]) -> None:
    if agent in loop.harmoniser.agents:
        requester.change(agent, args)
    else:
        loop.trace.emit(loop.now, "change", agent=agent, args=args, ignored="the task has ended")


def run(scenario: SyntheticScenario, *, seed: int | None = None, scheduler: str | None = None,
        mode: str | None = None, trace: Trace | None = None) -> Trace:
    loop = build(scenario, seed=scenario.seed if seed is None else seed, scheduler=scheduler, mode=mode, trace=trace)
    return loop.run()
