"""Synthetic scenarios: the TaskER model on timed stages, no robot.

A synthetic scenario file (TOML or JSON) defines task types as stage templates,
the requests with their times, changes during the run, and the harmonisation
settings.  Every field is checked when the file is loaded, with :mod:`tasker.support.reader`;
an error names the file, the line and the field.  See ``docs/scenarios.md`` for the format.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from experiments.inputs import fields
from experiments.inputs.actions import (
    NO_REQUESTS,
    TABLES,
    Change,
    ModeSwitch,
    Request,
    Terminate,
    TimedAction,
    located,
    read_actions,
)
from experiments.inputs.crossref import validate_request
from experiments.inputs.fields import MODES, ScenarioError
from experiments.inputs.filekinds import expect
from tasker import events as ev
from tasker import schedulers
from tasker.agent import Rates
from tasker.errors import TaskerError
from tasker.harmoniser import Mode
from tasker.loop import SimulationLoop
from tasker.stage import Stage, StageKind
from tasker.store import TaskStore
from tasker.support import reader
from tasker.support.reader import Table, check_name
from tasker.synthetic import SyntheticTask, TimedExecutor
from tasker.task import Strategy
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


SYNTHETIC_KEYS = ("kind", "name", "seed", "settings", "tasks", *(k for k, _ in TABLES if k != "world_events"))


def _stage(f: Table) -> Stage:
    kind = f.string("kind", "suspendable", choices=("suspendable", "blocking"))
    duration = float(f.number("duration", min=0, max=reader.MAX_SECONDS))
    data: dict[str, Any] = {}
    if "site" in f:
        data["site"] = _site(f)
    fail = f.string("fail", None)
    if fail:
        data["fail"] = fail
    stage = Stage(f.string("action"), kind=StageKind(kind), duration=duration, skill="timed", data=data)
    f.done()
    return stage


def _site(f: Table) -> tuple[float, ...]:
    """``site``: ``[x, y]`` or ``[x, y, yaw]``."""
    value = f.raw("site")
    n = len(value) if isinstance(value, list) and len(value) in (2, 3) else 2
    return tuple(f.numbers("site", n, "[x, y] or [x, y, yaw]"))


def _stages(f: Table, key: str) -> list[Stage]:
    items = f.tables(key)
    if not items:
        raise f.error(key, "expected at least one stage")
    return [_stage(t) for t in items]


def load(path: str | Path) -> SyntheticScenario:
    """Read and check a synthetic scenario file (``.toml`` or ``.json``)."""
    p = Path(path)
    top = reader.load(p, ScenarioError)
    expect(top, "scenario")
    top.string("kind", "synthetic", choices=("synthetic",))
    settings = top.table("settings", {})
    tasks_f = top.table("tasks")
    tasks = []
    for name, t in [(n, tasks_f.at(n, v)) for n, v in tasks_f.items()]:
        stages = _stages(t, "stages")
        susp_f = t.table("suspension", {})
        actions_of = sorted({st.action for st in stages})
        for action in susp_f.keys():  # keyed by the action of the interrupted stage (eq. 47)
            check_name(susp_f, action, action, actions_of, f"action in the stages of {name!r}")
        suspension = {action: _stages(susp_f, action) for action in susp_f.keys()}
        tasks.append(SyntheticTask(
            name, stages,
            weight=float(t.number("weight", 1.0, min=0)), speed=float(t.number("speed", 1.0, positive=True)),
            site=_site(t) if "site" in t else None,
            suspension=suspension or None,
            resume_prefix=_stages(t, "resume_prefix") if "resume_prefix" in t else (),
            planning_time=float(t.number("planning_time", 0.0, min=0)),
        ))
        t.done()
    if not tasks:
        raise top.error("tasks", "expected at least one task type ([tasks.NAME])")
    actions = read_actions(top, task_names={t.name for t in tasks})
    sched = fields.scheduler(settings)
    scenario = SyntheticScenario(
        name=str(top.string("name", p.stem)),
        tasks=tuple(tasks),
        actions=actions,
        scheduler=sched,
        scheduler_options=fields.scheduler_options(settings, sched, [t.name for t in tasks]),
        mode=str(settings.string("mode", "IT", choices=MODES)),
        s_freq=fields.rate(settings, "s_freq", 1.0),
        rates=Rates(fields.rate(settings, "rep_rate", 1.0), fields.rate(settings, "task_exe_rate", 10.0),
                    fields.rate(settings, "sp_up_rate", 1.0)),
        jitter=float(settings.number("jitter", 0.0, min=0, max=1)),
        seed=int(top.number("seed", 0, integer=True, min=0, max=reader.MAX_SEED)),
        horizon=float(settings.number("horizon", 24 * 3600.0, positive=True, max=reader.MAX_SECONDS)),
    )
    settings.done()
    top.done(SYNTHETIC_KEYS)
    if not any(a.kind == "request" for a in actions):
        top.warn("requests", NO_REQUESTS)
    for a in actions:
        if a.t > scenario.horizon:
            located(top, a).warn("t", f"t={a.t:g} is after the horizon ({scenario.horizon:g} s): it never happens")
    by_name = {t.name: t for t in tasks}
    for a in actions:
        if isinstance(a.payload, Request):
            validate_request(located(top, a), by_name[a.payload.task], a.payload.args)
    try:
        build(scenario, seed=scenario.seed)  # the rest (changes, the scheduler) now, before any run
    except TaskerError as exc:
        raise ScenarioError(str(p), f"{exc}") from None
    return scenario


SYNTHETIC_STRATEGY = Strategy("static", "static")
"""What synthetic tasks do: they run their timed stages, never a planner.  The loop is told so,
and its ``run`` event says so, as ``run.json`` does."""


def build(scenario: SyntheticScenario, *, seed: int, scheduler: str | None = None, mode: str | None = None,
          trace: Trace | None = None) -> SimulationLoop:
    """A ready-to-run loop for ``scenario`` (requests and changes scheduled)."""
    store = TaskStore(scenario.tasks)
    options = scenario.scheduler_options if scheduler in (None, scenario.scheduler) else {}
    loop = SimulationLoop(
        store, schedulers.create(scheduler or scenario.scheduler, **options), seed=seed, trace=trace,
        mode=Mode(mode or scenario.mode), s_freq=scenario.s_freq, rates=scenario.rates,
        core=TimedExecutor(seed=seed, jitter=scenario.jitter), horizon=scenario.horizon,
        strategy=SYNTHETIC_STRATEGY,
    )
    from tasker.requester import Requester

    requester = Requester(store, loop.harmoniser, "scenario")
    for a in scenario.actions:
        p = a.payload
        if isinstance(p, Request):
            loop.request(a.t, p.task, p.args, requester="scenario")
        elif isinstance(p, Terminate):
            loop.at(a.t, _terminate_event(requester, p.agent, p.reason))
        elif isinstance(p, Change):
            loop.at(a.t, _change_event(loop, requester, p.agent, p.args))
        elif isinstance(p, ModeSwitch):
            loop.at(a.t, _mode_event(loop, p.mode))
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
        loop.trace.emit(ev.ArgsChanged(loop.now, agent, args, ignored="the task has ended"))


def run(scenario: SyntheticScenario, *, seed: int | None = None, scheduler: str | None = None,
        mode: str | None = None, trace: Trace | None = None) -> Trace:
    loop = build(scenario, seed=scenario.seed if seed is None else seed, scheduler=scheduler, mode=mode, trace=trace)
    return loop.run()
