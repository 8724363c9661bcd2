"""Where a point is, symbolically: the room that holds it and the nearest place not behind a wall.

The world grounds ``(at robot PLACE)`` and ``(at PERSON PLACE)`` from poses through these
(:meth:`robot.sim.Simulation.snapshot`).  Walls, rooms and places never change during a run,
so answers are remembered per point and the places of each room are grouped once."""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping

import numpy as np

from robot.scene import Scene, segments_clear
from robot.spec import WorldSpec
from tasker.world import Pose

PLACE_MEMO = 4096  # points whose place is remembered (Places._memo), then forgotten all at once


class Places:
    """The symbolic places of one world, looked up from points."""

    def __init__(self, spec: WorldSpec, scene: Scene) -> None:
        self.spec, self.scene = spec, scene
        self._memo: dict[tuple[str, float, float], str] = {}
        # rooms smallest first (ties by name): the first holding a point is spec.room_of's answer
        self._rooms = sorted(spec.rooms.items(),
                             key=lambda nb: ((nb[1][2] - nb[1][0]) * (nb[1][3] - nb[1][1]), nb[0]))
        self._spot_rooms: dict[int, tuple[Mapping[str, Pose], dict[str | None, list[str]]]] = {}
        self._person_spots: dict[str, Pose] | None = None  # the places people can be at (person_place)

    def person_place(self, x: float, y: float) -> str:
        """Where a person is, symbolically: :meth:`place_of` among the places that are not
        the places of devices (people are not "at the stove"), or among all places if none."""
        if self._person_spots is None:
            device_places = {d.place for d in self.spec.devices.values()}
            self._person_spots = {n: p for n, p in self.spec.places.items()
                                  if n not in device_places} or dict(self.spec.places)
        return self._remembered("person", self._person_spots, x, y)

    def nearest_place(self, x: float, y: float) -> str:
        """Where the robot (or anything) at ``(x, y)`` is: :meth:`place_of` among all places."""
        return self._remembered("any", self.spec.places, x, y)

    def _remembered(self, which: str, spots: Mapping[str, Pose], x: float, y: float) -> str:
        """:meth:`place_of` among ``spots`` (named ``which``) remembered per point: every snapshot
        grounds everyone, most of whom stand where they stood."""
        key = (which, x, y)
        hit = self._memo.get(key)
        if hit is None:
            if len(self._memo) >= PLACE_MEMO:
                self._memo.clear()
            hit = self._memo[key] = self.place_of(x, y, spots)
        return hit

    def room_of(self, x: float, y: float) -> str | None:
        """The smallest room whose box holds ``(x, y)`` (ties by name), or None (:func:`robot.spec.room_of`:
        the same answer, from the rooms sorted once by area and name)."""
        for n, (x0, y0, x1, y1) in self._rooms:
            if x0 <= x <= x1 and y0 <= y <= y1:
                return n
        return None

    def place_of(self, x: float, y: float, spots: Mapping[str, Pose]) -> str:
        """The nearest of ``spots`` that is not behind a wall (ties broken by name).

        The nearest place of the room that holds ``(x, y)``; if that room has none, the
        nearest place in sight (the straight line to it crosses no wall); else the nearest.
        """
        def nearest(names: Iterable[str]) -> str:
            return min(names, key=lambda n: (math.hypot(spots[n][0] - x, spots[n][1] - y), n))

        room = self.room_of(x, y)
        if room is not None:
            by_room = self._spot_rooms.get(id(spots))
            if by_room is None or by_room[0] is not spots:  # the spots' rooms: places never move
                rooms: dict[str | None, list[str]] = {}
                for n in spots:
                    rooms.setdefault(self.room_of(spots[n][0], spots[n][1]), []).append(n)
                by_room = self._spot_rooms[id(spots)] = (spots, rooms)
            inside = by_room[1].get(room)
            if inside:
                return nearest(inside)
        names = sorted(spots)
        ends = np.array([spots[n][:2] for n in names], dtype=float)
        seen = segments_clear(np.repeat([[x, y]], len(names), axis=0), ends, self.scene.walls, 1e-6)
        return nearest([n for n, ok in zip(names, seen, strict=True) if ok] or names)
