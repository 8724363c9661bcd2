"""A world as plain data: what ``tasker world --json`` prints.

:func:`describe_world` turns a checked :class:`~robot.spec.WorldSpec` into a JSON-ready
dict (format :data:`FORMAT`, documented in ``docs/robot.md``): bounds, the robot, rooms,
walls, furniture, doors, places, devices, people, objects, facts and, optionally, the
statistics of the roadmap the base planner grows for the given seed.  Everything a tool
outside Python needs to draw or reason about the world, with rooms resolved
(:func:`robot.spec.room_of`) so that readers need not re-implement the geometry.

Key order follows the world file and numbers are the file's, so the same world gives
the same bytes.
"""

from __future__ import annotations

from typing import Any

from robot.spec import Box, WorldSpec, room_of

FORMAT = "tasker.world/1"
DOOR_PROBE = 0.3  # metres either side of a door's leaf where its two rooms are looked up


def _door_rooms(spec: WorldSpec, box: Box) -> list[str | None]:
    """The rooms on either side of a door leaf (west/east for a door in a vertical wall, else south/north)."""
    x0, y0, x1, y1 = box
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    if x1 - x0 < y1 - y0:
        sides = [(x0 - DOOR_PROBE, cy), (x1 + DOOR_PROBE, cy)]
    else:
        sides = [(cx, y0 - DOOR_PROBE), (cx, y1 + DOOR_PROBE)]
    return [room_of(spec, x, y) for x, y in sides]


def roadmap_stats(spec: WorldSpec, seed: int = 1) -> dict[str, Any]:
    """Size and connectivity of the roadmap :class:`robot.motion.BasePlanner` uses for ``seed``.

    ``components`` counts the roadmap's connected pieces; ``places_unlinked`` lists the places
    that are not a node of its largest piece (a place the robot cannot reach from most of the
    apartment, walls and furniture alone considered).
    """
    import numpy as np
    from scipy.sparse.csgraph import connected_components

    from robot.roadmap import Roadmap
    from robot.scene import Scene
    from robot.tiago import robot_dimensions

    scene = Scene(spec, robot_dimensions()[2])
    rm = Roadmap.for_world(spec, scene, seed)
    n, labels = connected_components(rm.graph, directed=False)
    main = int(np.bincount(labels).argmax())
    unlinked = []
    for name, (x, y, _) in spec.places.items():
        d = np.hypot(rm.nodes[:, 0] - x, rm.nodes[:, 1] - y)
        at = np.flatnonzero(d < 1e-9)
        if not len(at) or labels[int(at[0])] != main:
            unlinked.append(name)
    s = rm.stats
    return {"seed": s.seed, "planner": s.planner, "robot_radius": scene.radius, "nodes": s.nodes,
            "edges": s.edges, "ompl_milestones": s.ompl_milestones, "corner_milestones": len(rm.corner_nodes),
            "dropped_edges": s.dropped_edges, "components": int(n), "places_unlinked": unlinked}


def describe_world(spec: WorldSpec, roadmap_seed: int | None = 1) -> dict[str, Any]:
    """``spec`` as JSON-ready data (see ``docs/robot.md``); ``roadmap_seed=None`` leaves the
    roadmap out (it takes about a second to grow)."""
    def room(x: float, y: float) -> str | None:
        return room_of(spec, x, y)

    r = spec.robot
    rooms: dict[str, Any] = {n: {"box": list(b), "places": [], "doors": []} for n, b in spec.rooms.items()}
    places: dict[str, Any] = {}
    for n, (x, y, yaw) in spec.places.items():
        places[n] = {"pose": [x, y, yaw], "room": room(x, y)}
        if places[n]["room"] is not None:
            rooms[places[n]["room"]]["places"].append(n)
    doors: dict[str, Any] = {}
    for n, d in spec.doors.items():
        between = _door_rooms(spec, d.box)
        doors[n] = {"box": list(d.box), "open": d.open, "rooms": between}
        for rn in dict.fromkeys(between):
            if rn is not None:
                rooms[rn]["doors"].append(n)
    doc: dict[str, Any] = {
        "format": FORMAT,
        "name": spec.name,
        "description": spec.description,
        "source": spec.source,
        "bounds": [list(spec.bounds[0]), list(spec.bounds[1])],
        "robot": {"pose": list(r.pose), "room": room(r.pose[0], r.pose[1]), "max_speed": r.max_speed,
                  "max_turn": r.max_turn, "max_accel": r.max_accel, "max_turn_accel": r.max_turn_accel},
        "rooms": rooms,
        "walls": [list(o.box) for o in spec.obstacles if o.kind == "wall"],
        "furniture": {o.name: {"box": list(o.box), "height": o.height, "room": room((o.box[0] + o.box[2]) / 2,
                                                                                    (o.box[1] + o.box[3]) / 2)}
                      for o in spec.obstacles if o.kind == "furniture"},
        "doors": doors,
        "places": places,
        "devices": {n: {"type": d.type, "place": d.place, "state": d.state} for n, d in spec.devices.items()},
        "people": {n: {"pose": list(p.pose), "room": room(p.pose[0], p.pose[1]), "posture": p.posture,
                       "speed": p.speed, "walk": [list(w) for w in p.walk], "events": [list(e) for e in p.events]}
                   for n, p in spec.people.items()},
        "objects": dict(spec.objects),
        "facts": [list(f) for f in spec.facts],
    }
    if roadmap_seed is not None:
        doc["roadmap"] = roadmap_stats(spec, roadmap_seed)
    return doc
