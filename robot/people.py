"""People in the apartment: scripted walks, postures, and the reactions tasks rely on.

Each person is moved kinematically on the simulation clock (deterministic, no
randomness).  What a person does in a step, in order of precedence:

1. **fallen** people lie still;
2. :attr:`Person.giving_room` (someone lies fallen close by): step to the spot the world
   gave, clear of the ring the robot helps from, and stand there until they are up again
   (no such spot: carry on);
3. :attr:`Person.waiting` (the person was told to wait): stand still — after stepping to
   :attr:`Person.aside` if the world gave one (out of a doorway: nobody waits in one);
4. :attr:`Person.following` (the person follows the robot): walk along the robot's
   trail and stop ``FOLLOW_GAP`` metres (along the trail) behind the robot — the trail
   keeps them off walls;
5. otherwise the **script**: ``walk`` waypoints ``(t, x, y)`` say where the person is
   at time ``t``; the person heads for the scripted position of *now* at their walking
   speed, so after a reaction ends they walk back onto the script instead of jumping.
   A scenario's ``walk`` world event replaces the script from then on (:meth:`Person.go_to`).

People walk around walls and furniture, never through them: given a :data:`Route` (the
world's, :meth:`robot.sim.Simulation.person_route`), every leg of the script whose
straight line crosses a wall or furniture is walked along the route instead (each leg
keeps its scripted start and end times; its corners are timed in proportion to the
distance walked), a ``walk`` event's walk follows the route at the person's speed, and a
person who has to catch up with the script (after making room, or behind a script faster
than they walk) goes round what stands between them and it.

Posture changes come from the script's ``events`` ``(t, posture)`` or from
:meth:`Person.set_posture`; and a sitting person asked to follow the robot stands up
first — nobody follows seated, and a standing person takes less room in a doorway
(``robot.scene.PERSON_RADIUS``).  Scripted walks keep the script's postures.
``waiting`` and ``following`` are set by the world from the facts a task folder binds to
them (``robot.sim.Simulation.bind``): people react to what they were told, never to a
task's predicate names.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable

from robot.spec import PersonSpec
from tasker.world import Fact, Pose

FOLLOW_GAP = 0.9  # metres behind the robot, along its trail
TRAIL_STEP = 0.05  # metres between recorded trail points

Point = tuple[float, float]
Route = Callable[[Point, Point], tuple[Point, ...]]
"""How a person gets from one point to another: the polyline they walk, both ends included
(just the two when the straight line is clear)."""


class Revision:
    """A count of changes to people, shared by everyone of one :class:`People`: equal counts,
    nobody changed in between (what the world's :meth:`~robot.sim.Simulation.facts_key` keys on)."""

    __slots__ = ("n",)

    def __init__(self) -> None:
        self.n = 0


class Person:
    """One person's state: pose, posture, where the script and the reactions put them."""

    def __init__(self, spec: PersonSpec, route: Route | None = None, revision: Revision | None = None) -> None:
        self.spec = spec
        self.revision = revision if revision is not None else Revision()
        self.name = spec.name
        self.x, self.y, self.yaw = spec.pose
        self.posture = spec.posture
        self._route = route
        self.walk = self._routed(spec.walk)  # the script's waypoints; :meth:`go_to` replaces them
        self._detour: list[Point] = []  # corners to walk round before heading for the script again
        self._event = 0
        self._trail: list[tuple[float, float]] = []
        self._seg: list[float] = []  # the lengths of the trail's legs (Person._follow)
        self._following = False
        self._waiting = False
        self._aside: tuple[float, float] | None = None
        self._giving_room: tuple[str, tuple[float, float] | None] | None = None
        # steps before this time change nothing (:meth:`_idle_after`); any change from outside resets it
        self._idle_until = -math.inf
        # set whenever the person may have changed (a step that ran, a reaction, a posture or a
        # walk given): the world syncs its scene and MuJoCo from the people it finds touched
        self.touched = True

    def _poke(self) -> None:
        """Something changed from outside: the next step runs, the world looks again."""
        self._idle_until = -math.inf
        self.touched = True
        self.revision.n += 1

    @property
    def following(self) -> bool:
        """The person follows the robot (the world sets it from a ``follower`` binding)."""
        return self._following

    @following.setter
    def following(self, value: bool) -> None:
        self._following = value
        self._poke()

    @property
    def waiting(self) -> bool:
        """The person was told to wait (the world sets it from a ``waiting`` binding)."""
        return self._waiting

    @waiting.setter
    def waiting(self, value: bool) -> None:
        self._waiting = value
        self._poke()

    @property
    def aside(self) -> tuple[float, float] | None:
        """Where a waiting person steps to first (None: they wait where they are)."""
        return self._aside

    @aside.setter
    def aside(self, value: tuple[float, float] | None) -> None:
        self._aside = value
        self._poke()

    @property
    def giving_room(self) -> tuple[str, tuple[float, float] | None] | None:
        """(fallen person, where to stand or None to carry on): room given to someone fallen."""
        return self._giving_room

    @giving_room.setter
    def giving_room(self, value: tuple[str, tuple[float, float] | None] | None) -> None:
        self._giving_room = value
        self._poke()

    @property
    def pose(self) -> Pose:
        return (self.x, self.y, self.yaw)

    def set_posture(self, posture: str) -> None:
        self.posture = posture
        self._poke()

    def scripted(self, t: float) -> tuple[float, float] | None:
        """Where the script wants the person at time ``t`` (None: no walk scripted)."""
        walk = self.walk
        if not walk:
            return None
        if t <= walk[0][0]:
            return None  # before the first waypoint the person stays where they are
        if t > walk[-1][0]:
            return walk[-1][1], walk[-1][2]  # after the script (what the loop below ends with)
        for (t0, x0, y0), (t1, x1, y1) in zip(walk, walk[1:], strict=False):
            if t <= t1:
                f = (t - t0) / (t1 - t0)
                return (x0 + f * (x1 - x0), y0 + f * (y1 - y0))
        return walk[-1][1], walk[-1][2]

    def _way(self, a: Point, b: Point) -> list[tuple[Point, float]]:
        """The points of the way from ``a`` to ``b`` after ``a`` (the :data:`Route`'s, else the
        straight line), each with the distance walked to it."""
        pts = self._route(a, b) if self._route is not None else (a, b)
        out: list[tuple[Point, float]] = []
        walked = 0.0
        for p, q in zip(pts, pts[1:], strict=False):
            d = math.hypot(q[0] - p[0], q[1] - p[1])
            if d > 1e-9:
                walked += d
                out.append(((q[0], q[1]), walked))
        return out

    def _routed(self, walk: tuple[tuple[float, float, float], ...]) -> tuple[tuple[float, float, float], ...]:
        """``walk`` with each leg along the :data:`Route`: the leg's start and end times kept,
        its corners timed in proportion to the distance walked along it."""
        if self._route is None or len(walk) < 2:
            return walk
        out = [walk[0]]
        for (t0, x0, y0), (t1, x1, y1) in zip(walk, walk[1:], strict=False):
            way = self._way((x0, y0), (x1, y1))
            for (cx, cy), walked in way[:-1]:
                out.append((t0 + (t1 - t0) * walked / way[-1][1], cx, cy))
            out.append((t1, x1, y1))
        return tuple(out)

    def go_to(self, t: float, x: float, y: float) -> None:
        """From time ``t`` the script is a walk from here to ``(x, y)`` at the person's speed
        (along the :data:`Route`), and standing there (a scenario's ``walk`` world event)."""
        walk = [(t, self.x, self.y)]
        walk += [(t + walked / self.spec.speed, q[0], q[1]) for q, walked in self._way((self.x, self.y), (x, y))]
        self.walk = tuple(walk) if len(walk) > 1 else ((t, x, y),)
        self._detour = []
        self._poke()

    def _walk_to(self, tx: float, ty: float, dt: float, stop_at: float = 0.0) -> None:
        dx, dy = tx - self.x, ty - self.y
        d = math.hypot(dx, dy)
        step = min(self.spec.speed * dt, max(0.0, d - stop_at))
        if step > 1e-9:
            self.x += dx / d * step
            self.y += dy / d * step
            self.yaw = math.atan2(dy, dx)

    def _follow(self, robot: tuple[float, float], dt: float) -> None:
        trail = self._trail
        seg = self._seg  # seg[k]: the length from trail[k - 1] to trail[k], measured once
        if not trail:
            trail.append((self.x, self.y))
            seg[:] = [0.0]
        last = trail[-1]
        step = math.hypot(robot[0] - last[0], robot[1] - last[1])
        if step >= TRAIL_STEP:
            trail.append(robot)
            seg.append(step)
        # the trail point FOLLOW_GAP behind the robot, measured along the trail
        back, k = 0.0, len(trail) - 1
        while k > 0 and back < FOLLOW_GAP:
            back += seg[k]
            k -= 1
        budget = self.spec.speed * dt
        while budget > 1e-9 and len(trail) > 1 and k > 0:
            nx, ny = trail[1]
            d = math.hypot(nx - self.x, ny - self.y)
            if d <= budget:
                self.x, self.y = nx, ny
                budget -= d
                trail.pop(0)
                seg.pop(0)
                k -= 1
                continue
            self._walk_to(nx, ny, budget / self.spec.speed)
            break

    def step(self, t: float, dt: float, robot: tuple[float, float]) -> None:
        """Move the person from ``t - dt`` to ``t``: reactions are the flags the world sets from
        the task folders' bindings, never a task's predicates.

        A person who stands still and will until ``_idle_until`` (lying, waiting, before or
        after their script; :meth:`_idle_after`) is not stepped before then: such a step
        would change nothing.  Whatever changes them from outside (a posture, a walk, a
        reaction) ends that at once."""
        if t < self._idle_until:
            return
        self.touched = True
        self.revision.n += 1
        self._step(t, dt, robot)
        self._idle_until = self._idle_after(t)

    def _idle_after(self, t: float) -> float:
        """After a step to ``t``: until when further steps certainly change nothing (``-inf``:
        the next may).  Still are the fallen, those at the spot they give room or wait at,
        and those before their script's first waypoint or at its last; until their next
        scripted posture at the latest (and the script's start)."""
        events = self.spec.events
        nxt = events[self._event][0] if self._event < len(events) else math.inf
        if self._following:
            return -math.inf
        if self.posture == "fallen":
            return nxt
        room = self._giving_room
        spot = room[1] if room is not None else None
        if spot is None and self._waiting:
            if self._aside is None:
                return nxt
            spot = self._aside
        if spot is not None:
            return nxt if math.hypot(spot[0] - self.x, spot[1] - self.y) <= 1e-9 else -math.inf
        walk = self.walk
        if not walk:
            return nxt
        if t < walk[0][0]:
            return min(nxt, walk[0][0])
        if t > walk[-1][0] and not self._detour and math.hypot(self.x - walk[-1][1], self.y - walk[-1][2]) <= 1e-9:
            return nxt
        return -math.inf

    def _step(self, t: float, dt: float, robot: tuple[float, float]) -> None:
        events = self.spec.events
        while self._event < len(events) and events[self._event][0] <= t:
            self.posture = events[self._event][1]
            self._event += 1
        if not self._following and self._trail:
            self._trail = []
        target = self.scripted(t)
        if self.posture == "fallen" or self._giving_room is not None and self._giving_room[1] is not None \
                or self._waiting or self._following or target is None:
            self._detour = []  # a reaction (or no script): the way back is found afresh
        if self.posture == "fallen":
            return
        if self._giving_room is not None and self._giving_room[1] is not None:
            self._walk_to(self._giving_room[1][0], self._giving_room[1][1], dt)
            return
        if self._waiting:
            if self._aside is not None:
                self._walk_to(self._aside[0], self._aside[1], dt)
            return
        if self._following:
            self._stand_up()
            self._follow(robot, dt)
            return
        if target is not None:
            self._head_for(target, dt)

    def _head_for(self, target: Point, dt: float) -> None:
        """Walk toward the script's point of now: straight when it is within this step or
        nothing stands between, else round the corners of the :data:`Route` to it."""
        budget = self.spec.speed * dt
        if not self._detour and self._route is not None \
                and math.hypot(target[0] - self.x, target[1] - self.y) > budget + 1e-9:
            self._detour = list(self._route((self.x, self.y), target)[1:-1])
        if not self._detour:
            self._walk_to(target[0], target[1], dt)
            return
        while self._detour and budget > 1e-9:
            cx, cy = self._detour[0]
            d = math.hypot(cx - self.x, cy - self.y)
            if d > budget:
                self._walk_to(cx, cy, budget / self.spec.speed)
                return
            if d > 1e-9:
                self.yaw = math.atan2(cy - self.y, cx - self.x)
            self.x, self.y = cx, cy
            budget -= d
            self._detour.pop(0)
        if budget > 1e-9:
            self._walk_to(target[0], target[1], budget / self.spec.speed)

    def stepping_aside(self) -> bool:
        """Not yet where :attr:`giving_room` or, waiting, :attr:`aside` says to stand."""
        return self.stepping_to() is not None

    def stepping_to(self) -> tuple[float, float] | None:
        """Where the person is stepping aside to (:attr:`giving_room` or, waiting,
        :attr:`aside`), while not there yet; None otherwise."""
        if self.posture == "fallen":
            return None
        spot = self._giving_room[1] if self._giving_room is not None else None
        spot = spot if spot is not None else (self._aside if self._waiting else None)
        if spot is None or math.hypot(spot[0] - self.x, spot[1] - self.y) <= 1e-9:
            return None
        return spot

    def _stand_up(self) -> None:
        if self.posture == "sitting":
            self.posture = "standing"


class People:
    """Everyone in the world, stepped together in name order (deterministic)."""

    def __init__(self, specs: Iterable[PersonSpec], route: Route | None = None) -> None:
        self.revision = Revision()  # bumped by every change to anyone
        self.by_name = {p.name: Person(p, route, self.revision) for p in sorted(specs, key=lambda s: s.name)}

    def __getitem__(self, name: str) -> Person:
        return self.by_name[name]

    def __contains__(self, name: object) -> bool:
        return name in self.by_name

    def __iter__(self):  # type: ignore[no-untyped-def]
        return iter(self.by_name.values())

    def step(self, t: float, dt: float, robot: tuple[float, float]) -> None:
        for p in self.by_name.values():
            p.step(t, dt, robot)

    def facts(self) -> set[Fact]:
        return {("posture", p.name, p.posture) for p in self.by_name.values()}
