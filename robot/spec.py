"""World files: an apartment described as data, read and checked into frozen dataclasses.

A world file is TOML (read with the standard library's :mod:`tomllib`).  Every field
is checked here, and a bad one raises :class:`WorldFileError` naming the file and the
field, e.g. ``paper.toml: people.john.pose: expected [x, y, yaw]``.  Nothing
downstream (the 2-D scene, the MuJoCo model, the people) re-checks the data.

Boxes are axis-aligned rectangles ``[xmin, ymin, xmax, ymax]`` in metres; poses are
``[x, y, yaw]`` with yaw in radians.  See ``docs/robot.md`` for the full format.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tasker.errors import TaskerError
from tasker.world import Pose

WORLDS_DIR = Path(__file__).with_name("worlds")
POSTURES = ("standing", "sitting", "fallen")

Box = tuple[float, float, float, float]


class WorldFileError(TaskerError, ValueError):
    """A world file is missing, unreadable or holds a field of the wrong shape."""


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
    bounds: tuple[tuple[float, float], tuple[float, float]]
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


class _Reader:
    """Typed access to a parsed TOML table; every failure names file and field."""

    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, where: str, problem: str) -> WorldFileError:
        return WorldFileError(f"{self.source}: {where}: {problem}")

    def table(self, data: Any, where: str) -> Mapping[str, Any]:
        if not isinstance(data, Mapping):
            raise self.fail(where, "expected a table")
        return data

    def number(self, value: Any, where: str, positive: bool = False) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
            raise self.fail(where, f"expected a number, got {value!r}")
        if positive and value <= 0:
            raise self.fail(where, f"expected a number > 0, got {value!r}")
        return float(value)

    def string(self, value: Any, where: str, choices: tuple[str, ...] | None = None) -> str:
        if not isinstance(value, str) or not value:
            raise self.fail(where, f"expected a non-empty string, got {value!r}")
        if choices is not None and value not in choices:
            raise self.fail(where, f"expected one of {list(choices)}, got {value!r}")
        return value

    def numbers(self, value: Any, where: str, n: int, shape: str) -> tuple[float, ...]:
        if not isinstance(value, list) or len(value) != n:
            raise self.fail(where, f"expected {shape}")
        try:
            return tuple(self.number(v, where) for v in value)
        except WorldFileError:
            raise self.fail(where, f"expected {shape}") from None

    def pose(self, value: Any, where: str) -> Pose:
        x, y, yaw = self.numbers(value, where, 3, "[x, y, yaw]")
        return (x, y, yaw)

    def box(self, value: Any, where: str) -> Box:
        x0, y0, x1, y1 = self.numbers(value, where, 4, "[xmin, ymin, xmax, ymax]")
        if x1 <= x0 or y1 <= y0:
            raise self.fail(where, "expected xmin < xmax and ymin < ymax")
        return (x0, y0, x1, y1)

    def unknown_keys(self, data: Mapping[str, Any], where: str, known: set[str]) -> None:
        extra = sorted(set(data) - known)
        if extra:
            prefix = f"{where}." if where else ""
            raise self.fail(f"{prefix}{extra[0]}", f"unknown field; expected one of {sorted(known)}")


def _person(r: _Reader, name: str, data: Any) -> PersonSpec:
    where = f"people.{name}"
    t = r.table(data, where)
    r.unknown_keys(t, where, {"pose", "posture", "speed", "walk", "events"})
    if "pose" not in t:
        raise r.fail(f"{where}.pose", "missing; expected [x, y, yaw]")
    walk: list[tuple[float, float, float]] = []
    for k, wp in enumerate(t.get("walk", [])):
        wt, wx, wy = r.numbers(wp, f"{where}.walk[{k}]", 3, "[t, x, y]")
        if walk and wt <= walk[-1][0]:
            raise r.fail(f"{where}.walk[{k}]", "waypoint times must increase")
        walk.append((wt, wx, wy))
    events = []
    for k, ev in enumerate(t.get("events", [])):
        if not isinstance(ev, list) or len(ev) != 2:
            raise r.fail(f"{where}.events[{k}]", "expected [t, posture]")
        events.append((r.number(ev[0], f"{where}.events[{k}]"), r.string(ev[1], f"{where}.events[{k}]", POSTURES)))
    return PersonSpec(
        name=name,
        pose=r.pose(t["pose"], f"{where}.pose"),
        posture=r.string(t.get("posture", "standing"), f"{where}.posture", POSTURES),
        speed=r.number(t.get("speed", 0.8), f"{where}.speed", positive=True),
        walk=tuple(walk),
        events=tuple(sorted(events)),
    )


def _robot(r: _Reader, data: Any) -> RobotSpec:
    t = r.table(data, "robot")
    fields = {"max_speed", "max_turn", "max_accel", "max_turn_accel"}
    r.unknown_keys(t, "robot", fields | {"pose"})
    if "pose" not in t:
        raise r.fail("robot.pose", "missing; expected [x, y, yaw]")
    limits = {k: r.number(t[k], f"robot.{k}", positive=True) for k in fields if k in t}
    return RobotSpec(pose=r.pose(t["pose"], "robot.pose"), **limits)


def parse_world(data: Mapping[str, Any], source: str) -> WorldSpec:
    """Check a parsed world table and build a :class:`WorldSpec`; ``source`` names it in errors."""
    r = _Reader(source)
    known = {"name", "description", "bounds", "rooms", "walls", "furniture", "doors", "places",
             "devices", "people", "robot", "facts", "objects"}
    r.unknown_keys(data, "", known)
    for required in ("bounds", "robot"):
        if required not in data:
            raise r.fail(required, "missing")
    b = data["bounds"]
    if not isinstance(b, list) or len(b) != 2:
        raise r.fail("bounds", "expected [[xmin, ymin], [xmax, ymax]]")
    lo = r.numbers(b[0], "bounds", 2, "[[xmin, ymin], [xmax, ymax]]")
    hi = r.numbers(b[1], "bounds", 2, "[[xmin, ymin], [xmax, ymax]]")
    if hi[0] <= lo[0] or hi[1] <= lo[1]:
        raise r.fail("bounds", "expected xmin < xmax and ymin < ymax")
    rooms = {n: r.box(v, f"rooms.{n}") for n, v in r.table(data.get("rooms", {}), "rooms").items()}
    obstacles = []
    walls = data.get("walls", [])
    if not isinstance(walls, list):
        raise r.fail("walls", "expected a list of [xmin, ymin, xmax, ymax]")
    for k, w in enumerate(walls):
        obstacles.append(Obstacle(f"wall{k}", r.box(w, f"walls[{k}]"), 2.5, "wall"))
    for n, v in r.table(data.get("furniture", {}), "furniture").items():
        t = r.table(v, f"furniture.{n}")
        r.unknown_keys(t, f"furniture.{n}", {"box", "height"})
        if "box" not in t:
            raise r.fail(f"furniture.{n}.box", "missing; expected [xmin, ymin, xmax, ymax]")
        h = r.number(t.get("height", 0.8), f"furniture.{n}.height", positive=True)
        obstacles.append(Obstacle(n, r.box(t["box"], f"furniture.{n}.box"), h, "furniture"))
    doors = {}
    for n, v in r.table(data.get("doors", {}), "doors").items():
        t = r.table(v, f"doors.{n}")
        r.unknown_keys(t, f"doors.{n}", {"box", "open"})
        is_open = t.get("open", True)
        if not isinstance(is_open, bool):
            raise r.fail(f"doors.{n}.open", f"expected true or false, got {is_open!r}")
        doors[n] = Door(n, r.box(t.get("box"), f"doors.{n}.box"), is_open)
    places = {n: r.pose(v, f"places.{n}") for n, v in r.table(data.get("places", {}), "places").items()}
    devices = {}
    for n, v in r.table(data.get("devices", {}), "devices").items():
        t = r.table(v, f"devices.{n}")
        r.unknown_keys(t, f"devices.{n}", {"type", "place", "state"})
        place = r.string(t.get("place"), f"devices.{n}.place")
        if place not in places:
            raise r.fail(f"devices.{n}.place", f"unknown place {place!r}; known: {sorted(places)}")
        devices[n] = Device(n, r.string(t.get("type", n), f"devices.{n}.type"), place,
                            r.string(t.get("state", "off"), f"devices.{n}.state"))
    people = {n: _person(r, n, v) for n, v in r.table(data.get("people", {}), "people").items()}
    clash = sorted((set(places) & set(people)) | (set(places) & set(devices)) | (set(people) & set(devices)))
    if clash or "robot" in set(places) | set(people) | set(devices):
        raise r.fail(clash[0] if clash else "robot", "a name is used twice (places, people, devices, 'robot')")
    objects = {n: r.string(v, f"objects.{n}") for n, v in r.table(data.get("objects", {}), "objects").items()}
    taken = set(places) | set(people) | set(devices) | {"robot"}
    if taken & set(objects):
        raise r.fail(f"objects.{sorted(taken & set(objects))[0]}", "a name is used twice (objects and places, "
                     "people, devices or 'robot')")
    facts = []
    for k, f in enumerate(data.get("facts", [])):
        if not isinstance(f, list) or not f or not all(isinstance(a, str) and a for a in f):
            raise r.fail(f"facts[{k}]", "expected a list of non-empty strings")
        facts.append(tuple(f))
    name = data.get("name", Path(source).stem)
    return WorldSpec(
        name=r.string(name, "name"), source=source, bounds=((lo[0], lo[1]), (hi[0], hi[1])), rooms=rooms,
        obstacles=tuple(obstacles), doors=doors, places=places, devices=devices, people=people,
        robot=_robot(r, data["robot"]), facts=tuple(facts), objects=objects,
        description=r.string(data.get("description", "-"), "description"),
    )


def shipped_worlds() -> list[str]:
    """Names of the worlds shipped with the package (``paper``, ``flat``, ...)."""
    return sorted(p.stem for p in WORLDS_DIR.glob("*.toml"))


def load_world(name_or_path: str | Path) -> WorldSpec:
    """Read a shipped world by name (``"paper"``) or a world file by path, and check it."""
    p = Path(name_or_path)
    if p.suffix != ".toml" and not p.exists():
        if str(name_or_path) not in shipped_worlds():
            raise WorldFileError(f"{name_or_path}: no such world; shipped: {', '.join(shipped_worlds())}")
        p = WORLDS_DIR / f"{name_or_path}.toml"
    try:
        data = tomllib.loads(p.read_text(encoding="utf-8"))
    except OSError as e:
        raise WorldFileError(f"{p.name}: cannot read: {e.strerror or e}") from None
    except tomllib.TOMLDecodeError as e:
        raise WorldFileError(f"{p.name}: not valid TOML: {e}") from None
    return parse_world(data, p.name)
