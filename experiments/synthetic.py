"""Synthetic scenarios: the TaskER model on timed stages, no robot.

A synthetic scenario file (TOML or JSON) defines task types as stage templates,
the requests with their times, changes during the run, and the harmonisation
settings.  Every field is checked when the file is loaded; an error names the file
and the field.  See ``docs/scenarios.md`` for the format.
"""

from __future__ import annotations

import json
import tomllib
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from experiments.actions import TimedAction, read_actions
from experiments.fields import Fields as _Fields
from experiments.fields import ScenarioError
from tasker import schedulers
from tasker.agent import Rates
from tasker.harmoniser import Mode
from tasker.loop import SimulationLoop
from tasker.stage import Stage, StageKind
from tasker.store import TaskStore
from tasker.synthetic import SyntheticTask, TimedExecutor
from tasker.trace import Trace

if TYPE_CHECKING:
    from tasker.requester import Requester


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
    actions = read_actions(top, task_names={t.name for t in tasks})
    mode = settings.get("mode", str, "IT")
    if mode not in ("IT", "CT"):
        raise settings.error("mode", f"expected 'IT' or 'CT', got {mode!r}")
    scheduler = settings.get("scheduler", str, "alg2")
    if scheduler not in schedulers.names():
        raise settings.error("scheduler", f"unknown scheduler {scheduler!r}; known: {schedulers.names()}")
    scenario = SyntheticScenario(
        name=top.get("name", str, p.stem),
        tasks=tuple(tasks),
        actions=actions,
        scheduler=scheduler,
        scheduler_options=settings.get("scheduler_options", dict, {}),
        mode=mode,
        s_freq=settings.get("s_freq", float, 1.0, positive=True),
        rates=Rates(settings.get("rep_rate", float, 1.0, positive=True),
                    settings.get("task_exe_rate", float, 10.0, positive=True),
                    settings.get("sp_up_rate", float, 1.0, positive=True)),
        jitter=settings.get("jitter", float, 0.0),
        seed=top.seed("seed", 0),
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
            loop.at(a.t, _terminate_event(requester, agent, reason))
        elif a.kind == "change":
            agent, args = a.fields["agent"], a.fields["args"]
            loop.at(a.t, _change_event(loop, requester, agent, args))
        else:
            m = a.fields["mode"]
            loop.at(a.t, _mode_event(loop, m))
    return loop


# The event builders bind each action's own arguments (a bare lambda in the loop would see the last ones).
def _terminate_event(requester: Requester, agent: str, reason: str) -> Callable[[], None]:
    return lambda: requester.terminate(agent, reason)


def _change_event(loop: SimulationLoop, requester: Requester, agent: str, args: dict[str, Any]) -> Callable[[], None]:
    return lambda: _change(loop, requester, agent, args)


def _mode_event(loop: SimulationLoop, mode: str) -> Callable[[], None]:
    return lambda: loop.harmoniser.set_mode(mode)


def _change(loop: SimulationLoop, requester: Requester, agent: str, args: dict[str, Any]) -> None:
    if agent in loop.harmoniser.agents:
        requester.change(agent, args)
    else:
        loop.trace.emit(loop.now, "change", agent=agent, args=args, ignored="the task has ended")


def run(scenario: SyntheticScenario, *, seed: int | None = None, scheduler: str | None = None,
        mode: str | None = None, trace: Trace | None = None) -> Trace:
    loop = build(scenario, seed=scenario.seed if seed is None else seed, scheduler=scheduler, mode=mode, trace=trace)
    return loop.run()
