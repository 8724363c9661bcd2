"""Run one scenario: build the system, run it on the simulated clock, save what happened.

:func:`run_scenario` is what ``tasker run`` and the sweeps call.  A robot scenario
gets the TIAGo simulation (:class:`robot.sim.Simulation`, both the world and the core
agent), the OMPL motion model, and the bundled PDDL task types; a synthetic one gets
timed stages.  In ``out`` it writes ``trace.jsonl`` (reproducible byte for byte),
``trajectory.jsonl`` (robot and people at a fixed rate, robot runs),
``run.json`` (the record: scenario, seed, settings, planner, host, date, version),
``metrics.json`` and the pictures.  If the run raises, the trace so far, ``run.json``
(with ``status: "aborted"`` and the ``error``) and ``metrics.json`` are still written,
then :class:`tasker.errors.RunAborted` is raised carrying the partial :class:`RunResult`.
"""

from __future__ import annotations

import contextlib
import dataclasses
import datetime as _dt
import json
import platform
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import tasker
from experiments.inputs import fields, synthetic
from experiments.inputs import scenario as scenarios
from experiments.inputs.actions import Change, ModeSwitch, Request, Terminate, TimedAction, WorldEvent
from experiments.inputs.perturbation import TOGGLE, TargetDraw, named
from experiments.inputs.request_fields import asked_for
from experiments.metrics import run as metrics
from experiments.report.explain import INDEX, write_problems
from experiments.run.options import RunOptions
from experiments.run.records import PlannerConfig, RunRecord, RunSettings
from experiments.run.simulation import SimulatedWorld
from experiments.run.targeting import Targeter
from experiments.trace.timeline import Timeline
from tasker import events as ev
from tasker import schedulers
from tasker.agent import Rates
from tasker.errors import RunAborted, RunInterrupted
from tasker.harmoniser import Mode
from tasker.loop import SimulationLoop
from tasker.meaning import Monitor
from tasker.requester import Requester
from tasker.store import TaskStore
from tasker.task import Strategy, TaskType
from tasker.trace import FAILED, Trace

if TYPE_CHECKING:
    from planners.pddl_task import PlanningRecord
    from robot.recording import Recorder
    from robot.spec import WorldSpec


@dataclass(frozen=True)
class RunResult:
    """What one run produced: its record, its metrics and its trace."""

    record: RunRecord
    metrics: dict[str, Any]
    trace: Trace
    trajectory: tuple[tuple[float, float, float, float], ...] = ()
    recording: Recorder | None = None
    """A robot run's :class:`robot.recording.Recorder` (``trajectory.jsonl`` is written from it); None if synthetic."""


def build_robot(scn: scenarios.RobotScenario, options: RunOptions, *, trace: Trace | None = None,
                task_wrapper: Callable[[TaskType], TaskType] | None = None) -> tuple[SimulationLoop, SimulatedWorld]:
    """The loop and the simulation for a robot scenario, with every request and event scheduled
    (:func:`build_robot_actions`)."""
    loop, sim, _ = build_robot_actions(scn, options, trace=trace, task_wrapper=task_wrapper)
    return loop, sim


def build_robot_actions(scn: scenarios.RobotScenario, options: RunOptions, *, trace: Trace | None = None,
                        task_wrapper: Callable[[TaskType], TaskType] | None = None
                        ) -> tuple[SimulationLoop, SimulatedWorld, Actions]:
    """The loop, the simulation and the :class:`Actions` of a robot scenario, every action scheduled.

    ``options`` (:class:`~experiments.run.options.RunOptions`, whose ``seed`` must be set) choose
    the strategies, the scheduler and the tree over the scenario's own; its ``task_paths`` are task
    folders loaded besides the bundled ones and ``$TASKER_TASKS``; ``request_fields`` lets every
    task type take the requests' ``deadline`` and ``priority`` (:mod:`experiments.inputs.request_fields`),
    on too whenever the scenario's requests give one or its ``settings.request_fields`` is true.
    ``task_wrapper`` is applied to every task type after that (a day's drawn work:
    :mod:`experiments.days.robot_work`).  A ``people`` entry may set a person's ``pose``, ``walk`` and
    walking ``speed``."""
    from planners.bundled import task_types
    from robot.sim import Simulation
    from robot.spec import load_world

    spec = load_world(scn.world)
    if scn.people:
        people = dict(spec.people)
        for name, entry in scn.people.items():
            if name not in people:
                raise scenarios.ScenarioError(f"{scn.source}: people.{name}: no such person in world {scn.world!r}; "
                                              f"known: {sorted(people)}")
            changes: dict[str, Any] = {}
            if "pose" in entry:
                changes["pose"] = tuple(entry["pose"])
            if "walk" in entry:
                changes["walk"] = tuple(tuple(w) for w in entry["walk"])
            if "speed" in entry:
                changes["speed"] = float(entry["speed"])
            people[name] = dataclasses.replace(people[name], **changes)
        spec = dataclasses.replace(spec, people=people)
    spec = _with_objects(scn, spec)
    spec, from_world = _world_file_events(spec, str(scn.world))
    seed = scn.seed if options.seed is None else options.seed
    update, suspension, scheduler, policy = options.update, options.suspension, options.scheduler, options.policy
    sim = Simulation(spec, seed=seed)
    loaded = task_types(options.task_paths)
    if options.request_fields or scn.request_fields or asked_for(scn.actions):
        from experiments.inputs.request_fields import with_request_fields

        loaded = [with_request_fields(t) for t in loaded]
    if task_wrapper is not None:
        loaded = [task_wrapper(t) for t in loaded]
    store = TaskStore(loaded)
    types = [store.get(n) for n in store.names()]
    sim.bind(b for t in types for b in t.meaning.bindings)  # the world reads the folders' bindings
    default = Strategy(update or scn.update, suspension or scn.suspension, policy or scn.policy)
    per_type = {t: Strategy(update or s.get("update", default.update),
                            suspension or s.get("suspension", default.suspension), default.policy)
                for t, s in scn.strategies.items()}
    per_type = _with_trees(options, types, default, per_type)
    # another scheduler than the scenario's gets no options of its, but what the folders declare (alg2's classes)
    scheduler_options = scn.scheduler_options if scheduler in (None, scn.scheduler) else \
        fields.scheduler_defaults(str(scheduler), {}, types)
    loop = SimulationLoop(
        store, schedulers.create(scheduler or scn.scheduler, **scheduler_options), seed=seed, trace=trace,
        mode=Mode(scn.mode), s_freq=scn.s_freq, rates=Rates(scn.rep_rate, scn.task_exe_rate, scn.sp_up_rate),
        strategy=default, strategies=per_type, core=sim, world=sim, motion=sim.motion, horizon=scn.horizon,
        hazard_waiting=options.hazard_waiting, secure_over_higher=scn.secure_over_higher,
    )
    monitor = Monitor(loop.trace, lambda: loop.all_agents, lambda name: store.get(name).meaning,
                      lambda: sim.snapshot().facts, task_types=store.names(),
                      version=sim.facts_key)
    loop.observers.append(monitor.observe)
    loop.harmoniser.hazards = monitor.active  # hazard-aware waiting learns of hazards from the monitor
    actions = Actions(loop, sim, _Made(loop, Requester(store, loop.harmoniser, "scenario")))
    for a in sorted([*from_world, *scn.actions], key=lambda a: a.t):  # stable: the world file's first at a tie
        if isinstance(a.payload, Request):
            store.validate(a.payload.task, a.payload.args)  # bad requests fail before the run
        actions.schedule(a)
    return loop, sim, actions


class Actions:
    """Schedules a scenario's timed actions on its built loop: :func:`build_robot` every action of
    the scenario before the run, a live controller (:mod:`experiments.serve`) each action as it
    arrives.  The K-th request scheduled is the scenario's ``dK`` (what ``terminate``, ``change``
    and ``after`` name); :meth:`agents` says which agents were made for it."""

    def __init__(self, loop: SimulationLoop, sim: SimulatedWorld, made: _Made) -> None:
        self.loop, self.sim, self._made = loop, sim, made
        self.requests = 0

    def schedule(self, a: TimedAction) -> str | None:
        """Run ``a`` at ``a.t`` through the same path as a scenario's; a request's scenario id."""
        if a.kind == "request":
            self.requests += 1
        self.loop.at(a.t, _action(self.loop, self.sim, self._made, a, f"d{self.requests}"))
        return f"d{self.requests}" if a.kind == "request" else None

    def now(self, a: TimedAction) -> None:
        """Run world action ``a`` at once (a change chosen while the run runs: :mod:`experiments.run.targeting`)."""
        _action(self.loop, self.sim, self._made, a, "")()

    def agents(self, sid: str) -> tuple[str, ...]:
        """The agents made for the scenario's request ``sid`` so far (renewals after the first)."""
        return tuple(self._made.agents.get(sid, ()))


def _with_trees(options: RunOptions, types: list[TaskType], default: Strategy,
                per_type: dict[str, Strategy]) -> dict[str, Strategy]:
    """``per_type`` with ``options.tree`` given to each task type that declares a tree of that name (or
    to the one it names, ``TYPE:NAME``); a tree no task type of the run declares is an error."""
    if options.tree is None:
        return per_type
    out = dict(per_type)
    chosen = []
    for t in types:
        name = options.tree_for(t.name, t.tree_names())
        if name is not None:
            out[t.name] = replace(out.get(t.name, default), tree=name)
            chosen.append(t.name)
    if not chosen:
        known = sorted(f"{t.name}:{n}" for t in types for n in t.tree_names())
        raise scenarios.ScenarioError(f"--tree {options.tree}: no task type of this run has that decision tree; "
                                      f"known: {', '.join(known) or 'none'}")
    return out


def _world_file_events(spec: WorldSpec, world: str) -> tuple[WorldSpec, list[TimedAction]]:
    """The world file's own timed events (a person's ``events = [[t, posture]]``) taken out of the
    people and returned as world events, so they run — and are traced — as a scenario's do."""
    out = [TimedAction(float(t), "world", {"what": "posture", "value": [name, posture],
                                           "note": f"world file {world}"})
           for name, p in spec.people.items() for t, posture in p.events]
    if not out:
        return spec, []
    people = {name: dataclasses.replace(p, events=()) for name, p in spec.people.items()}
    return dataclasses.replace(spec, people=people), sorted(out, key=lambda a: a.t)


def _with_objects(scn: scenarios.RobotScenario, spec: WorldSpec) -> WorldSpec:
    """The world with the scenario's ``[objects]``: each gets its type, ``("at", name, place)``
    and its facts (its pose is its place's, see :meth:`robot.sim.Simulation.snapshot`); and with
    its ``[devices]``, as if the world file listed them."""
    spec = scenarios.with_devices(scn, spec)
    if not scn.objects:
        return spec
    objects = dict(spec.objects)
    facts = list(spec.facts)
    for name, o in sorted(scn.objects.items()):
        if o["place"] not in spec.places:
            raise scenarios.ScenarioError(f"{scn.source}: objects.{name}.place: no place {o['place']!r} in world "
                                          f"{scn.world!r}; known: {sorted(spec.places)}")
        taken = set(spec.places) | set(spec.people) | set(spec.devices) | set(spec.doors) | {"robot"}
        if name in taken:
            raise scenarios.ScenarioError(f"{scn.source}: objects.{name}: the world already has something "
                                          f"called {name!r}")
        objects[name] = o["type"]
        facts = [f for f in facts if not (f[0] == "at" and len(f) == 3 and f[1] == name)]
        facts.append(("at", name, o["place"]))
        facts += [tuple(f) for f in o.get("facts", [])]
    return dataclasses.replace(spec, objects=objects, facts=tuple(dict.fromkeys(facts)))


class _Made:
    """The scenario's requests as made.  Its K-th request is ``dK`` in the scenario's own
    terms (``after``, ``terminate``, ``change``); the agents made for it are the one the
    request made and any that renew it.  A request with ``renew`` (``{"after_s", "until"}``)
    whose task ends without doing its work (an ``end`` cause in :data:`tasker.trace.FAILED`)
    is asked for again ``after_s`` later, if that is before ``until``: the need stands until
    served (a day's fall, until the person is helped or dead).  Without renewals ``dK`` is
    the K-th agent, as the harmoniser numbers them."""

    def __init__(self, loop: SimulationLoop, requester: Requester) -> None:
        self.loop, self.requester = loop, requester
        self.agents: dict[str, list[str]] = {}
        self._renewable: dict[str, tuple[str, Request]] = {}  # agent -> (its scenario id, its request)
        self._terminated: set[str] = set()  # scenario ids a requester terminated: never renewed
        loop.trace.subscribe(self._watch)

    def current(self, sid: str) -> str:
        """The agent now standing for the scenario's ``sid`` (``sid`` itself before it is made)."""
        made = self.agents.get(sid)
        return made[-1] if made else sid

    def terminate(self, sid: str, reason: str) -> None:
        self._terminated.add(sid)
        self.requester.terminate(self.current(sid), reason)

    def submit(self, sid: str, a: Request, renews: str | None = None) -> None:
        if renews is not None and sid in self._terminated:
            return
        agent = self.requester.request(a.task, a.args, renews=renews)
        self.agents.setdefault(sid, []).append(agent)
        if a.renew is not None:
            self._renewable[agent] = (sid, a)

    def _watch(self, e: ev.Event) -> None:
        if not isinstance(e, ev.TaskEnded) or e.cause not in FAILED or e.agent not in self._renewable:
            return
        sid, a = self._renewable.pop(e.agent)
        assert a.renew is not None
        when = e.t + a.renew.after_s
        if when < a.renew.until:
            self.loop.at(when, lambda: self.submit(sid, a, renews=e.agent))


def _action(loop: SimulationLoop, sim: SimulatedWorld, made: _Made, a: TimedAction, sid: str) -> Callable[[], None]:
    """What happens at ``a.t``; ``sid``: the scenario's id of the latest request (``a``'s own if it is one)."""
    p = a.payload
    requester = made.requester
    if isinstance(p, Request):
        return lambda: made.submit(sid, p)  # through the public requester, as any user's requests
    if isinstance(p, Terminate):
        return lambda: made.terminate(p.agent, p.reason)
    if isinstance(p, Change):
        return lambda: synthetic._change(loop, requester, made.current(p.agent), p.args)
    if isinstance(p, ModeSwitch):
        return lambda: loop.harmoniser.set_mode(p.mode)
    assert isinstance(p, WorldEvent)

    def world_event() -> None:
        what, value = p.what, p.value
        if what == "posture":
            sim.people[value[0]].set_posture(value[1])
        elif what == "walk":
            sim.people[value[0]].go_to(loop.now, float(value[1]), float(value[2]))
        elif what == "door":
            if value[1] == TOGGLE:  # whichever it is not now (the robot may have opened or closed it)
                value = [value[0], not sim.door_open[value[0]]]
            sim.set_door(value[0], value[1])
        elif what == "device":
            if value[1] == TOGGLE:
                value = [value[0], "off" if sim.device_state[value[0]] == "on" else "on"]
            sim.set_device(value[0], value[1])
        elif what == "move":  # an object someone moved: wherever it was, its relations gone (not if held)
            sim.move(value[0], value[1])
        elif what == "add":
            sim.apply(add=value)
        else:
            sim.apply(delete=value)
        loop.trace.emit(ev.WorldChanged(loop.now, what, value, "" if p.note is None else p.note))

    if p.after is None:
        return world_event
    return _after(loop, made, p.after, world_event)


def _after(loop: SimulationLoop, made: _Made, sid: str, event: Callable[[], None]) -> Callable[[], None]:
    """``event`` at its time if the scenario's request ``sid`` has been served by then (one of
    its agents ended with cause ``finished``), else as soon as it is (in the tick that ``end``
    event is traced); never if it is not."""
    state = {"finished": False, "due": False}

    def watch(e: ev.Event) -> None:
        if isinstance(e, ev.TaskEnded) and e.cause == "finished" and e.agent in made.agents.get(sid, ()) \
                and not state["finished"]:
            state["finished"] = True
            if state["due"]:
                loop.at(loop.now, event)

    loop.trace.subscribe(watch)

    def at_time() -> None:
        state["due"] = True
        if state["finished"]:
            event()

    return at_time


def run_scenario(source: str | Path | scenarios.RobotScenario, options: RunOptions | None = None, *,
                 out: Path | None = None, progress: bool = False, pictures: bool = True,
                 task_wrapper: Callable[[TaskType], TaskType] | None = None,
                 live: Callable[[SimulationLoop, SimulatedWorld, Actions], scenarios.RobotScenario] | None = None,
                 **changes: Any) -> RunResult:
    """Run a scenario (a shipped name, a path, or a loaded robot scenario) and return what it produced.

    ``options`` (:class:`~experiments.run.options.RunOptions`) choose the seed, the strategies, the
    scheduler, the tree, a randomised variant (``randomize``, with ``interruption`` placing the
    interrupting request in the seed's stratum, :class:`experiments.inputs.scenario.InterruptionGrid`,
    and ``perturbation`` changing its world, :mod:`experiments.inputs.perturbation`) and the task
    folders besides the bundled ones; ``changes`` are fields of it given as keywords
    (``run_scenario("carry", suspension="static")``).  ``task_wrapper``: see
    :func:`build_robot_actions`.  ``live`` drives a robot scenario's loop instead of running it to its
    end (``tasker serve``, :mod:`experiments.serve`): it gets the loop, the simulation and their
    :class:`Actions`, and returns the scenario that replays what it ran (the scenario ``run.json``
    records)."""
    opts = dataclasses.replace(options or RunOptions(), **changes)
    if isinstance(source, scenarios.RobotScenario):
        kind, scn_path = "robot", Path(source.source)
    else:
        scn_path = scenarios.resolve(source)
        kind = scenarios.kind_of(scn_path)
    t0 = time.perf_counter()
    trajectory: tuple[tuple[float, float, float, float], ...] = ()
    actions: Actions | None = None
    if kind == "synthetic":
        syn = synthetic.load(scn_path)
        run_seed = syn.seed if opts.seed is None else opts.seed
        loop = synthetic.build(syn, seed=run_seed, scheduler=opts.scheduler, mode=opts.mode)
        spec_json: dict[str, Any] = {"kind": "synthetic", "name": syn.name, "source": str(scn_path)}
        sim = None
    elif kind == "robot":
        scn = source if isinstance(source, scenarios.RobotScenario) else scenarios.load(
            scn_path, task_paths=opts.task_paths)
        run_seed = scn.seed if opts.seed is None else opts.seed
        draw = _target_draw(scn, run_seed, opts)
        if opts.randomize:
            scn = scenarios.randomize(scn, run_seed, interruption=opts.interruption, perturbation=opts.perturbation)
        if opts.mode is not None:
            scn = dataclasses.replace(scn, mode=opts.mode)
        loop, sim, actions = build_robot_actions(scn, dataclasses.replace(opts, seed=run_seed),
                                                 task_wrapper=task_wrapper)
        if draw is not None:
            Targeter(loop, sim, actions.now, *draw)
        spec_json = {"kind": "robot", **scn.to_json()}
    else:
        raise scenarios.ScenarioError(f"{scn_path}: kind: expected 'robot' or 'synthetic', got {kind!r}")
    if opts.cold and kind == "robot":
        from planners.pddl_task import forget_caches

        forget_caches()
    error: BaseException | None = None
    with _journal(kind) as journal:  # the PDDL of every planning call, for problems/
        try:
            if live is not None and actions is not None and sim is not None:
                spec_json = {"kind": "robot", **live(loop, sim, actions).to_json()}
            else:
                _run(loop, progress)
        except Exception as exc:  # the trace so far, run.json and metrics.json are still written, then it propagates
            error = exc
        except KeyboardInterrupt as exc:  # the user stopped it: keep what ran, closed like a run cut by its horizon
            error = exc
            loop.trace.emit(ev.RunStopped(loop.now, "interrupted", None, sorted(loop.harmoniser.agents)))
    wall = time.perf_counter() - t0
    trace = loop.trace
    world_spec = None
    if sim is not None:
        trajectory = tuple(sim.trajectory)
        world_spec = sim.spec
    calls = loop.planner_calls
    settings = RunSettings(
        loop.harmoniser.scheduler.name, loop.harmoniser.mode.value,
        # synthetic task types have only static strategies: say what was used
        update="static" if kind == "synthetic" else (opts.update or loop.strategy.update),
        suspension="static" if kind == "synthetic" else (opts.suspension or loop.strategy.suspension),
        randomized=opts.randomize, policy=None if kind == "synthetic" else loop.strategy.policy,
        hazard_waiting=opts.hazard_waiting, tree=opts.tree,
        interruption=opts.interruption.to_json() if opts.interruption and opts.randomize else None,
        perturbation=opts.perturbation.to_json() if opts.perturbation and opts.randomize else None)
    record = RunRecord(
        spec_json, run_seed, settings, _planner_config() if kind == "robot" else None,
        host=platform.node(), platform=platform.platform(), python=sys.version.split()[0],
        date=_dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"), tasker_version=tasker.__version__,
        wall_time_s=round(wall, 3))
    reason = ""
    if error is None:
        metrics = _metrics(trace, calls, wall)
    else:
        if isinstance(error, KeyboardInterrupt):
            reason, status = f"interrupted by the user at t={loop.now:g} s", "interrupted"
        else:
            reason = error.reason if isinstance(error, RunAborted) else f"{type(error).__name__}: {error}"
            status = "aborted"
        record = dataclasses.replace(record, status=status, error=reason)
        try:
            metrics = _metrics(trace, calls, wall)
        except Exception as exc:  # metrics of a cut trace may not compute: say so, keep the rest
            metrics = {"error": f"metrics failed on the partial trace: {type(exc).__name__}: {exc}"}
    if out is not None:
        _save(Path(out), record, metrics, trace, trajectory, world_spec, pictures and error is None, sim, journal)
    result = RunResult(record, metrics, trace, trajectory, None if sim is None else sim.recording)
    if isinstance(error, KeyboardInterrupt):
        raise RunInterrupted(reason, result) from error
    if error is not None:
        raise RunAborted(reason, result) from error
    return result


def _target_draw(scn: scenarios.RobotScenario, seed: int,
                 opts: RunOptions) -> tuple[TargetDraw, float, set[str]] | None:
    """For a targeted variant: its draw, the time of its interruption and what its requests name."""
    p, grid = opts.perturbation, opts.interruption
    if not (opts.randomize and p is not None and p.mode == "targeted" and grid is not None):
        return None
    return TargetDraw.of(p, f"{scn.name}:{seed}"), scenarios.placed_time(scn.name, seed, grid), named(scn.actions)


def _journal(kind: str) -> contextlib.AbstractContextManager[list[Any]]:
    if kind != "robot":
        return contextlib.nullcontext([])
    from planners.pddl_task import planning_journal

    return planning_journal()


def _run(loop: SimulationLoop, progress: bool) -> None:
    if not progress:
        loop.run()
        return
    from tqdm import tqdm

    horizon = loop.horizon
    with tqdm(total=round(horizon), unit="sim s", desc="simulating", leave=False, file=sys.stderr) as bar:
        while True:
            before = loop.now
            loop.run(until=loop.now + 10.0)
            bar.update(round(loop.now) - bar.n)
            if not loop.harmoniser.busy and loop._pending_events == 0 or loop.now <= before or loop.now >= horizon:
                break


def _planner_config() -> PlannerConfig:
    from planners.pddl_task import default_planner

    p = default_planner()
    return PlannerConfig(getattr(p, "name", "tasker-fd"), _version("unified-planning"), _version("up-fast-downward"))


def _version(dist: str) -> str | None:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(dist)
    except PackageNotFoundError:
        return None


def _metrics(trace: Trace, calls: list[dict[str, Any]], wall: float) -> dict[str, Any]:
    tl = Timeline(trace.typed)
    m = metrics.compute(tl)
    sim_time = tl.t_end
    m["planner_wall_time_s"] = round(sum(float(c.get("planner_time_s", 0.0)) for c in calls), 6)
    # each genSusp's planner wall time (0 for a tree's stages): what planning a suspension costs, host-dependent
    m["gensusp_wall_s"] = [round(float(c.get("planner_time_s", 0.0)), 6) for c in calls
                           if c.get("purpose") == "genSusp"]
    m["planner_cache_hits"] = sum(1 for c in calls if c.get("cached"))
    m["wall_time_s"] = round(wall, 3)
    m["real_time_factor"] = round(sim_time / wall, 2) if wall > 0 else None
    return m


OUTPUTS = ("trace.jsonl", "trajectory.jsonl", "run.json", "metrics.json", "timeline.png", "gantt.png",
           "world.png", "report.html")
"""The files a run writes into its folder (and ``problems/``), each only when it has one."""


def _clear_outputs(out: Path) -> None:
    """Remove what an earlier run wrote into ``out`` (:data:`OUTPUTS`, ``problems/``'s PDDL, plans and
    index) and nothing else: a run writes only some of them (no pictures with ``--no-pictures``, no
    trajectory for a synthetic scenario, fewer planning calls), so the rest would read as this run's."""
    if not ((out / "trace.jsonl").is_file() and (out / "run.json").is_file()):
        return  # not a run's folder (e.g. --out . in a project): nothing of a run to remove
    for name in OUTPUTS:
        (out / name).unlink(missing_ok=True)
    problems = out / "problems"
    if problems.is_dir():
        for f in problems.iterdir():
            if f.is_file() and (f.name == INDEX or f.suffix in (".pddl", ".plan")):
                f.unlink()
        if not any(problems.iterdir()):
            problems.rmdir()


def _save(out: Path, record: RunRecord, metrics_: dict[str, Any], trace: Trace,
          trajectory: tuple[tuple[float, float, float, float], ...], world: WorldSpec | None, pictures: bool,
          sim: SimulatedWorld | None = None, journal: Sequence[PlanningRecord] = ()) -> None:
    out.mkdir(parents=True, exist_ok=True)
    _clear_outputs(out)
    trace.write(out / "trace.jsonl")
    if sim is not None:  # poses and postures at a fixed rate (robot.recording)
        sim.write_trajectory(out / "trajectory.jsonl")
    (out / "run.json").write_text(json.dumps(record.to_json(), indent=2, sort_keys=True, default=str) + "\n")
    (out / "metrics.json").write_text(json.dumps(metrics_, indent=2, sort_keys=True) + "\n")
    write_problems(out / "problems", journal)
    if not pictures:
        return
    from experiments.report import plots
    from experiments.report import run_page as report_html

    tl = Timeline(trace.typed)  # read once by every picture
    plots.timeline(tl, out / "timeline.png")
    plots.gantt(tl, out / "gantt.png")
    report_html.write_run(out, tl, record=record.to_json(), metrics=metrics_, world=world, trajectory=trajectory)
    if world is not None:
        plots.world_path(world, list(trajectory), out / "world.png", events=tl,
                         recording=getattr(sim, "recording", None))
