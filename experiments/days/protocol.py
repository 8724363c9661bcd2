"""Day protocols (TaBSA-like) and a seeded generator of synthetic days.

A protocol file (``experiments/days/protocols/tabsa.toml``, documented in ``docs/benchmark.md``)
says how a day is drawn: its length and step, the robot's speed, the apartment's sites,
the arrival process, and for each task type (transport, fall, pick_place) how many a day,
priority, cost weight, deadline window and stage durations.  :func:`load` reads it with
the strict reader; :func:`generate` draws one day from a seed and returns it as a
:class:`experiments.inputs.synthetic.SyntheticScenario` — the one scenario representation the
synthetic backend runs (:func:`experiments.inputs.synthetic.run`).

The day's task types are :class:`DayTask`, synthetic tasks whose stages are built from
each request's arguments and from where the robot is: a motion stage lasts the distance
over the speed of whoever sets the pace (the robot, or the person it escorts).  Each
request records its ``deadline`` and, for a fall, ``death_at`` (deadline +
``death_after_s``), so the metrics can judge from the trace alone.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import random
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from experiments.inputs.actions import TimedAction
from experiments.inputs.filekinds import expect
from experiments.inputs.synthetic import SyntheticScenario
from tasker.agent import Rates
from tasker.messages import SP_COMPLETION, CompletionCost, CostParams, SPRequest
from tasker.stage import Purpose, Stage, StageKind, StagePlan
from tasker.support.reader import Table, check_name, suggest
from tasker.support.reader import load as read_table
from tasker.synthetic import SyntheticTask
from tasker.task import ArgSpec, TaskContext

Pose = tuple[float, ...]
KINDS = ("transport", "fall", "pick_place")
SUSP, BLOCK = StageKind.SUSPENDABLE, StageKind.BLOCKING
MAX_REQUESTS = 10_000
"""A protocol whose counts add up to more requests a day than this is refused (a typo such as
``count = 1200000`` would otherwise run for hours; 9 000 take a minute on the synthetic backend)."""
MAX_STEPS = 1_000_000
"""A protocol whose day has more steps than this (``length_s / step_s``) is refused: the loop steps
through the whole day (about 2 million steps take 5 s of one synthetic day, and a robot day far
more), so ``length_s = 1e9`` never ended; the shipped days have 720 to 2 880 steps."""
_RESUME_STAGES = ("go_back", "apologise", "pick_again")
TOP_KEYS = ("name", "day", "robot", "apartment", "arrivals", "tasks", "robot_backend")
"""The top-level keys and tables of a protocol file."""


@dataclass(frozen=True)
class TaskSpec:
    """One task type of a protocol.  Durations in seconds, speeds in m/s; pairs are uniform ranges."""

    kind: str
    count: int
    priority: int
    weight: float
    deadline_s: tuple[float, float]
    person_speed: tuple[float, float] = (0.0, 0.0)
    work_s: tuple[float, float] = (0.0, 0.0)
    greet_s: float = 0.0
    goodbye_s: float = 0.0
    pick_s: float = 0.0
    place_s: float = 0.0
    suspend_s: float = 0.0
    resume_s: float = 0.0
    death_after_s: float | None = None


@dataclass(frozen=True)
class RobotTask:
    """How one protocol task type runs on the robot backend: a task folder and its arguments.

    ``args`` values may use ``$site`` and ``$dest`` (the world places of the request's
    sites), ``$person`` (a person of the world, one per request, scripted to be at the
    site) and ``$object`` (an object of ``object_type`` put at the site for this request).
    ``posture``: the person takes it at the call (e.g. ``fallen``) and stands up again at
    the request's ``death_at``.
    ``renew_after_s``: a request of this type whose task fails (a plan, a skill or a hook
    failed) is made again this long after, until its ``death_at`` (or the day's end): the
    need stands until served, as in TaBSA.  ``None``: a failed task stays failed.
    """

    kind: str
    task: str
    args: dict[str, str]
    object_type: str | None = None
    posture: str | None = None
    renew_after_s: float | None = None


@dataclass(frozen=True)
class RobotBackend:
    """The robot backend of a protocol: the world, where each site is in it, the task folders.

    ``spots``: per site, where its people stand, in order of preference: a request's
    person takes the first spot no one else holds then (an escorted person holds theirs
    for the rest of the day, a fallen person until taken away)."""

    world: str
    places: dict[str, str]
    spots: dict[str, tuple[Pose, ...]]
    tasks: dict[str, RobotTask]
    lead_s: float
    task_exe_rate: float


@dataclass(frozen=True)
class Protocol:
    """A checked day protocol."""

    name: str
    source: str
    start: str
    length_s: float
    step_s: float
    robot_speed: float
    start_site: str
    planning_time_s: float
    sites: dict[str, Pose]
    last_call_s: float
    tasks: dict[str, TaskSpec]
    robot: RobotBackend | None = None

    @property
    def death_after_s(self) -> float | None:
        return self.tasks["fall"].death_after_s if "fall" in self.tasks else None

    def digest(self) -> str:
        """A SHA-256 of what its days are drawn and run from: every checked value (not the file's
        comments, layout or place) and, with a robot backend, the bytes of its world file.  Stored
        with each day, so that a resumed run does not mix days of two versions of a protocol."""
        values = dataclasses.asdict(self)
        values.pop("source")
        h = hashlib.sha256(json.dumps(values, sort_keys=True, default=str).encode())
        if self.robot is not None:
            h.update(Path(self.robot.world).read_bytes())
        return h.hexdigest()


# -- reading ---------------------------------------------------------------------------------------

def _range(t: Table, key: str, *, positive: bool = False) -> tuple[float, float]:
    value = t.raw(key)
    if not (isinstance(value, list) and len(value) == 2 and all(isinstance(v, int | float) and not isinstance(v, bool)
                                                               for v in value)):
        raise t.error(key, f"expected a range [low, high] of two numbers, got {value!r}")
    low, high = float(value[0]), float(value[1])
    if low > high:
        raise t.error(key, f"expected low <= high, got [{low:g}, {high:g}]")
    if low < 0 or (positive and low <= 0):
        raise t.error(key, f"expected numbers {'> 0' if positive else '>= 0'}, got [{low:g}, {high:g}]")
    return low, high


def _pose(t: Table, key: str, value: Any) -> Pose:
    if not (isinstance(value, list) and len(value) == 2 and all(isinstance(v, int | float) and not isinstance(v, bool)
                                                               for v in value)):
        raise t.error(key, f"expected a site [x, y] in metres, got {value!r}")
    return float(value[0]), float(value[1])


def _task(t: Table, kind: str) -> TaskSpec:
    common: dict[str, Any] = dict(
        kind=kind, count=t.number("count", integer=True, min=0), priority=t.number("priority", integer=True),
        weight=t.number("weight", min=0), deadline_s=_range(t, "deadline_s"),
    )
    if kind == "transport":
        spec = TaskSpec(**common, person_speed=_range(t, "person_speed", positive=True),
                        greet_s=t.number("greet_s", min=0), goodbye_s=t.number("goodbye_s", min=0),
                        suspend_s=t.number("suspend_s", min=0), resume_s=t.number("resume_s", min=0))
    elif kind == "fall":
        spec = TaskSpec(**common, work_s=_range(t, "work_s"), death_after_s=t.number("death_after_s", min=0))
    else:
        spec = TaskSpec(**common, pick_s=t.number("pick_s", min=0), place_s=t.number("place_s", min=0),
                        suspend_s=t.number("suspend_s", min=0), resume_s=t.number("resume_s", min=0))
    t.done()
    return spec


def load(path: str | Path) -> Protocol:
    """Read and check a protocol file; every fault names the file, line and field."""
    top = read_table(path)
    expect(top, "day protocol")
    top.declare(TOP_KEYS)  # a misspelt [arivals] is named where "arrivals: missing" is said
    top.string("name")
    day, robot, apartment = top.table("day"), top.table("robot"), top.table("apartment")
    arrivals, tasks_t = top.table("arrivals"), top.table("tasks")
    for t, keys in ((day, ("length_s", "step_s", "start")), (robot, ("speed", "start_site", "planning_time_s")),
                    (arrivals, ("process", "last_call_s"))):
        t.declare(keys)
    length = day.number("length_s", positive=True)
    step = day.number("step_s", positive=True)
    if step > length:
        raise day.error("step_s", f"expected at most the day's length_s ({length:g} s), got {step:g}")
    if length / step > MAX_STEPS:
        raise day.error("length_s", f"{length:g} s in steps of step_s = {step:g} s is {length / step:.3g} steps, "
                                    f"more than the {MAX_STEPS} a day may have")
    start = day.string("start", "00:00")
    if not re.fullmatch(r"([01]\d|2[0-3]):[0-5]\d", start):
        raise day.error("start", f"expected a wall-clock time HH:MM (00:00 to 23:59), got {start!r}")
    day.done()
    sites_t = apartment.table("sites")
    sites = {name: _pose(sites_t, name, v) for name, v in sites_t.items()}
    if len(sites) < 2:
        raise sites_t.error(None, f"expected at least two sites (tasks go from one to another), got {len(sites)}")
    apartment.done()
    speed = robot.number("speed", positive=True)
    start_site = robot.name("start_site", sites, "site")
    planning = robot.number("planning_time_s", 0.0, min=0)
    robot.done()
    arrivals.string("process", "uniform", choices=("uniform",))
    last_call = arrivals.number("last_call_s", length, positive=True, max=length)
    arrivals.done()
    tasks: dict[str, TaskSpec] = {}
    for kind in tasks_t.keys():
        if kind not in KINDS:
            raise tasks_t.error(kind, f"unknown task type {kind!r}{suggest(kind, KINDS)} (known: {', '.join(KINDS)})")
        tasks[kind] = _task(tasks_t.table(kind), kind)
    if not tasks:
        raise tasks_t.error(None, f"expected at least one of {', '.join(KINDS)}")
    total = sum(spec.count for spec in tasks.values())
    if total == 0:  # every day would be empty: a table of zeros, "all done", for every scheduler
        raise tasks_t.error(None, f"the day's counts add up to 0 requests: expected a count > 0 for at least one "
                                  f"of {', '.join(tasks)}")
    if total > MAX_REQUESTS:
        kind = max(tasks, key=lambda k: tasks[k].count)
        raise tasks_t.at(kind, tasks_t.data[kind]).error(
            "count", f"the day's counts add up to {total} requests, more than the {MAX_REQUESTS} a day may have")
    tasks_t.done()
    backend = _robot_backend(top.table("robot_backend"), Path(path), sites, tasks) if "robot_backend" in top else None
    top.done(also=TOP_KEYS)  # robot_backend is optional: listed among the valid keys even when absent
    return Protocol(name=top.data["name"], source=str(path), start=start, length_s=length, step_s=step,
                    robot_speed=speed, start_site=start_site, planning_time_s=planning, sites=sites,
                    last_call_s=last_call, tasks=tasks, robot=backend)


_VARIABLES = ("$site", "$dest", "$person", "$object")


def _robot_backend(t: Table, path: Path, sites: dict[str, Pose], tasks: dict[str, TaskSpec]) -> RobotBackend:
    """``[robot_backend]``: the world file (relative to the protocol), sites, task folders."""
    world = t.string("world")
    world_file = path.parent / world
    if not world_file.is_file():
        raise t.error("world", f"no world file {world_file} (a .toml file relative to the protocol)")
    from robot.spec import load_world  # the world's TOML only (no MuJoCo): its places and rooms

    spec = load_world(world_file)
    lead = t.number("lead_s", 120.0, positive=True)
    exe_rate = t.number("task_exe_rate", 10.0, positive=True)
    sites_t = t.table("sites")
    places: dict[str, str] = {}
    spots: dict[str, tuple[Pose, ...]] = {}
    for name, _ in sites_t.items():
        check_name(sites_t, name, name, sorted(sites), "site of [apartment.sites]")
        st = sites_t.table(name)
        places[name] = st.string("place")
        check_name(st, "place", places[name], spec.places, "place",
                   f"a site's place is a place of the world file {world}")
        raw = st.raw("spots")
        if not isinstance(raw, list) or not raw:
            raise st.error("spots", f"expected a list of [x, y] where the site's people stand, got {raw!r}")
        spots[name] = tuple(_pose(st, "spots", v) for v in raw)
        for i, xy in enumerate(spots[name]):
            why = _not_standable(spec, xy)
            if why:
                raise st.error("spots", f"spot {i + 1} {list(xy)} is {why}: a person cannot stand there")
        st.done()
    missing = sorted(set(sites) - set(places))
    if missing:
        raise sites_t.error(None, f"every site needs its place and spot in the world; missing: {', '.join(missing)}")
    sites_t.done()
    tasks_t = t.table("tasks")
    out: dict[str, RobotTask] = {}
    from experiments.inputs.crossref import check_template
    from planners.bundled import task_types  # what a robot day runs: the bundled task folders and $TASKER_TASKS

    types = {tt.name: tt for tt in task_types()}
    for kind, _ in tasks_t.items():
        check_name(tasks_t, kind, kind, sorted(tasks), "task type of [tasks]")
        tt = tasks_t.table(kind)
        args_t = tt.table("args")
        args = {k: str(args_t.string(k)) for k, _ in args_t.items()}
        for k, v in args.items():
            if v.startswith("$") and v not in _VARIABLES:
                raise args_t.error(k, f"unknown variable {v!r}{_suggest(v)} (known: {', '.join(_VARIABLES)})")
        args_t.done()
        obj = tt.string("object_type", None)
        if "$object" in args.values() and obj is None:
            raise tt.error("object_type", "required when an argument is $object (the type of the object to create)")
        posture = tt.string("posture", None, choices=("fallen", "sitting", "standing"))
        if posture is not None and "$person" not in args.values():
            raise tt.error("posture", "needs a $person argument (whose posture changes)")
        name = str(tt.string("task"))
        check_name(tt, "task", name, types, "task type", "a robot day runs the bundled task types and those of "
                                                         "$TASKER_TASKS (see 'tasker domains')")
        domain = getattr(types[name], "domain", None)
        if obj is not None and getattr(domain, "types", None):
            check_name(tt, "object_type", obj, domain.types, "object type",  # type: ignore[union-attr]
                       f"a type of task type {name!r}'s domain")
        variables = {"$site": "place", "$dest": "place", "$person": "person", **({"$object": obj} if obj else {})}
        check_template(tt, types[name], args, variables, spec)  # names, required ones, each of its PDDL type
        renew = tt.number("renew_after_s", None, positive=True)
        out[kind] = RobotTask(kind, name, args, obj, posture, renew)
        tt.done()
    missing = sorted(set(tasks) - set(out))
    if missing:
        raise tasks_t.error(None, "every task type of [tasks] needs its task folder here; "
                                  f"missing: {', '.join(missing)}")
    tasks_t.done()
    t.done()
    return RobotBackend(world=str(world_file.resolve()), places=places, spots=spots, tasks=out, lead_s=lead,
                        task_exe_rate=exe_rate)


def _not_standable(spec: Any, xy: Pose) -> str:
    """Why no person can stand at ``xy`` in world ``spec`` (empty if one can): in no room, or
    outside the world's free space (:func:`robot.spec.point_problem`)."""
    from robot.spec import point_problem, room_of

    if room_of(spec, xy[0], xy[1]) is None:
        return f"in no room of world {spec.name!r} (rooms: {', '.join(sorted(spec.rooms))})"
    return point_problem(spec, xy[0], xy[1]) or ""


def _suggest(value: str) -> str:
    return suggest(value, _VARIABLES)


# -- the day's task types --------------------------------------------------------------------------

def _dist(a: Pose | None, b: Pose | None) -> float:
    if a is None or b is None:
        return 0.0
    return math.hypot(a[0] - b[0], a[1] - b[1])


def _move(action: str, target: Pose, speed: float, origin: Pose | None = None) -> Stage:
    """A motion stage; ``origin`` set means the motion has a fixed start (escort, carry)."""
    return Stage(action, kind=SUSP, duration=0.0 if origin is None else _dist(origin, target) / speed,
                 skill="timed", data={"site": target, "from": origin, "speed": speed})


class DayTask(SyntheticTask):
    """A protocol task type; its stages come from the request (site, dest, work, walk speed).

    ``transport``: go to the person, greet (blocking), escort at the person's pace to
    ``dest``, goodbye (blocking); suspended while escorting, the robot asks the person to
    wait (blocking) and apologises on return.  ``fall``: go to the person, help for
    ``work`` seconds (blocking: not interruptible).  ``pick_place``: go to the object,
    pick (blocking), carry to ``dest``, place (blocking); suspended while carrying, the
    robot puts the object down and picks it up again on return.

    A stopped motion stage restarts from its origin (the synthetic executor does not
    track partial motion), after the robot has travelled back there: progress lost to
    an interruption is a real cost here, as is the travel.
    """

    def __init__(self, spec: TaskSpec, robot_speed: float, planning_time: float) -> None:
        super().__init__(spec.kind, [Stage("placeholder")], weight=spec.weight, speed=robot_speed,
                         planning_time=planning_time)
        self.spec = spec
        self.description = f"protocol task {spec.kind!r}"
        self.arg_specs = (*self.arg_specs,
                          ArgSpec("dest", "pose", required=False, help="where the person or object goes"),
                          ArgSpec("work", "float", required=False, default=0.0, help="seconds of work on site"),
                          ArgSpec("walk_speed", "float", required=False, default=robot_speed,
                                  help="pace of the escorted person (m/s)"),
                          ArgSpec("death_at", "float", required=False,
                                  help="time the person is dead if not helped (falls; for metrics)"))

    # -- stages -------------------------------------------------------------------------------------
    def _template(self, args: dict[str, Any]) -> list[Stage]:
        s, site, dest = self.spec, args["site"], args["dest"]
        go = _move("go_to", site, self.speed)
        if s.kind == "transport":
            return [go, Stage("meet", kind=BLOCK, duration=s.greet_s),
                    _move("escort", dest, args["walk_speed"], site), Stage("goodbye", kind=BLOCK, duration=s.goodbye_s)]
        if s.kind == "fall":
            return [go, Stage("help", kind=BLOCK, duration=args["work"])]
        return [go, Stage("pick_up", kind=BLOCK, duration=s.pick_s), _move("carry", dest, self.speed, site),
                Stage("place", kind=BLOCK, duration=s.place_s)]

    def _build(self, ctx: TaskContext, start: Pose | None, resume: bool) -> list[Stage]:
        rest = list(ctx.remaining) if ctx.plan is not None else self._template(ctx.args)
        rest = [st for st in rest if st.action not in _RESUME_STAGES]  # an unfinished resume is rebuilt below
        out: list[Stage] = []
        pose = start
        first = rest[0] if rest else None
        if resume and first is not None and first.data.get("from") is not None:
            origin = first.data["from"]
            out.append(Stage("go_back", kind=SUSP, duration=_dist(pose, origin) / self.speed, skill="timed",
                             data={"site": origin, "from": None, "speed": self.speed}))
            pose = origin
            if self.spec.resume_s:
                action = "apologise" if self.spec.kind == "transport" else "pick_again"
                out.append(Stage(action, kind=BLOCK, duration=self.spec.resume_s))
        for st in rest:
            if "speed" in st.data:
                origin = st.data["from"]
                d = _dist(pose if origin is None else origin, st.data["site"]) / st.data["speed"]
                st = Stage(st.action, kind=st.kind, duration=d, skill="timed", data=st.data)
                pose = st.data["site"]
            out.append(st)
        return out

    def update_task(self, ctx: TaskContext) -> StagePlan:
        ctx.memory["waiting"] = False
        stages = self._build(ctx, self._robot_pose(ctx), resume=ctx.suspended)
        return StagePlan(tuple(stages), Purpose.UP_TSK, strategy="static", sim_time=self.planning_time)

    def generate_suspension(self, ctx: TaskContext) -> StagePlan:
        ctx.memory["waiting"] = True
        stopped = ctx.interrupted
        stages: tuple[Stage, ...] = ()
        if stopped is not None and stopped.data.get("from") is not None and self.spec.suspend_s:
            action = "ask_to_stay" if self.spec.kind == "transport" else "set_down"
            stages = (Stage(action, kind=BLOCK, duration=self.spec.suspend_s),)
        return StagePlan(stages, Purpose.GEN_SUSP, strategy="static", sim_time=self.planning_time)

    # -- estimates ----------------------------------------------------------------------------------
    def _c_time(self, ctx: TaskContext, start: Pose | None) -> float:
        started = ctx.plan is not None and not ctx.memory.get("waiting", False)
        if started and start is None:
            return self._remaining(ctx)  # executing: what is left of the current plan
        # not started, waiting, or asked "from another pose" (i.e. resumed later): the plan it would build
        stages = self._build(ctx, start, resume=started or ctx.suspended)
        return sum(s.duration for s in stages) + self.planning_time

    def _end_pose(self, ctx: TaskContext) -> Pose | None:
        return ctx.args["dest"] if ctx.args["dest"] is not None else ctx.args["site"]

    def compute_params(self, ctx: TaskContext) -> CostParams:
        c_time = self._c_time(ctx, None if ctx.plan is not None and not ctx.memory.get("waiting")
                              else self._robot_pose(ctx))
        w = ctx.args["weight"]
        return CostParams(self.name, cost=w * (ctx.age + c_time), cps=w, c_time=c_time, end_pose=self._end_pose(ctx),
                          deadline=ctx.args["deadline"], priority=ctx.args["priority"])

    def request_sp(self, ctx: TaskContext, request: SPRequest) -> CompletionCost:
        if request.sp_id != SP_COMPLETION:
            return super().request_sp(ctx, request)
        pose = request.args.get("pose")
        c_time = self._c_time(ctx, tuple(pose) if pose is not None else self._robot_pose(ctx))
        w = ctx.args["weight"]
        return CompletionCost(cc=w * (ctx.age + c_time), ccps=w)


# -- generating a day ------------------------------------------------------------------------------

def task_types(protocol: Protocol) -> tuple[DayTask, ...]:
    return tuple(DayTask(spec, protocol.robot_speed, protocol.planning_time_s) for spec in protocol.tasks.values())


@dataclass(frozen=True)
class DayRequest:
    """One request of a drawn day, before any backend gives it a form.

    ``site`` and ``dest`` are site names of the protocol; ``deadline`` and ``death_at``
    absolute seconds; ``work`` (falls) and ``walk_speed`` (transports) as drawn.
    """

    t: float
    kind: str
    site: str
    dest: str
    deadline: float
    priority: int
    weight: float
    work: float | None = None
    walk_speed: float | None = None
    death_at: float | None = None


def draw(protocol: Protocol, seed: int) -> tuple[DayRequest, ...]:
    """The requests of day ``seed``, in call order: the same seed gives the same day.

    Each task type draws its own stream (``random.Random(f"{name}:{seed}:{kind}")``), so
    adding a type to a protocol leaves the other types' draws unchanged.  Both backends
    are built from this one draw (:mod:`experiments.days.pipeline`).
    """
    sites = sorted(protocol.sites)
    requests: list[tuple[float, int, DayRequest]] = []
    for kind, spec in protocol.tasks.items():
        rng = random.Random(f"{protocol.name}:{seed}:{kind}")
        for _ in range(spec.count):
            call = round(rng.uniform(0.0, protocol.last_call_s), 1)
            deadline = round(call + rng.uniform(*spec.deadline_s), 1)
            a, b = rng.sample(sites, 2)
            extra: dict[str, Any] = {}
            if kind == "transport":
                extra["walk_speed"] = round(rng.uniform(*spec.person_speed), 3)
            elif kind == "fall":
                extra["work"] = round(rng.uniform(*spec.work_s), 1)
                assert spec.death_after_s is not None
                extra["death_at"] = round(deadline + spec.death_after_s, 1)
            requests.append((call, len(requests), DayRequest(call, kind, a, b, deadline, spec.priority, spec.weight,
                                                             **extra)))
    requests.sort(key=lambda r: (r[0], r[1]))
    return tuple(r for *_, r in requests)


def generate(protocol: Protocol, seed: int, *, scheduler: str = "alg2",
             scheduler_options: dict[str, Any] | None = None) -> SyntheticScenario:
    """Day ``seed`` of ``protocol`` (:func:`draw`) as a synthetic scenario."""
    actions = []
    for r in draw(protocol, seed):
        args: dict[str, Any] = {"site": list(protocol.sites[r.site]), "deadline": r.deadline, "priority": r.priority,
                                "weight": r.weight}
        if r.kind == "transport":
            args["dest"] = list(protocol.sites[r.dest])
            args["walk_speed"] = r.walk_speed
        elif r.kind == "fall":
            args["work"] = r.work
            args["death_at"] = r.death_at
        else:
            args["dest"] = list(protocol.sites[r.dest])
        actions.append(TimedAction(r.t, "request", {"task": r.kind, "args": args}))
    rate = 1.0 / protocol.step_s
    return SyntheticScenario(
        name=f"{protocol.name}-day{seed}", tasks=task_types(protocol), actions=tuple(actions), scheduler=scheduler,
        scheduler_options=dict(scheduler_options or {}), mode="IT", s_freq=rate, rates=Rates(rate, rate, rate),
        jitter=0.0, seed=seed, horizon=protocol.length_s,
    )
