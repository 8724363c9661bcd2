"""Doors a task may find closed: the passages a bundled domain may travel without one.

One definition for every task folder whose robot moves between places (``carry_object``,
``cook``, ``guide_human``, ``human_fell``): their ``task.py`` hooks yield these facts.  A
pair of places joined by a ``door_between`` fact is travelled only through the door, by
an action that needs the door ``open`` (and the domain's ``open_door`` can make it so);
every other ordered pair is a ``free_passage``.  A world without ``door_between`` facts
(every door open, or none modelled) makes every pair a free passage, so the plans there
are those of a domain without doors.
"""

from __future__ import annotations

from collections.abc import Iterator

from tasker.task import TaskContext
from tasker.world import Fact, WorldState

DOOR_BETWEEN = "door_between"
FREE_PASSAGE = "free_passage"


def free_passages(world: WorldState) -> Iterator[Fact]:
    """Every ordered pair of distinct places with no door between them is a free passage."""
    places = sorted(n for n, t in world.objects.items() if t == "place")
    doors = {(f[2], f[3]) for f in world.matching(DOOR_BETWEEN) if len(f) == 4}
    for a in places:
        for b in places:
            if a != b and (a, b) not in doors:
                yield (FREE_PASSAGE, a, b)


def extra_facts(ctx: TaskContext, world: WorldState) -> Iterator[Fact]:
    """The ``extra_facts`` hook of a task folder that needs nothing else: its free passages
    (a ``task.py`` re-exports it: ``from domains.doors import extra_facts``)."""
    return free_passages(world)
