"""World files: an apartment described as data, read and checked into frozen dataclasses.

A world file is TOML, read with the strict reader :mod:`tasker.support.reader`.  Every field
is checked here, and a bad one raises :class:`WorldFileError` naming the file, the line
and the field, e.g. ``paper.toml:61: people.john.pose: expected [x, y, yaw]``; unknown
keys, NaN, binary files, decreasing walk times, names used twice, facts naming nothing,
and places, people or the robot inside a wall or outside the bounds are refused.  Nothing
downstream (the 2-D scene, the MuJoCo model, the people) re-checks the data.

Boxes are axis-aligned rectangles ``[xmin, ymin, xmax, ymax]`` in metres; poses are
``[x, y, yaw]`` with yaw in radians.  See ``docs/robot.md`` for the full format.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tasker.errors import WorldFileError as WorldFileError  # defined there; re-exported here
from tasker.support import reader
from tasker.support.reader import Table, check_name, check_number, check_numbers, suggest
from tasker.world import Pose

WORLDS_DIR = Path(__file__).with_name("worlds")
POSTURES = ("standing", "sitting", "fallen")

Box = tuple[float, float, float, float]
Bounds = tuple[tuple[float, float], tuple[float, float]]


@dataclass(frozen=True, slots=True)
class Obstacle:
    """A wall, a piece of furniture or a door leaf: a box with a height."""

    name: str
    box: Box
    height: float
    kind: str  # "wall", "furniture" or "door"


@dataclass(frozen=True, slots=True)
class Door:
    """A door filling a gap in a wall; a closed door is an obstacle."""

    name: str
    box: Box
    open: bool


@dataclass(frozen=True, slots=True)
class Device:
    """An appliance with a symbolic state (e.g. a cooker that is ``on`` or ``off``)."""

    name: str
    type: str
    place: str
    state: str


@dataclass(frozen=True, slots=True)
class PersonSpec:
    """A person: start pose and posture, scripted walk and posture changes, walking speed.

    ``walk`` holds ``(t, x, y)`` waypoints: the script puts the person at ``(x, y)`` at
    time ``t`` and interpolates in between.  ``events`` holds ``(t, posture)`` changes.
    """

    name: str
    pose: Pose
    posture: str
    speed: float
    walk: tuple[tuple[float, float, float], ...]
    events: tuple[tuple[float, str], ...]


@dataclass(frozen=True, slots=True)
class RobotSpec:
    """The robot's start pose and speed limits (linear m/s, angular rad/s, accelerations)."""

    pose: Pose
    max_speed: float = 0.5
    max_turn: float = 1.0
    max_accel: float = 0.5
    max_turn_accel: float = 2.0


@dataclass(frozen=True, slots=True)
class WorldSpec:
    """A whole apartment: bounds, rooms, obstacles, doors, places, devices, people, facts."""

    name: str
    source: str
    bounds: Bounds
    rooms: Mapping[str, Box]
    obstacles: tuple[Obstacle, ...]
    doors: Mapping[str, Door]
    places: Mapping[str, Pose]
    devices: Mapping[str, Device]
    people: Mapping[str, PersonSpec]
    robot: RobotSpec
    facts: tuple[tuple[str, ...], ...]
    description: str = ""
    objects: Mapping[str, str] = field(default_factory=dict)


DEFAULT_DENSITY = 13.0
"""The roadmap's milestones per square metre of the bounds (:mod:`robot.roadmap` grows them)."""
MAX_AREA = 10_000.0
"""The largest area of a world's bounds, in m²: the roadmap is grown over all of the bounds at
:data:`DEFAULT_DENSITY`, so its time and memory grow with the area, and a typo such as ``1e6``
never ends."""
POSE = "[x, y, yaw]"
BOX = "[xmin, ymin, xmax, ymax]"
PDDL_NAME = re.compile(r"[a-z][a-z0-9_-]*")
"""A name of the world as a PDDL object: a letter, then letters, digits, ``-`` and ``_`` (PDDL's
``<name>``, in the lower case plans give it)."""
TOP_KEYS = ("name", "description", "bounds", "rooms", "walls", "furniture", "doors", "places", "devices",
            "people", "robot", "facts", "objects")


def _box(t: Table, key: str | int, value: Any) -> Box:
    x0, y0, x1, y1 = check_numbers(t, key, value, 4, BOX)
    if x1 <= x0 or y1 <= y0:
        raise t.error(key, f"expected xmin < xmax and ymin < ymax, got {value!r}")
    return (x0, y0, x1, y1)


def _pose(t: Table, key: str | int, value: Any) -> Pose:
    x, y, yaw = check_numbers(t, key, value, 3, POSE)
    return (x, y, yaw)


def _person(name: str, t: Table) -> PersonSpec:
    pose = _pose(t, "pose", t.raw("pose"))
    walk: list[tuple[float, float, float]] = []
    walk_t = t.at("walk", {})  # only to name elements
    for k, wp in enumerate(t.array("walk", [])):
        wt, wx, wy = check_numbers(walk_t, k, wp, 3, "[t, x, y]")
        if wt < 0:
            raise walk_t.error(k, f"expected a time >= 0, got {wt!r}")
        if walk and wt <= walk[-1][0]:
            raise walk_t.error(k, f"waypoint times must increase: {wt!r} after {walk[-1][0]!r}")
        walk.append((wt, wx, wy))
    events = []
    events_t = t.at("events", {})
    for k, ev in enumerate(t.array("events", [])):
        if not isinstance(ev, list) or len(ev) != 2 or isinstance(ev[0], bool) \
                or not isinstance(ev[0], int | float) or not isinstance(ev[1], str):
            raise events_t.error(k, f"expected [t, posture], got {ev!r}")
        at = check_number(events_t, k, ev[0], min=0)
        check_name(events_t, k, ev[1], POSTURES, "posture")
        events.append((float(at), ev[1]))
    person = PersonSpec(name=name, pose=pose, posture=t.string("posture", "standing", choices=POSTURES),
                        speed=t.number("speed", 0.8, positive=True), walk=tuple(walk), events=tuple(sorted(events)))
    t.done()
    return person


def _robot(t: Table) -> RobotSpec:
    limits = {k: t.number(k, positive=True) for k in ("max_speed", "max_turn", "max_accel", "max_turn_accel")
              if k in t}
    robot = RobotSpec(pose=_pose(t, "pose", t.raw("pose")), **limits)
    t.done({"max_speed", "max_turn", "max_accel", "max_turn_accel"})
    return robot


def read_world(top: Table, source: str) -> WorldSpec:
    """Check a world file read by :mod:`tasker.support.reader` and build a :class:`WorldSpec`."""
    if "kind" in top and "bounds" not in top:  # a scenario given where a world is expected
        raise top.error("kind", "this is a scenario file, not a world file (a world has bounds, rooms, walls, "
                                "places, ...; a robot scenario names its world with world = ...)")
    for key in top.keys():
        if key not in TOP_KEYS:
            raise top.error(key, f"unknown key {key!r}{suggest(key, TOP_KEYS)} (valid keys: {', '.join(TOP_KEYS)})")
    b = top.raw("bounds")
    if not isinstance(b, list) or len(b) != 2:
        raise top.error("bounds", f"expected [[xmin, ymin], [xmax, ymax]], got {b!r}")
    lo = check_numbers(top, "bounds", b[0], 2, "[[xmin, ymin], [xmax, ymax]]")
    hi = check_numbers(top, "bounds", b[1], 2, "[[xmin, ymin], [xmax, ymax]]")
    if hi[0] <= lo[0] or hi[1] <= lo[1]:
        raise top.error("bounds", f"expected xmin < xmax and ymin < ymax, got {b!r}")
    area = (hi[0] - lo[0]) * (hi[1] - lo[1])
    if area > MAX_AREA:
        raise top.error("bounds", f"the world covers {area:.4g} m², more than {MAX_AREA:g} m² (e.g. 100 m x 100 m): "
                                  "the robot's roadmap grows milestones over the whole of the bounds "
                                  f"({DEFAULT_DENSITY:g} a m²), "
                                  "which would take minutes and gigabytes; expected bounds around the rooms")
    rooms_t = top.table("rooms", {})
    rooms = {n: _box(rooms_t, n, v) for n, v in rooms_t.items()}
    obstacles = []
    walls_t = top.at("walls", {})
    for k, w in enumerate(top.array("walls", [])):
        obstacles.append(Obstacle(f"wall{k}", _box(walls_t, k, w), 2.5, "wall"))
    for n, t in top.named("furniture"):
        obstacles.append(Obstacle(n, _box(t, "box", t.raw("box")), t.number("height", 0.8, positive=True),
                                  "furniture"))
        t.done()
    doors = {}
    for n, t in top.named("doors"):
        doors[n] = Door(n, _box(t, "box", t.raw("box")), t.boolean("open", True))
        t.done()
    places_t = top.table("places", {})
    places = {n: _pose(places_t, n, v) for n, v in places_t.items()}
    devices = {}
    for n, t in top.named("devices"):
        place = t.name("place", places, "place")
        devices[n] = Device(n, t.string("type", n), place, t.string("state", "off"))
        t.done()
    people = {n: _person(n, t) for n, t in top.named("people")}
    objects_t = top.table("objects", {})
    objects = {n: objects_t.string(n) for n in objects_t.keys()}
    seen: dict[str, str] = {"robot": "robot"}
    for what, names in (("places", places), ("people", people), ("devices", devices), ("doors", doors),
                        ("objects", objects)):
        for n in names:
            if n in seen:
                raise top.at(what, {}).error(n, f"the name {n!r} is used twice ({seen[n]} and {what}); "
                                                "places, people, devices, doors, objects and 'robot' share names")
            bad = name_problem(n)
            if bad:
                raise top.at(what, {}).error(n, bad)
            seen[n] = what
    facts = []
    facts_t = top.at("facts", {})
    for k, f in enumerate(top.array("facts", [])):
        if not isinstance(f, list) or not f or not all(isinstance(a, str) and a for a in f):
            raise facts_t.error(k, f"expected a fact: a list of non-empty strings, got {f!r}")
        for a in f[1:]:
            check_name(facts_t, k, a, seen, "object")
        facts.append(tuple(f))
    spec = WorldSpec(
        name=top.string("name", Path(source).stem), source=source, bounds=((lo[0], lo[1]), (hi[0], hi[1])),
        rooms=rooms, obstacles=tuple(obstacles), doors=doors, places=places, devices=devices, people=people,
        robot=_robot(top.table("robot")), facts=tuple(facts), objects=objects,
        description=top.string("description", "-"),
    )
    top.done(TOP_KEYS)
    _check_geometry(spec, top)
    return spec


def name_problem(name: str) -> str | None:
    """Why ``name`` cannot name an object of the world in a PDDL problem, or ``None``.

    Every place, person, device, door and object is written into the problems the planner
    reads: a space, a ``?``, a dot or a non-ASCII letter would make every planning call of
    the run fail, and a name in upper case would never be the lower-case name a plan gives.
    """
    if name != name.lower():  # the plan would name another object than the world's
        return f"PDDL names ignore case and plans give them in lower case: write {name.lower()!r}"
    if not PDDL_NAME.fullmatch(name):
        return (f"{name!r} is not a PDDL name: expected a letter, then letters, digits, '-' or '_' "
                "(the name is an object of every planning problem)")
    return None


def room_of(spec: WorldSpec, x: float, y: float) -> str | None:
    """The smallest room whose box holds ``(x, y)`` (ties by name), or None."""
    inside = [((b[2] - b[0]) * (b[3] - b[1]), n) for n, b in spec.rooms.items()
              if b[0] <= x <= b[2] and b[1] <= y <= b[3]]
    return min(inside)[1] if inside else None


def in_bounds(bounds: Bounds, x: float, y: float, radius: float = 0.0) -> bool:
    """Is a disc of ``radius`` at ``(x, y)`` inside ``bounds`` (touching them allowed)?"""
    (x0, y0), (x1, y1) = bounds
    return x0 + radius <= x <= x1 - radius and y0 + radius <= y <= y1 - radius


def disc_clear(boxes: Sequence[Box], bounds: Bounds, radius: float, x: float, y: float) -> bool:
    """Is a disc of ``radius`` at ``(x, y)`` inside ``bounds`` and at least ``radius`` from every
    box (touching allowed)?  **The** rule for where the robot may stand among walls and furniture:
    :func:`robot_problem` checks a world file's places with it, and the 2-D scene's
    ``static_free`` answers OMPL's validity checker with it (plain Python: called millions of
    times).  It lives here, not in the scene, so that the scene depends on the world file's
    module and never the reverse."""
    if not in_bounds(bounds, x, y, radius):
        return False
    r2 = radius * radius
    for x0, y0, x1, y1 in boxes:
        dx = x0 - x if x < x0 else (x - x1 if x > x1 else 0.0)
        dy = y0 - y if y < y0 else (y - y1 if y > y1 else 0.0)
        if dx * dx + dy * dy < r2:
            return False
    return True


def point_problem(spec: WorldSpec, x: float, y: float) -> str | None:
    """Why ``(x, y)`` is not a point in the world's free space (outside the bounds, inside a
    wall or furniture), or ``None``."""
    if not in_bounds(spec.bounds, x, y):
        (x0, y0), (x1, y1) = spec.bounds
        return f"outside the world's bounds [[{x0:g}, {y0:g}], [{x1:g}, {y1:g}]]"
    for o in spec.obstacles:
        if o.box[0] < x < o.box[2] and o.box[1] < y < o.box[3]:
            return f"inside {o.kind} {o.name!r} {list(o.box)}"
    return None


def check_point(spec: WorldSpec, t: Table, key: str | int, x: float, y: float) -> None:
    """``t.error(key)`` unless ``(x, y)`` is in the world's free space."""
    bad = point_problem(spec, x, y)
    if bad:
        raise t.error(key, f"({x:g}, {y:g}) is {bad}; expected a point in free space")


def _check_geometry(spec: WorldSpec, top: Table) -> None:
    """Places, people, walks inside the bounds and not inside a wall or furniture; the robot, at its pose
    and at every place, in free space."""
    def check(t: Table, key: str | int, x: float, y: float) -> None:
        check_point(spec, t, key, x, y)

    (bx0, by0), (bx1, by1) = spec.bounds
    for what, boxes in (("rooms", spec.rooms), ("doors", {n: d.box for n, d in spec.doors.items()}),
                        ("furniture", {o.name: o.box for o in spec.obstacles if o.kind == "furniture"})):
        t = top.table(what, {})
        for n, (x0, y0, x1, y1) in boxes.items():
            if x0 < bx0 or y0 < by0 or x1 > bx1 or y1 > by1:
                key: str | int = n
                owner = t
                if what != "rooms":
                    owner, key = t.at(n, t.data[n]), "box"
                raise owner.error(key, f"{[x0, y0, x1, y1]} reaches outside the world's bounds "
                                       f"[[{bx0:g}, {by0:g}], [{bx1:g}, {by1:g}]]")
    places_t = top.table("places", {})
    for n, (x, y, _) in spec.places.items():
        check(places_t, n, x, y)
    people_t = top.table("people", {})
    for n, p in spec.people.items():
        pt = people_t.at(n, people_t.data[n])
        check(pt, "pose", p.pose[0], p.pose[1])
        for k, (_, x, y) in enumerate(p.walk):
            check(pt.at("walk", {}), k, x, y)
    robot_t = top.table("robot")
    x, y, _ = spec.robot.pose
    check(robot_t, "pose", x, y)
    from robot.tiago import robot_dimensions

    radius = robot_dimensions()[2]
    bad = robot_problem(spec, x, y, radius)
    if bad:
        raise robot_t.error("pose", f"{bad}; expected free space")
    for n, (x, y, _) in spec.places.items():  # the robot drives to every place: a goal it never reaches
        bad = robot_problem(spec, x, y, radius)
        if bad:
            raise places_t.error(n, f"{bad}, and a place is where the robot stands (it could never get there); "
                                    "expected a point with room for the robot")


def robot_problem(spec: WorldSpec, x: float, y: float, radius: float | None = None) -> str | None:
    """Why the robot cannot stand at ``(x, y)`` (its disc overlaps a wall, furniture or the bounds), or
    ``None``; ``radius``: the robot's planning radius (looked up when not given)."""
    if radius is None:
        from robot.tiago import robot_dimensions

        radius = robot_dimensions()[2]
    if disc_clear([o.box for o in spec.obstacles], spec.bounds, radius, x, y):
        return None
    return (f"the robot (radius {radius:g} m) at ({x:g}, {y:g}) overlaps a wall, furniture or the "
            "world's bounds")


def parse_world(data: Mapping[str, Any], source: str) -> WorldSpec:
    """Check a parsed world table and build a :class:`WorldSpec`; ``source`` names it in errors."""
    return read_world(Table(source, dict(data), (), None, WorldFileError), source)


def shipped_worlds() -> list[str]:
    """Names of the worlds shipped with the package (``paper``, ``flat``, ...)."""
    return sorted(p.stem for p in WORLDS_DIR.glob("*.toml"))


def load_world(name_or_path: str | Path) -> WorldSpec:
    """Read a shipped world by name (``"paper"``) or a world file by path, and check it."""
    p = world_path(name_or_path)
    return read_world(reader.load(p, WorldFileError), str(p))


def world_path(name_or_path: str | Path) -> Path:
    """The file of a shipped world name (``"paper"``) or of a path; an unknown name lists the shipped ones."""
    p = Path(name_or_path)
    if p.suffix != ".toml" and not p.exists():
        shipped = shipped_worlds()
        if str(name_or_path) not in shipped:
            did = suggest(str(name_or_path), shipped)
            raise WorldFileError(str(name_or_path), f"no such world file, and not a shipped world{did} "
                                                    f"(shipped: {', '.join(shipped)})")
        p = WORLDS_DIR / f"{name_or_path}.toml"
    return p
