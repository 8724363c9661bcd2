"""One scenario pipeline for day protocols: (protocol, seed, backend) → a scenario → a run.

The shape is Gymnasium's ``EnvSpec`` + ``make``: protocols are registered by name
(:func:`register`; ``tabsa``, ``tabsa-short`` and ``tabsa-rush`` are shipped), and
:func:`make` turns a name (or a protocol file), a seed and a backend into a :class:`Day` —
the scenario that backend runs, built from the one draw of :func:`experiments.days.draw.draw`:

* ``synthetic``: a :class:`experiments.inputs.synthetic.SyntheticScenario` of timed stages
  (:class:`experiments.days.daytask.DayTask`);
* ``robot``: a :class:`experiments.inputs.scenario.RobotScenario` in the protocol's world
  (``[robot_backend]``): each protocol task type is a task folder with its arguments,
  a person of the world per request is scripted to walk to the request's site before
  the call (and, for a fall, lies down at the call and is taken away — gets up and walks
  home — once the robot's task for them has finished, or at ``death_at`` if it has not),
  each pick-and-place gets its own object at its site.  A task type with
  ``renew_after_s`` is requested again that long after its task fails, until the
  request's ``death_at`` (or the day's end): the need stands until served.

Either way every request carries ``deadline`` and ``priority`` (and a fall its
``death_at``) as request fields that reach every scheduler through the schedule
parameters (:mod:`experiments.inputs.request_fields` for task folders), and requests enter
through the public :class:`tasker.requester.Requester`, never the loop's internals.
:meth:`Day.run` runs it and returns a :class:`DayRun`: the trace's events and, on the
robot backend, the recorded trajectory (``trajectory.jsonl``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from experiments.days import draw as draws
from experiments.days import protocol as protocols
from experiments.days.draw import DayRequest
from experiments.days.protocol import Protocol
from experiments.days.robot_work import SUFFIX, wrapper_for
from experiments.days.specs import SchedulerSpec, parse
from experiments.inputs.actions import TimedAction
from experiments.inputs.strategy import FACTORS
from experiments.inputs.synthetic import SyntheticScenario
from tasker.errors import ConfigError
from tasker.loop import SimulationLoop
from tasker.support.reader import suggest

PROTOCOLS_DIR = Path(__file__).resolve().parent / "protocols"
BACKENDS = ("synthetic", "robot")
STRATEGY_SETTINGS = tuple(f for f in FACTORS if f != "scheduler")
"""What :meth:`Day.run` lets a strategy set (the scheduler is the day's own, given to :func:`make`)."""


def check_settings(backend: str, settings: Mapping[str, Any]) -> None:
    """The strategy settings ``backend`` can run (see :meth:`Day.run`), or a :class:`ConfigError`."""
    unknown = sorted(set(settings) - set(STRATEGY_SETTINGS))
    if unknown:
        raise ConfigError(f"unknown setting {unknown[0]!r}; known: {', '.join(STRATEGY_SETTINGS)}")
    if backend == "synthetic" and settings:
        raise ConfigError(f"the synthetic backend runs timed stages that {', '.join(sorted(settings))} "
                          "cannot change: compare strategies on the robot backend")

_registry: dict[str, Path] = {}


def register(name: str, path: str | Path) -> None:
    """Make a protocol file known by ``name`` (like ``gymnasium.register``)."""
    if name in _registry and _registry[name] != Path(path).resolve():
        raise ConfigError(f"protocol {name!r} is already registered as {_registry[name]}")
    _registry[name] = Path(path).resolve()


def names() -> list[str]:
    """Registered protocol names."""
    return sorted(_registry)


register("tabsa", PROTOCOLS_DIR / "tabsa.toml")
register("tabsa-short", PROTOCOLS_DIR / "tabsa_short.toml")
register("tabsa-rush", PROTOCOLS_DIR / "tabsa_rush.toml")
register("tabsa-original", PROTOCOLS_DIR / "tabsa_original.toml")
register("tabsa-anywhere", PROTOCOLS_DIR / "tabsa_anywhere.toml")


def resolve(name_or_path: str | Path) -> Path:
    """A registered name or a protocol file."""
    if str(name_or_path) in _registry:
        return _registry[str(name_or_path)]
    p = Path(name_or_path)
    if p.suffix == ".toml" or p.exists():  # a folder too: the reader says it is one, not "no protocol"
        return p
    raise ConfigError(f"no protocol {str(name_or_path)!r}{suggest(str(name_or_path), _registry)} "
                      f"(registered: {', '.join(names())}; or give a .toml file)")


def load(name_or_path: str | Path | Protocol) -> Protocol:
    """The checked protocol of a registered name or a file."""
    if isinstance(name_or_path, Protocol):
        return name_or_path
    return protocols.load(resolve(name_or_path))


# -- schedulers --------------------------------------------------------------------------------------

def task_names(proto: Protocol, backend: str) -> dict[str, str]:
    """Protocol task type → the task type name that backend runs."""
    if backend == "robot":
        assert proto.robot is not None
        return {k: proto.robot.tasks[k].task for k in proto.tasks}
    return {k: k for k in proto.tasks}


def scheduler_options(proto: Protocol, name: str, backend: str = "synthetic", seed: int = 0) -> dict[str, Any]:
    """Options each scheduler gets from the protocol and the day: what it can know of the day's task types.

    ``alg2``: the priority classes; the look-ahead: the falls' hazard budget and a switch
    penalty; TaBSA's agents: the protocol's non-preemptive types (``non_preemptive``, the task
    names ``backend`` runs) and, for the two that draw at random, the day's ``seed``."""
    to = task_names(proto, backend)
    if name == "alg2":  # priority classes, highest first
        prios = sorted({s.priority for s in proto.tasks.values()}, reverse=True)
        return {"classes": [[to[k] for k, s in proto.tasks.items() if s.priority == p] for p in prios]}
    if name in ("lookahead", "lookahead-cpsat"):
        budgets = {to[k]: s.death_after_s for k, s in proto.tasks.items() if s.death_after_s is not None}
        penalty = max((s.suspend_s for s in proto.tasks.values()), default=0.0) + proto.planning_time_s
        return {"switch_penalty_s": penalty, "budgets": budgets}
    if name in TABSA_AGENTS:
        out: dict[str, Any] = {"non_preemptive": [to[k] for k in proto.non_preemptive]}
        if name in ("tabsa-simple", "tabsa-simple2"):
            out["seed"] = seed
        return out
    return {}


TABSA_AGENTS = ("tabsa-simple", "tabsa-simple2", "tabsa-distance", "tabsa-scheduler")
"""TaBSA's agents (:mod:`tasker.schedulers.tabsa`): they take the protocol's non-preemptive types."""


# -- the backends --------------------------------------------------------------------------------------

def _synthetic(proto: Protocol, seed: int, scheduler: str, options: dict[str, Any]) -> SyntheticScenario:
    return draws.generate(proto, seed, scheduler=scheduler, scheduler_options=options)


def _robot(proto: Protocol, seed: int, scheduler: str, options: dict[str, Any]) -> Any:
    """The drawn day as a robot scenario (see the module docstring)."""
    from experiments.inputs.scenario import RobotScenario
    from robot.spec import load_world

    backend = proto.robot
    if backend is None:
        raise ConfigError(f"{proto.source}: this protocol has no [robot_backend]: it runs on the synthetic "
                          "backend only")
    world = load_world(backend.world)
    pool = sorted(world.people)
    requests = draws.draw(proto, seed)
    need = sum(1 for r in requests if "$person" in backend.tasks[r.kind].args.values())
    if need > len(pool):
        raise ConfigError(f"{proto.source}: day {seed} needs {need} people and world {world.name!r} has "
                          f"{len(pool)}: add people to {backend.world} or lower the counts")
    actions: list[TimedAction] = []
    people: dict[str, dict[str, Any]] = {}
    objects: dict[str, dict[str, Any]] = {}
    held: dict[tuple[str, int], float] = {}  # (site, spot) -> until when someone stands there
    taken: list[tuple[TimedAction, str, tuple[float, ...]]] = []  # (request, who lies down for it, their home)
    for r in requests:
        rt = backend.tasks[r.kind]
        lies_down: tuple[str, tuple[float, ...]] | None = None
        values = {"$site": backend.places[r.site], "$dest": backend.places[r.dest]}
        if "$person" in rt.args.values():
            person = pool.pop(0)
            values["$person"] = person
            release = r.death_at if rt.posture else None  # the spot is held until then at most
            home = world.people[person].pose
            lead = _lead(backend.lead_s, home, r.xy if r.xy is not None else backend.spots[r.site][0], r.walk_speed)
            if r.xy is not None:  # drawn anywhere free in a room: their own spot
                where: tuple[float, ...] = r.xy
            else:
                where = backend.spots[r.site][_free_spot(held, r.site, len(backend.spots[r.site]), r.t - lead,
                                                         math.inf if release is None else release + backend.lead_s)]
            people[person] = _script(home, where, r, lead)
            if rt.posture:
                actions.append(TimedAction(r.t, "world", {"what": "posture", "value": [person, rt.posture],
                                                                "note": f"{person}: {rt.posture}"}))
                lies_down = (person, home)  # taken away once the robot's help is done, or at death_at
                if r.death_at is not None and r.death_at < proto.length_s:
                    actions += _taken_away(r.death_at, person, home, "death_at")
        if "$object" in rt.args.values():
            obj = f"o{len(objects) + 1:02d}"
            values["$object"] = obj
            assert rt.object_type is not None
            objects[obj] = {"type": rt.object_type, "place": backend.places[r.site], "facts": []}
        args: dict[str, Any] = {k: values.get(v, v) for k, v in rt.args.items()}
        args |= {"deadline": r.deadline, "priority": r.priority}
        drawn = {"$work": r.work, "$pick": r.pick_s, "$place": r.place_s}
        args |= {action + SUFFIX: drawn[v] for action, v in rt.durations.items() if drawn[v] is not None}
        if r.death_at is not None:
            args["death_at"] = r.death_at
        renew = {} if rt.renew_after_s is None else {"renew": {
            "after_s": rt.renew_after_s, "until": r.death_at if r.death_at is not None else proto.length_s}}
        actions.append(TimedAction(r.t, "request", {"task": rt.task, "args": args, **renew}))
        if lies_down is not None:
            taken.append((actions[-1], *lies_down))
    actions.sort(key=lambda a: a.t)  # stable: a posture change comes before its request
    agents = {id(a): f"d{k}" for k, a in enumerate((a for a in actions if a.kind == "request"), 1)}
    for req, person, back in taken:  # agents are d1, d2, … in the order requests are made
        actions += _taken_away(req.t, person, back, "help done", after=agents[id(req)])
    actions.sort(key=lambda a: a.t)
    rate = 1.0 / proto.step_s
    return RobotScenario(
        name=f"{proto.name}-day{seed}", source=proto.source, world=backend.world, actions=tuple(actions),
        scheduler=scheduler, scheduler_options=options, mode="IT", s_freq=rate, rep_rate=rate,
        task_exe_rate=backend.task_exe_rate, sp_up_rate=rate, seed=seed, horizon=proto.length_s,
        people=people, objects=objects,
    )


def _free_spot(held: dict[tuple[str, int], float], site: str, n: int, start: float, until: float) -> int:
    """The first spot of ``site`` free from ``start``; if none is, the one freed first (people then share it)."""
    k = min(range(n), key=lambda i: (held.get((site, i), -math.inf) > start, held.get((site, i), -math.inf), i))
    held[site, k] = until
    return k


def _taken_away(t: float, person: str, home: tuple[float, ...], why: str,
                after: str | None = None) -> list[TimedAction]:
    """Someone who lay down gets up and walks home: at ``t``, or once agent ``after`` has finished."""
    when = {"after": after} if after is not None else {}
    note = f"{person} is taken away ({why})"
    return [TimedAction(t, "world", {"what": "posture", "value": [person, "standing"], "note": note, **when}),
            TimedAction(t, "world", {"what": "walk", "value": [person, home[0], home[1]], "note": note, **when})]


ROUTE_FACTOR = 2.0
"""A person's walk from home to their spot is scripted to take at least this many times the
straight line at their pace: the way round walls and through the front door is longer, and a
script faster than they walk would leave them behind it (TaBSA's people walk at 0.01-0.1 m/s)."""


def _lead(lead: float, home: tuple[float, ...], spot: tuple[float, ...], speed: float | None) -> float:
    """How long before the call a person sets out: ``lead``, or longer for a slow walker."""
    if speed is None:
        return lead
    return max(lead, ROUTE_FACTOR * math.hypot(spot[0] - home[0], spot[1] - home[1]) / speed)


def _script(home: tuple[float, ...], spot: tuple[float, ...], r: DayRequest, lead: float) -> dict[str, Any]:
    """A person's pose and walk: from home to ``spot`` by the call (:func:`_taken_away` takes
    them home again)."""
    entry: dict[str, Any] = {}
    walk: list[list[float]] = []
    if r.t >= lead:
        walk += [[r.t - lead, home[0], home[1]], [r.t, spot[0], spot[1]]]
    else:  # called before they could walk there: they start at the spot, and the script holds them there
        entry["pose"] = [spot[0], spot[1], 0.0]
        walk += [[0.0, spot[0], spot[1]], [max(r.t, 1.0), spot[0], spot[1]]]
    if walk:
        entry["walk"] = walk
    if r.walk_speed is not None:
        entry["speed"] = r.walk_speed
    return entry


def robot_work(proto: Protocol) -> dict[str, tuple[tuple[str, ...], bool]]:
    """Per task folder the robot day runs: the actions given drawn durations, and whether it is preemptive
    (:func:`experiments.days.robot_work.wrapper_for`)."""
    if proto.robot is None:
        return {}
    return {rt.task: (tuple(rt.durations), proto.tasks[kind].preemptive) for kind, rt in proto.robot.tasks.items()}


_BACKENDS: dict[str, Callable[[Protocol, int, str, dict[str, Any]], Any]] = {
    "synthetic": _synthetic, "robot": _robot}


# -- make and run -------------------------------------------------------------------------------------

@dataclass(frozen=True)
class DayRun:
    """What one day produced: the trace's events and (robot) the recorded samples."""

    events: list[dict[str, Any]]
    samples: tuple[Any, ...] = ()
    record: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class Day:
    """One day of a protocol on one backend under one scheduler, ready to run."""

    protocol: Protocol
    seed: int
    backend: str
    scheduler: str
    scenario: Any

    def run(self, out: str | Path | None = None, **settings: Any) -> DayRun:
        """Run the day.  ``out``: keep the run's files there (robot: ``trace.jsonl``,
        ``trajectory.jsonl``, ``run.json``, ``metrics.json``; no pictures).

        ``settings``: the strategy's factors for the robot backend's task folders
        (``update``, ``suspension``, ``policy``, ``hazard_waiting``, as
        :func:`experiments.run.runner.run_scenario` takes them; ``None`` keeps the day's own).
        The synthetic backend's tasks are timed templates that no strategy changes, so
        a setting there is a :class:`ConfigError` rather than a comparison of equals."""
        settings = {k: v for k, v in settings.items() if v is not None}
        check_settings(self.backend, settings)
        if self.backend == "synthetic":
            loop = self.build()
            trace = loop.run()
            if out is not None:
                Path(out).mkdir(parents=True, exist_ok=True)
                trace.write(Path(out) / "trace.jsonl")
            return DayRun(list(trace.events))
        from experiments.run.runner import run_scenario

        # the samples from memory, as the file would give them back: no write-and-read round trip
        result = run_scenario(self.scenario, seed=self.seed, out=None if out is None else Path(out), pictures=False,
                              request_fields=True, task_wrapper=wrapper_for(robot_work(self.protocol)), **settings)
        assert result.recording is not None  # a robot run always records
        return DayRun(list(result.trace.events), tuple(result.recording.samples_as_read()), result.record.to_json())

    def build(self) -> Any:
        """The synthetic backend's ready loop (the robot at the start site)."""
        if self.backend != "synthetic":
            raise ConfigError("Day.build: only the synthetic backend builds a bare loop; run the robot day with run()")
        from experiments.inputs import synthetic

        loop = synthetic.build(self.scenario, seed=self.seed)
        loop.core.pose = self.protocol.sites[self.protocol.start_site]  # type: ignore[union-attr]  # TimedExecutor
        return loop


def make(protocol: str | Path | Protocol, seed: int, *, backend: str = "synthetic", scheduler: str = "alg2",
         scheduler_options: Mapping[str, Any] | None = None) -> Day:
    """Day ``seed`` of ``protocol`` (a registered name, a file, or a loaded protocol) on ``backend``.

    ``scheduler`` is a scheduler spec (:mod:`experiments.days.specs`: a registered name, with
    options as ``NAME:OPTION=VALUE``).  ``scheduler_options`` default to what the protocol and the
    day tell the scheduler (:func:`scheduler_options`), with the spec's options over them."""
    if backend not in _BACKENDS:
        raise ConfigError(f"unknown backend {backend!r}{suggest(backend, BACKENDS)}; known: {', '.join(BACKENDS)}")
    spec = parse(scheduler)
    proto = load(protocol)
    options = (dict(scheduler_options) | spec.as_dict() if scheduler_options is not None
               else scheduler_options_for(proto, spec, backend, seed))
    return Day(proto, seed, backend, spec.label, _BACKENDS[backend](proto, seed, spec.name, options))


def scheduler_options_for(proto: Protocol, scheduler: str | SchedulerSpec, backend: str,
                          seed: int = 0) -> dict[str, Any]:
    """What :func:`make` gives ``scheduler`` (a spec or its text): the day's options, then the spec's."""
    spec = parse(scheduler) if isinstance(scheduler, str) else scheduler
    if backend == "robot" and proto.robot is None:
        return spec.as_dict()
    return scheduler_options(proto, spec.name, backend, seed) | spec.as_dict()


def build_day(protocol: Protocol, seed: int, scheduler: str, scheduler_options: dict[str, Any] | None = None,
              ) -> SimulationLoop:
    """A ready-to-run synthetic loop for day ``seed`` under ``scheduler`` (robot at ``start_site``);
    the same as ``make(protocol, seed, scheduler=...).build()``."""
    day = make(protocol, seed, scheduler=scheduler, scheduler_options=scheduler_options or {})
    loop: SimulationLoop = day.build()
    return loop
