"""The simulated robot and its world: one object that is both the TaskER ``World`` and ``CoreAgent``.

:class:`Simulation` owns the MuJoCo apartment, the people, the 2-D scene, the
planner and the symbolic state, and steps them together on the simulated clock:

* :meth:`advance` (``World``) runs fixed control ticks (``CONTROL_DT``), each one
  moving the people, updating the scene, asking the running skill for a base command
  and stepping MuJoCo ``CONTROL_DT / TIMESTEP`` times.  Same inputs, same trajectory.
* :meth:`begin` / :meth:`poll` / :meth:`stop` (``CoreAgent``) run the skills of
  :mod:`robot.skills`; :meth:`poll` advances the world to ``now`` first, so the
  simulation also works when nobody else calls :meth:`advance`.

The symbolic state starts from the world file's facts, ``("at", device, place)`` and
``("at", "robot", place)`` when the robot starts on a place; skills change it through
their stage's ``add``/``delete`` lists.  The world keeps **one** state: a fact a task
folder *binds* to physical state (:class:`tasker.meaning.Binding`, given with
:meth:`Simulation.bind`) — a device's state, a door open, an object held, a person
following or waiting — is never stored: :meth:`Simulation.apply` changes the device,
the door, the grip or the person, and :meth:`Simulation.snapshot` derives the fact from
it.  The world names no task's predicate but the facts it derives (:data:`DERIVED`):
``("clear", place)`` while no movable object rests at a place.  Device states are reported
as ``("state", device, value)``, postures as ``("posture", person, posture)``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from robot.control import STOP
from robot.drive import DriveLimits
from robot.estimator import APPROACH, MotionEstimator
from robot.mjworld import TIMESTEP, MjApartment
from robot.motion import BasePlanner, open_planner
from robot.people import People, Person
from robot.places import Places
from robot.recording import PersonState, Recorder
from robot.scene import PERSON_RADIUS, Scene, point_box_distance, segments_clear
from robot.skills import SKILLS, Skill
from robot.spec import WorldSpec, load_world, room_of
from robot.tiago import robot_dimensions
from tasker.meaning import Binding
from tasker.protocols import RUNNING, SkillState, SkillStatus, failed
from tasker.stage import Stage
from tasker.world import Fact, Pose, WorldState

CONTROL_DT = 0.02  # seconds: the base controller and the people run at 50 Hz
STEPS = round(CONTROL_DT / TIMESTEP)  # MuJoCo steps a control tick
AT_TOLERANCE = 0.3  # metres: the robot starts "at" a place this close
TOGETHER = 1.5  # metres: a person this close to the robot is symbolically at the robot's place
WAIT_MARGIN = 0.05  # metres beyond a standing person's radius and the robot's width (Simulation._aside_spot)
ASIDE_STEP, ASIDE_MAX, ASIDE_DIRECTIONS = 0.1, 3.0, 16  # where a person stepping aside looks for a spot
CLEAR = "clear"
DERIVED = frozenset({CLEAR})
"""Predicates the world derives and never stores: ``("clear", place)`` holds while no movable object
(of the world file or the scenario) is ``at`` the place; an effect on one is ignored (:meth:`Simulation.apply`)."""
DOOR_BETWEEN = "door_between"
"""A world file's fact ``(door_between door a b)``: the route from place ``a`` to place ``b`` passes the door."""
WORLD_PREDICATES = DERIVED | {DOOR_BETWEEN}
"""Predicates the world speaks of itself, which a task domain may read (the contract, like ``at``)."""


class Simulation:
    """TIAGo in a MuJoCo apartment: ``tasker.protocols.World`` and ``CoreAgent`` in one.

    ``rate_hz`` is the rate the loop should call :meth:`advance` at; physics and
    control run at their own fixed rates underneath.
    """

    def __init__(self, world: str | Path | WorldSpec, seed: int = 1, rate_hz: float = 10.0,
                 milestones: int | None = None) -> None:
        self.spec = world if isinstance(world, WorldSpec) else load_world(world)
        self.seed = seed
        self.rate_hz = float(rate_hz)
        _, _, radius = robot_dimensions()
        self.scene = Scene(self.spec, radius)
        self.planner = BasePlanner(self.spec, self.scene, seed=seed, milestones=milestones)
        self.limits = DriveLimits.of(self.spec.robot)
        self._open = open_planner(self.spec, radius, seed, milestones)
        self.motion = MotionEstimator(self.planner, self.limits, self._open)
        self.people = People(self.spec.people.values(), route=self.person_route)
        self.mj = MjApartment(self.spec)
        self.time = 0.0
        self._objects = self._object_types()
        # the last snapshot's facts, under the facts_key they were made for (snapshot)
        self._snapped: tuple[tuple[Any, ...], frozenset[Fact], tuple[tuple[str, Pose | None], ...]] | None = None
        # the last facts_key, under what it was made from: (version, people's revision, robot x, y)
        self._key: tuple[tuple[int, int, float, float], tuple[Any, ...]] | None = None
        self.facts: set[Fact] = set(self.spec.facts)
        # devices are where their place is
        self.facts |= {("at", d.name, d.place) for d in self.spec.devices.values()}
        # physical state: the one copy; bound facts are derived from it (see bind)
        self.device_state: dict[str, str] = {n: d.state for n, d in sorted(self.spec.devices.items())}
        self.door_open: dict[str, bool] = {n: bool(d.open) for n, d in sorted(self.spec.doors.items())}
        self.held: set[str] = set()
        self.bindings: tuple[Binding, ...] = ()
        self.version = 0  # bumped whenever the symbolic or bound state changes
        x, y, _ = self.spec.robot.pose
        for name, (px, py, _) in sorted(self.spec.places.items()):
            if math.hypot(px - x, py - y) < AT_TOLERANCE and not any(f[:2] == ("at", "robot") for f in self.facts):
                self.facts.add(("at", "robot", name))
        self.skill: Skill | None = None
        self._owner: tuple[str, Stage] | None = None
        self._applied = False
        self.recording = Recorder(self.spec.name)
        self.trajectory: list[tuple[float, float, float, float]] = []  # (t, x, y, yaw) at RECORD_HZ
        self._ticks = 0
        self._last_cmd = STOP
        self._blocker: Person | None = None  # the person who kept the last fast-forward from happening
        self._synced: dict[str, tuple[float, float, float, str]] = {}
        self.places = Places(self.spec, self.scene)
        self._fallen: tuple[str, ...] = ()  # who lay fallen at the last look (Simulation._give_room)
        self._door_changes = self._doors_seen = 0  # doors opened or closed, in all and at the last look
        self.physics_ticks = 0  # control ticks that stepped MuJoCo (the rest: robot at rest, nothing to do)
        self._people_seen = -1  # the scene's version after the last _sync_people
        self._sync_people()
        self._record()

    # ---- World -----------------------------------------------------------------------
    def robot_pose(self) -> Pose:
        return self.mj.pose()

    def objects(self) -> dict[str, str]:
        return dict(self._objects)

    def _object_types(self) -> dict[str, str]:
        """Every object's type: fixed by the world file for the whole run."""
        out = {"robot": "robot"}
        out |= {n: "place" for n in self.spec.places}
        out |= {n: "person" for n in self.spec.people}
        out |= {n: d.type for n, d in self.spec.devices.items()}
        out |= {n: "door" for n in self.spec.doors}
        out |= dict(self.spec.objects)
        return out

    def person_route(self, a: tuple[float, float], b: tuple[float, float]) -> tuple[tuple[float, float], ...]:
        """How a person walks from ``a`` to ``b`` (:data:`robot.people.Route`): straight when
        that line crosses no wall and no furniture; otherwise along the base's shortest way
        with every door open (people open doors; where the base fits, a person fits),
        between the nearest points the base may stand on; straight when there is no such way.
        People in the way are not considered: they step round each other."""
        if segments_clear(np.array([a], float), np.array([b], float), self.scene.static, 1e-9)[0]:
            return (a, b)
        s, g = self._open.snap((round(a[0], 4), round(a[1], 4))), self._open.snap((round(b[0], 4), round(b[1], 4)))
        path = None if s is None or g is None else self._open.plan_ignoring_people(s, g)
        if path is None:
            return (a, b)
        out = [a]
        for p in (*path, b):
            if math.hypot(p[0] - out[-1][0], p[1] - out[-1][1]) > 1e-9:
                out.append((float(p[0]), float(p[1])))
        if len(out) == 1:
            out.append(b)
        out[-1] = b
        return tuple(out)

    def _sync_people(self) -> None:
        """The scene and MuJoCo follow the people: only those touched since the last look
        (:attr:`robot.people.Person.touched`: stepped, or changed from outside), and of them
        only who moved."""
        for p in self.people:
            if not p.touched:
                continue
            p.touched = False
            self.scene.set_stepping_to(p.name, p.stepping_to())
            state = (p.x, p.y, p.yaw, p.posture)
            if self._synced.get(p.name) != state:
                self._synced[p.name] = state
                self.scene.set_person(p.name, p.x, p.y, p.posture)
                self.mj.set_person(p.name, p.x, p.y, p.yaw, p.posture)
        self._people_seen = self.scene.version

    def _people_react(self) -> None:
        """:meth:`_give_room`, then :meth:`_sync_people` — skipped when no person was touched
        and the scene (people, doors) is as it was after the last time: both would change
        nothing then."""
        if self.scene.version == self._people_seen and not any(p.touched for p in self.people):
            return
        self._give_room()
        self._sync_people()

    def _still_until(self, p: Person) -> float:
        """Until when person ``p`` certainly stays as they are (``self.time``: they may move now)."""
        events = p.spec.events
        nxt = events[p._event][0] if p._event < len(events) else math.inf
        if p.following or p.stepping_aside():
            return self.time
        if p.giving_room is not None and p.giving_room[1] is not None:
            return nxt  # standing clear of someone fallen until a posture changes
        if p.posture == "fallen" or p.waiting or not p.walk:
            return nxt
        walk = p.walk
        if self.time < walk[0][0]:
            return min(nxt, walk[0][0])
        if self.time >= walk[-1][0] and math.hypot(p.x - walk[-1][1], p.y - walk[-1][2]) <= 1e-9 and not p._detour:
            return nxt
        return self.time

    def _fast_forward(self, now: float) -> bool:
        """Skip the control ticks in which nothing can change: no command, the base at rest,
        every person still, the running skill only waiting for its time.  Such ticks would
        leave the state exactly as it is, so skipping them changes no result; samples due
        meanwhile are recorded."""
        if self._last_cmd != STOP or not self.mj.at_rest():
            return False
        # whoever kept the last look from skipping usually keeps this one too: asked first (a
        # pure question, so the order changes nothing but how soon the answer is known)
        if self._blocker is not None and self._still_until(self._blocker) <= self.time:
            return False
        horizon = min(now + 1e-9, self.skill.quiet_until() if self.skill is not None else math.inf)
        for p in self.people:
            horizon = min(horizon, self._still_until(p))
            if horizon <= self.time:
                self._blocker = p
                return False
        if not math.isfinite(horizon):
            return False
        # ticks k = 1..n with time (ticks + k) * CONTROL_DT strictly before the horizon
        n = math.ceil((horizon - 1e-9) / CONTROL_DT - 1e-9) - 1 - self._ticks
        if n < 2:
            return False
        for p in self.people:
            if not p.following:
                p._trail = []  # what Person.step does for someone not following
        end = self._ticks + n
        while self._ticks < end:
            due = math.ceil(self.recording.next_time() / CONTROL_DT - 1e-6)
            self._ticks = min(end, max(due, self._ticks + 1))
            self.time = round(self._ticks * CONTROL_DT, 9)
            if self.recording.due(self.time):
                self._record()
        return True

    def _tick(self) -> None:
        self._ticks += 1
        t = round(self._ticks * CONTROL_DT, 9)
        x, y, _ = self.mj.pose()
        self.people.step(t, CONTROL_DT, (x, y))
        self._people_react()
        cmd = self.skill.control(t, CONTROL_DT) if self.skill is not None else STOP
        self._last_cmd = cmd
        self.mj.command(cmd.v, cmd.w)
        # People are mocap bodies that touch nothing, so with no command and the base at
        # rest a physics step changes nothing worth its MuJoCo steps: skip it
        if cmd != STOP or not self.mj.at_rest():
            self.mj.step(STEPS)
            self.physics_ticks += 1
        self.time = t
        if self.recording.due(t):
            self._record()

    def _record(self) -> None:
        pose = self.mj.pose()
        self.recording.record(self.time, pose, [PersonState(p.name, p.x, p.y, p.yaw, p.posture) for p in self.people])
        self.trajectory.append((self.time, *pose))

    def write_trajectory(self, path: str | Path) -> Path:
        """Write what was recorded (``trajectory.jsonl``, see :mod:`robot.recording`)."""
        return self.recording.write(path)

    def advance(self, now: float) -> None:
        """Step control and physics in fixed ticks up to simulated time ``now``."""
        self._people_react()  # a posture set from outside since the last tick
        while self.time + CONTROL_DT <= now + 1e-9:
            if not self._fast_forward(now):
                self._tick()

    def set_door(self, name: str, is_open: bool) -> None:
        """Open or close a door: the scene (and so every cached estimate) and MuJoCo follow."""
        self.door_open[name] = bool(is_open)
        self._door_changes += 1
        self.version += 1
        self.scene.set_door(name, is_open)
        self.mj.set_door(name, is_open)

    def set_device(self, name: str, state: str) -> None:
        """Switch a device (``"on"``, ``"off"``, ...): the one place its state is kept."""
        if name not in self.device_state:
            raise KeyError(f"no device {name!r}; known: {sorted(self.device_state)}")
        self.device_state[name] = str(state)
        self.version += 1

    # ---- bindings: facts that are physical state -------------------------------------
    def bind(self, bindings: Iterable[Binding]) -> None:
        """Say which facts are physical state (the task folders' ``[[bindings]]``).

        Facts of the world file that a binding covers move into the physical state."""
        self.bindings = tuple(dict.fromkeys(bindings))
        stored = sorted(f for f in self.facts if self._binding(f) is not None)
        self.facts -= set(stored)
        for f in stored:
            self._set_bound(f, True)
        self.version += 1

    def _binding(self, fact: Fact) -> tuple[Binding, str] | None:
        """The binding that covers a ground fact, with the physical thing it is about."""
        kinds: dict[str, set[str]] = {"device": set(self.device_state), "door": set(self.door_open),
                                      "held": set(self.spec.objects), "follower": set(self.people.by_name),
                                      "waiting": set(self.people.by_name)}
        for b in self.bindings:
            obj = b.object_of(fact)
            if obj is not None and obj in kinds[b.kind] and (not b.types or self._type(obj) in b.types):
                return b, obj
        return None

    def doors_closed_by(self, stage: Stage) -> tuple[str, ...]:
        """The doors a stage closes when it succeeds: its ``delete`` facts bound to a door."""
        out = []
        for f in stage.data.get("delete", []):
            hit = self._binding(tuple(str(x) for x in f))
            if hit is not None and hit[0].kind == "door" and self.door_open.get(hit[1]):
                out.append(hit[1])
        return tuple(dict.fromkeys(out))

    def _type(self, name: str) -> str:
        return self._objects.get(name, "")

    def _set_bound(self, fact: Fact, value: bool) -> bool:
        hit = self._binding(fact)
        if hit is None:
            return False
        b, obj = hit
        if b.kind == "device":
            self.set_device(obj, b.state if value else b.otherwise)
        elif b.kind == "door":
            self.set_door(obj, value)
        elif b.kind == "held":
            (self.held.add if value else self.held.discard)(obj)
        elif b.kind == "follower":
            self.people[obj].following = value
            self.scene.set_making_way(obj, value)
        else:
            person = self.people[obj]
            person.waiting = value
            person.aside = self._aside_spot(person) if value else None
            self.scene.set_stepping_to(person.name, person.stepping_to())  # estimates see it at once
        return True

    def _room_clear(self) -> float:
        """How far a standing bystander keeps from a fallen person's centre: the near approach
        ring (``robot.estimator.APPROACH``), the robot on it (its radius), a lane as wide as
        the robot beside that, their own radius and ``WAIT_MARGIN``: every pose of the ring the
        robot helps from stays free of them, and so does a way in to it."""
        return APPROACH + 3 * self.scene.radius + PERSON_RADIUS["standing"] + WAIT_MARGIN

    def _give_room(self) -> None:
        """Bystanders make room for help: a standing person who is not following the robot and
        who comes within :meth:`_room_clear` of someone fallen they can see (no wall or closed
        door between) steps to the nearest spot of their own room clear of every fallen person
        they see and of the doorways (:meth:`_aside_spot`; none within ``ASIDE_MAX``: they carry
        on) and stays there while that person is down; then they return to what they were
        doing.  Whenever someone falls or gets up, everyone looks again; otherwise only those
        touched since the last look (:attr:`robot.people.Person.touched`) can see anything new,
        unless a door opened or closed."""
        fallen = tuple(p.name for p in self.people if p.posture == "fallen")
        everyone = fallen != self._fallen or self._doors_seen != self._door_changes
        self._doors_seen = self._door_changes
        if fallen != self._fallen:
            self._fallen = fallen
            for p in self.people:
                p.giving_room = None
        if not fallen:
            return
        near = self._room_clear()
        for p in self.people:
            if not (everyone or p.touched):
                continue  # not moved, nothing about them changed: what they saw last time stands
            if p.giving_room is not None:
                if p.following or p.posture != "standing":
                    p.giving_room = None
                continue
            if p.posture != "standing" or p.following:
                continue
            for name in fallen:
                f = self.people[name]
                if math.hypot(p.x - f.x, p.y - f.y) < near and self.scene.sees((p.x, p.y), (f.x, f.y)):
                    p.giving_room = (name, self._aside_spot(p))
                    break

    def _aside_spot(self, p: Person) -> tuple[float, float] | None:
        """Where standing person ``p`` steps to be out of the robot's way: the nearest spot of
        their own room (rings of ``ASIDE_STEP`` metres, ``ASIDE_DIRECTIONS`` directions, east
        first) at least ``clear`` metres — their radius, the robot's width and ``WAIT_MARGIN``
        — from every door's leaf, at least :meth:`_room_clear` from every fallen person they
        see, free of walls and furniture, and reached in a straight line that crosses neither.
        None when they stand clear already, are not standing (nobody sitting or lying moves
        aside), or no such spot lies within ``ASIDE_MAX`` metres."""
        if p.posture != "standing":
            return None
        clear = PERSON_RADIUS["standing"] + 2 * self.scene.radius + WAIT_MARGIN
        leaves = np.array([d.box for _, d in sorted(self.spec.doors.items())], dtype=float).reshape(-1, 4)
        seen = [(f.x, f.y) for f in self.people if f.posture == "fallen" and self.scene.sees((p.x, p.y), (f.x, f.y))]
        fallen = np.array(seen, dtype=float).reshape(-1, 2)
        near = self._room_clear()

        def clear_here(x: float, y: float) -> bool:
            if len(leaves) and point_box_distance(np.array([x]), np.array([y]), leaves).min() < clear:
                return False
            return not len(fallen) or bool(np.hypot(fallen[:, 0] - x, fallen[:, 1] - y).min() >= near)

        if clear_here(p.x, p.y):
            return None
        room = room_of(self.spec, p.x, p.y)
        here = np.array([[p.x, p.y]])
        door = next((pose[:2] for _, pose in sorted(self.spec.places.items())
                     if room_of(self.spec, pose[0], pose[1]) == room), None)
        for ring in range(1, round(ASIDE_MAX / ASIDE_STEP) + 1):
            r = ring * ASIDE_STEP
            for k in range(ASIDE_DIRECTIONS):
                a = 2 * math.pi * k / ASIDE_DIRECTIONS
                x, y = round(p.x + r * math.cos(a), 3), round(p.y + r * math.sin(a), 3)
                if (room_of(self.spec, x, y) == room and clear_here(x, y) and self.scene.static_free(x, y)
                        and segments_clear(here, np.array([[x, y]]), self.scene.static, 1e-9)[0]
                        and self._robot_reaches(p.name, door, (x, y))):
                    return (x, y)
        return None

    def _robot_reaches(self, name: str, place: tuple[float, float] | None, spot: tuple[float, float]) -> bool:
        """Can the robot drive from the room's place to ``spot`` as the scene stands, less person
        ``name``?  A person who steps aside must not step into a pocket the robot cannot
        reach (a dead end behind the one they make room for): they could not be helped or
        guided there.  True when the room has no place to drive from."""
        if place is None:
            return True
        was = name in self.scene.making_way
        self.scene.set_making_way(name, True)
        try:
            return self.planner.plan((float(place[0]), float(place[1])), spot) is not None
        finally:
            self.scene.set_making_way(name, was)

    def _bound_facts(self) -> set[Fact]:
        out: set[Fact] = set()
        objects = self._objects
        for b in self.bindings:
            if b.kind == "device":
                things = [n for n, v in self.device_state.items() if v == b.state]
            elif b.kind == "door":
                things = [n for n, v in self.door_open.items() if v]
            elif b.kind == "held":
                things = sorted(self.held)
            elif b.kind == "follower":
                things = [p.name for p in self.people if p.following]
            else:
                things = [p.name for p in self.people if p.waiting]
            out |= {b.ground(n, "robot") for n in things if not b.types or objects.get(n) in b.types}
        return out

    def snapshot(self) -> WorldState:
        """The world as task hooks see it: symbolic facts plus the facts read off the physics.

        Symbolic places are read off the physics, never kept from a skill's effects (an
        interrupted navigation leaves the robot between places; people walk by
        themselves, follow the robot, or stay): the robot is at its nearest named place;
        a person who follows the robot or stands within ``TOGETHER`` metres of it is at
        the robot's place, anyone else at :meth:`person_place`.  A fallen person is
        ``("fallen", name)``.
        """
        poses: dict[str, Pose] = {"robot": self.robot_pose()}
        poses |= {p.name: p.pose for p in self.people}
        poses |= self.spec.places
        key = self.facts_key()
        if self._snapped is None or self._snapped[0] != key:  # facts change only with their key
            self._snapped = (key, *self._facts_now(poses["robot"]))
        _, facts, held_or_placed = self._snapped
        for name, place in held_or_placed:
            poses[name] = poses["robot"] if place is None else place
        return WorldState(facts, poses, dict(self._objects), self.time)

    def _facts_now(self, robot: Pose) -> tuple[frozenset[Fact], tuple[tuple[str, Pose | None], ...]]:
        """The facts of :meth:`snapshot` and where each movable object is posed (None: with
        the robot, which holds it), computed afresh."""
        names = set(self.spec.people) | {"robot"}
        facts = {f for f in self.facts if not (f[0] == "at" and len(f) == 3 and f[1] in names)}
        rx, ry, _ = robot
        robot_place = self.nearest_place(rx, ry)
        facts.add(("at", "robot", robot_place))
        for p in self.people:
            with_robot = p.following or math.hypot(p.x - rx, p.y - ry) <= TOGETHER
            facts.add(("at", p.name, robot_place if with_robot else self.person_place(p.x, p.y)))
            if p.posture == "fallen":
                facts.add(("fallen", p.name))
        facts |= {("state", n, v) for n, v in self.device_state.items()}
        facts |= self._bound_facts()
        occupied = {f[2] for f in facts if f[0] == "at" and len(f) == 3 and f[1] in self.spec.objects}
        facts |= {(CLEAR, p) for p in self.spec.places if p not in occupied}
        objects: list[tuple[str, Pose | None]] = []
        for name in sorted(self.spec.objects):  # an object is posed at its place, or with the robot holding it
            place = next((f[2] for f in facts if f[0] == "at" and len(f) == 3 and f[1] == name), None)
            if name in self.held:
                objects.append((name, None))
            elif place is not None and place in self.spec.places:
                objects.append((name, self.spec.places[place]))
        return frozenset(facts | self.people.facts()), tuple(objects)

    def facts_key(self) -> tuple[Any, ...]:
        """What the facts of :meth:`snapshot` are made of, cheaply: equal keys, equal facts.

        The symbolic state, devices, doors, what is held and who follows or waits all bump
        :attr:`version` when they change; the rest is the place the robot is at, and for
        each person their posture and the place they are at (the robot's, when they follow
        it or stand within ``TOGETHER`` of it) — exactly what :meth:`_facts_now` reads of
        poses.  A monitor that asks only when this changes misses nothing, and skips the
        ticks in which nobody changed place (the robot driving across a room, say)."""
        rx, ry, _ = self.mj.pose()
        made = (self.version, self.people.revision.n, rx, ry)  # nothing else moves anyone: equal, the same key
        if self._key is not None and self._key[0] == made:
            return self._key[1]
        here = self.nearest_place(rx, ry)
        hypot = math.hypot
        key = (self.version, here, tuple(
            (p.posture, here if p.following or hypot(p.x - rx, p.y - ry) <= TOGETHER else self.person_place(p.x, p.y))
            for p in self.people))
        self._key = (made, key)
        return key

    def person_place(self, x: float, y: float) -> str:
        """Where a person is, symbolically (:meth:`robot.places.Places.person_place`)."""
        return self.places.person_place(x, y)

    def nearest_place(self, x: float, y: float) -> str:
        """Where the robot (or anything) at ``(x, y)`` is (:meth:`robot.places.Places.nearest_place`)."""
        return self.places.nearest_place(x, y)

    def room_of(self, x: float, y: float) -> str | None:
        """The smallest room whose box holds ``(x, y)`` (:meth:`robot.places.Places.room_of`)."""
        return self.places.room_of(x, y)

    def place_of(self, x: float, y: float, spots: Mapping[str, Pose]) -> str:
        """The nearest of ``spots`` not behind a wall (:meth:`robot.places.Places.place_of`)."""
        return self.places.place_of(x, y, spots)

    def move(self, thing: str, place: str) -> bool:
        """Someone moved ``thing`` to ``place`` (not while the robot holds it): it rests at ``place`` now,
        and its relations to other things — every stored fact of two or more arguments naming it, such
        as where it stood or what it stood on (``("on_cooker", "pan", "cooker")``) — are gone; its own
        properties (one-argument facts: ``("cooked", "pan")``) stay.  False if it was held."""
        if thing in self.held:
            return False
        self.apply(delete=[f for f in self.facts if len(f) >= 3 and thing in f[1:]], add=[("at", thing, place)])
        return True

    def apply(self, add: Iterable[Iterable[str]] = (), delete: Iterable[Iterable[str]] = ()) -> None:
        """Change the symbolic state: ``delete`` first, then ``add`` (lists of ground facts)."""
        removed: list[Fact] = [tuple(f) for f in delete]
        added: list[Fact] = [tuple(f) for f in add]
        for fact, value in [(f, False) for f in removed] + [(f, True) for f in added]:
            if fact and fact[0] in DERIVED:  # the world derives it from where things are
                continue
            if not self._set_bound(fact, value):  # bound facts change the physical state, not a copy
                (self.facts.add if value else self.facts.discard)(fact)
        self.version += 1

    # ---- CoreAgent -------------------------------------------------------------------
    def begin(self, agent: str, stage: Stage, now: float) -> None:
        self.advance(now)
        kind = SKILLS.get(stage.skill)
        self._owner = (agent, stage)
        self._applied = False
        if kind is None:
            self.skill = Skill(self, stage, now)
            self.skill.result = failed(f"unknown skill {stage.skill!r}; known: {', '.join(sorted(SKILLS))}")
            return
        self.skill = kind(self, stage, now)

    def poll(self, agent: str, stage: Stage, now: float) -> SkillStatus:
        self.advance(now)
        if self.skill is None or self._owner != (agent, stage):
            return failed(f"stage {stage.label} of {agent} was not begun")
        status = self.skill.result
        if status.state is SkillState.SUCCEEDED and not self._applied:
            self._applied = True
            self.apply(stage.data.get("add", []), stage.data.get("delete", []))
            if stage.skill == "manipulate":  # where movable objects were handled, for the pictures
                x, y, _ = self.robot_pose()
                for obj in dict.fromkeys(a for a in (*stage.args, stage.data.get("object")) if a in self.spec.objects):
                    self.recording.mark(self.time, str(obj), stage.action, x, y)
        return status

    def stop(self, agent: str, stage: Stage, now: float) -> None:
        self.advance(now)
        if self.skill is not None and self._owner == (agent, stage) and self.skill.result is RUNNING:
            self.skill.stop(now)
