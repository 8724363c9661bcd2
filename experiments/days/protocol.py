"""Day protocols (TaBSA-like): the file format, read and checked.

A protocol file (``experiments/days/protocols/tabsa.toml``, documented in ``docs/benchmark.md``)
says how a day is drawn: its length and step, the robot's speed, the apartment's sites and
where people stand, the arrival process, and for each task type (transport, fall,
pick_place) how many a day, priority, cost weight, deadline window, stage durations and
whether it can be interrupted; optionally how the day runs on the robot backend.
:func:`load` reads it with the strict reader.  :mod:`experiments.days.draw` draws one day
from a seed; :mod:`experiments.days.daytask` are its task types on the synthetic backend;
:mod:`experiments.days.pipeline` builds either backend's scenario from the one draw.

Two arrival processes: ``uniform`` (ours: a call uniform over ``[0, last_call_s)``, the
deadline a per-type window after it) and ``before_deadline`` (TaBSA's ``my_tasks.py``: the
deadline uniform over the day, the call uniform before it, at least ``call_lead_s`` before).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from experiments.inputs.filekinds import expect
from tasker.support.reader import Table, check_name, suggest
from tasker.support.reader import load as read_table

Pose = tuple[float, ...]
KINDS = ("transport", "fall", "pick_place")
PROCESSES = ("uniform", "before_deadline")
"""Arrival processes: ours (``uniform``) and TaBSA's (``before_deadline``); see the module docstring."""
POSITIONS = ("sites", "rooms")
"""Where a request's person is: at a spot of its site (``sites``), or anywhere free in a room (``rooms``)."""
MAX_REQUESTS = 10_000
"""A protocol whose counts add up to more requests a day than this is refused (a typo such as
``count = 1200000`` would otherwise run for hours; 9 000 take a minute on the synthetic backend)."""
MAX_STEPS = 1_000_000
"""A protocol whose day has more steps than this (``length_s / step_s``) is refused: the loop steps
through the whole day (about 2 million steps take 5 s of one synthetic day, and a robot day far
more), so ``length_s = 1e9`` never ended; the shipped days have 720 to 2 880 steps."""
TOP_KEYS = ("name", "day", "robot", "apartment", "arrivals", "tasks", "robot_backend")
"""The top-level keys and tables of a protocol file."""
Range = tuple[float, float]


@dataclass(frozen=True)
class TaskSpec:
    """One task type of a protocol.  Durations in seconds, speeds in m/s; pairs are uniform ranges.

    ``priority``: the type's static priority; ``priorities`` (when not empty) the values a
    request's priority is drawn from, uniformly (TaBSA: 1, 2 or 3 per transport), and
    ``priority`` is then their highest (a type-level class, as ``alg2`` needs one).
    ``deadline_s``: the deadline's window after the call (``uniform`` arrivals; ``None`` with
    ``before_deadline``).  ``deadline_draws``: TaBSA's pick-and-place is three tasks (pick,
    place, carry) each drawn with its own deadline and call; the whole takes the latest
    deadline and the earliest call.  ``pick_s``/``place_s``: a number, or a range drawn per
    request; ``carry_speed``: the carry's pace, drawn per request (``None``: the robot's).
    ``preemptive``: false for a type that, once started, runs to its end (TaBSA's falls and
    pick-and-place).
    """

    kind: str
    count: int
    priority: int
    weight: float
    deadline_s: Range | None
    person_speed: Range = (0.0, 0.0)
    work_s: Range = (0.0, 0.0)
    greet_s: float = 0.0
    goodbye_s: float = 0.0
    pick_s: float | Range = 0.0
    place_s: float | Range = 0.0
    suspend_s: float = 0.0
    resume_s: float = 0.0
    death_after_s: float | None = None
    priorities: tuple[int, ...] = ()
    preemptive: bool = True
    deadline_draws: int = 1
    carry_speed: Range | None = None


_ADDED: dict[str, Any] = {"priorities": (), "preemptive": True, "deadline_draws": 1, "carry_speed": None,
                          "process": "uniform", "call_lead_s": 0.0, "positions": "sites", "clearance_m": 0.0,
                          "durations": {}}
"""Fields added after days were stored: left out of :meth:`Protocol.digest` while they hold their
default, so that a protocol written before them keeps its digest (and its stored days resume)."""


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
    ``durations``: per action of the folder, the drawn value its stage takes (``$work`` of a
    fall, ``$pick`` and ``$place`` of a pick-and-place; :mod:`experiments.days.robot_work`).
    """

    kind: str
    task: str
    args: dict[str, str]
    object_type: str | None = None
    posture: str | None = None
    renew_after_s: float | None = None
    durations: dict[str, str] = dataclasses.field(default_factory=dict)


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
    process: str = "uniform"
    call_lead_s: float = 0.0
    positions: str = "sites"
    clearance_m: float = 0.0

    @property
    def death_after_s(self) -> float | None:
        return self.tasks["fall"].death_after_s if "fall" in self.tasks else None

    @property
    def non_preemptive(self) -> tuple[str, ...]:
        """The task types that, once started, run to their end (``preemptive = false``)."""
        return tuple(k for k, s in self.tasks.items() if not s.preemptive)

    def digest(self) -> str:
        """A SHA-256 of what its days are drawn and run from: every checked value (not the file's
        comments, layout or place) and, with a robot backend, the bytes of its world file.  Stored
        with each day, so that a resumed run does not mix days of two versions of a protocol."""
        values = _without_defaults(dataclasses.asdict(self))
        for spec in [*values["tasks"].values(), *(values["robot"] or {}).get("tasks", {}).values()]:
            _without_defaults(spec)
        values.pop("source")
        h = hashlib.sha256(json.dumps(values, sort_keys=True, default=str).encode())
        if self.robot is not None:
            h.update(Path(self.robot.world).read_bytes())
        return h.hexdigest()


def _without_defaults(values: dict[str, Any]) -> dict[str, Any]:
    for key, default in _ADDED.items():
        if key in values and values[key] == default:
            del values[key]
    return values


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


def _number_or_range(t: Table, key: str) -> float | Range:
    """A duration: a number, or a range ``[low, high]`` drawn per request."""
    return _range(t, key) if isinstance(t.raw(key), list) else float(t.number(key, min=0))


def _priority(t: Table) -> tuple[int, tuple[int, ...]]:
    """``priority``: an integer, or a list of integers drawn from per request (then the type's is the highest)."""
    value = t.raw("priority")
    if isinstance(value, list):
        if not value or not all(isinstance(v, int) and not isinstance(v, bool) for v in value):
            raise t.error("priority", f"expected an integer or a non-empty list of integers (drawn from per request), "
                                      f"got {value!r}")
        return max(value), tuple(value)
    return int(t.number("priority", integer=True)), ()


def _task(t: Table, kind: str, process: str) -> TaskSpec:
    priority, priorities = _priority(t)
    if process == "uniform":
        deadline: Range | None = _range(t, "deadline_s")
        draws = 1
    else:
        if "deadline_s" in t:
            raise t.error("deadline_s", f"not used with arrivals.process = {process!r}: the deadline is drawn over "
                                        "the day and the call before it (remove it)")
        deadline = None
        draws = int(t.number("deadline_draws", 1, integer=True, min=1, max=10))
    common: dict[str, Any] = dict(
        kind=kind, count=t.number("count", integer=True, min=0), priority=priority, priorities=priorities,
        weight=t.number("weight", min=0), deadline_s=deadline, deadline_draws=draws,
        preemptive=t.boolean("preemptive", True),
    )
    if kind == "transport":
        spec = TaskSpec(**common, person_speed=_range(t, "person_speed", positive=True),
                        greet_s=t.number("greet_s", min=0), goodbye_s=t.number("goodbye_s", min=0),
                        suspend_s=t.number("suspend_s", min=0), resume_s=t.number("resume_s", min=0))
    elif kind == "fall":
        spec = TaskSpec(**common, work_s=_range(t, "work_s"), death_after_s=t.number("death_after_s", min=0))
    else:
        carry = _range(t, "carry_speed", positive=True) if "carry_speed" in t else None
        spec = TaskSpec(**common, pick_s=_number_or_range(t, "pick_s"), place_s=_number_or_range(t, "place_s"),
                        suspend_s=t.number("suspend_s", min=0), resume_s=t.number("resume_s", min=0),
                        carry_speed=carry)
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
                    (arrivals, ("process", "last_call_s", "call_lead_s"))):
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
    positions = apartment.string("positions", "sites", choices=POSITIONS)
    clearance = apartment.number("clearance_m", 0.3 if positions == "rooms" else 0.0, min=0)
    if positions == "sites" and "clearance_m" in apartment:
        raise apartment.error("clearance_m", "only with positions = 'rooms' (how far a drawn position keeps from "
                                             "walls and furniture)")
    apartment.done()
    speed = robot.number("speed", positive=True)
    start_site = robot.name("start_site", sites, "site")
    planning = robot.number("planning_time_s", 0.0, min=0)
    robot.done()
    process = arrivals.string("process", "uniform", choices=PROCESSES)
    if process == "uniform":
        last_call = arrivals.number("last_call_s", length, positive=True, max=length)
        lead = 0.0
    else:
        for key in ("last_call_s",):
            if key in arrivals:
                raise arrivals.error(key, f"not used with process = {process!r}: deadlines are drawn over the whole "
                                          "day and each call before its deadline (remove it)")
        last_call = length
        lead = arrivals.number("call_lead_s", 5.0, min=0)
    arrivals.done()
    tasks: dict[str, TaskSpec] = {}
    for kind in tasks_t.keys():
        if kind not in KINDS:
            raise tasks_t.error(kind, f"unknown task type {kind!r}{suggest(kind, KINDS)} (known: {', '.join(KINDS)})")
        tasks[kind] = _task(tasks_t.table(kind), kind, process)
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
    if positions == "rooms" and backend is None:
        raise apartment.error("positions", "'rooms' draws positions in the rooms of the [robot_backend]'s world: "
                                           "the protocol needs one")
    top.done(also=TOP_KEYS)  # robot_backend is optional: listed among the valid keys even when absent
    return Protocol(name=top.data["name"], source=str(path), start=start, length_s=length, step_s=step,
                    robot_speed=speed, start_site=start_site, planning_time_s=planning, sites=sites,
                    last_call_s=last_call, tasks=tasks, robot=backend, process=process, call_lead_s=lead,
                    positions=positions, clearance_m=clearance)


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
        durations = _durations(tt, kind, tasks[kind], types[name])
        out[kind] = RobotTask(kind, name, args, obj, posture, renew, durations)
        tt.done()
    missing = sorted(set(tasks) - set(out))
    if missing:
        raise tasks_t.error(None, "every task type of [tasks] needs its task folder here; "
                                  f"missing: {', '.join(missing)}")
    tasks_t.done()
    t.done()
    return RobotBackend(world=str(world_file.resolve()), places=places, spots=spots, tasks=out, lead_s=lead,
                        task_exe_rate=exe_rate)


DRAWN = {"fall": ("$work",), "pick_place": ("$pick", "$place"), "transport": ()}
"""What each type draws per request that a robot task's ``durations`` may give a stage."""


def _durations(t: Table, kind: str, spec: TaskSpec, task: Any) -> dict[str, str]:
    """``durations = { ACTION = "$work" }``: actions of the task folder, each given a value the type draws."""
    if "durations" not in t:
        return {}
    d = t.table("durations")
    actions = sorted(getattr(getattr(task, "spec", None), "actions", {}) or {})
    drawn = [v for v in DRAWN[kind] if v != "$pick" or isinstance(spec.pick_s, tuple)]
    drawn = [v for v in drawn if v != "$place" or isinstance(spec.place_s, tuple)]
    out: dict[str, str] = {}
    for action, _ in d.items():
        check_name(d, action, action, actions, "action", f"an action of task folder {task.name!r}")
        value = d.string(action)
        if value not in drawn:
            have = f"one of {', '.join(drawn)}" if drawn else "nothing: this protocol's type draws no duration"
            raise d.error(action, f"expected a value the {kind} requests draw ({have}), got {value!r}")
        out[action] = value
    d.done()
    return out


def _not_standable(spec: Any, xy: Pose) -> str:
    """Why no person can stand at ``xy`` in world ``spec`` (empty if one can): in no room, or
    outside the world's free space (:func:`robot.spec.point_problem`)."""
    from robot.spec import point_problem, room_of

    if room_of(spec, xy[0], xy[1]) is None:
        return f"in no room of world {spec.name!r} (rooms: {', '.join(sorted(spec.rooms))})"
    return point_problem(spec, xy[0], xy[1]) or ""


def _suggest(value: str) -> str:
    return suggest(value, _VARIABLES)
