"""Command-line subcommands of ``tasker`` for worlds: ``world`` and ``cost``.

``register(subparsers)`` adds them to an :mod:`argparse` parser; each handler returns
the exit status.  ``cost`` exits 0 when the goal is reachable, 1 when it is not and 2
on bad input (message on stderr, never a traceback).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import Any

from robot.spec import WorldSpec, load_world
from tasker.errors import TaskerError
from tasker.world import Pose


class BadInput(TaskerError, ValueError):
    """A command-line argument that names no place and is no ``x,y[,yaw]``."""


def _pose(spec: WorldSpec, text: str) -> Pose:
    if text in spec.places:
        return spec.places[text]
    parts = text.split(",")
    try:
        values = [float(p) for p in parts]
    except ValueError:
        values = []
    if len(values) not in (2, 3) or not all(math.isfinite(v) for v in values):
        raise BadInput(f"{text!r} is neither a place of {spec.name} ({', '.join(sorted(spec.places))}) "
                       "nor x,y[,yaw]")
    return (values[0], values[1], values[2] if len(values) == 3 else 0.0)


def _world(args: argparse.Namespace) -> int:
    spec = load_world(args.world)
    if args.out:
        from robot.picture import draw_world

        draw_world(spec, args.out)
    if args.json:
        doc: dict[str, Any] = {
            "name": spec.name,
            "places": {n: list(p) for n, p in spec.places.items()},
            "bounds": [list(spec.bounds[0]), list(spec.bounds[1])],
            "people": {n: {"pose": list(p.pose), "posture": p.posture} for n, p in spec.people.items()},
            "doors": {n: d.open for n, d in spec.doors.items()},
            "devices": {n: {"type": d.type, "place": d.place, "state": d.state} for n, d in spec.devices.items()},
        }
        print(json.dumps(doc, indent=2))
    elif not args.out:
        print(f"{spec.name}: {spec.description}")
        print(f"  bounds {spec.bounds}, {len(spec.rooms)} rooms, {len(spec.obstacles)} obstacles, "
              f"{len(spec.doors)} doors")
        for n, p in spec.places.items():
            print(f"  place  {n:18s} {p[0]:6.2f} {p[1]:6.2f} {p[2]:6.2f}")
        for n, per in spec.people.items():
            print(f"  person {n:18s} {per.pose[0]:6.2f} {per.pose[1]:6.2f}  {per.posture}")
    return 0


def _cost(args: argparse.Namespace) -> int:
    from robot.motion import motion_model

    spec = load_world(args.world)
    start, goal = _pose(spec, args.start), _pose(spec, args.goal)
    est = motion_model(spec, seed=args.seed).estimate(start, goal)
    if args.json:
        print(json.dumps({"reachable": est.reachable,
                          "distance_m": est.distance_m if est.reachable else None,
                          "time_s": est.time_s if est.reachable else None,
                          "path": [list(p) for p in est.path]}))
    elif est.reachable:
        print(f"{args.start} -> {args.goal}: {est.distance_m:.2f} m, {est.time_s:.1f} s, {len(est.path)} waypoints")
    else:
        print(f"{args.start} -> {args.goal}: unreachable")
    return 0 if est.reachable else 1


def _guarded(handler: Any) -> Any:
    def run(args: argparse.Namespace) -> int:
        try:
            return int(handler(args))
        except TaskerError as e:
            print(f"error: {e}", file=sys.stderr)
            return 2

    return run


def register(subparsers: Any) -> None:
    """Add ``world`` and ``cost`` to ``subparsers`` (from ``ArgumentParser.add_subparsers``)."""
    p = subparsers.add_parser("world", help="show a world: places, people; draw it")
    p.add_argument("world", help="a shipped world name (paper, flat) or a .toml path")
    p.add_argument("--out", metavar="PNG", help="write a top-down picture")
    p.add_argument("--json", action="store_true", help="print places, bounds and people as JSON")
    p.set_defaults(func=_guarded(_world))
    c = subparsers.add_parser("cost", help="travel time and path of the robot between two poses")
    c.add_argument("world", help="a shipped world name (paper, flat) or a .toml path")
    c.add_argument("start", metavar="FROM", help="a place name or x,y[,yaw]")
    c.add_argument("goal", metavar="TO", help="a place name or x,y[,yaw]")
    c.add_argument("--json", action="store_true", help="print the estimate as JSON")
    c.add_argument("--seed", type=int, default=1, help="roadmap seed (default 1)")
    c.set_defaults(func=_guarded(_cost))


def main(argv: list[str] | None = None) -> int:
    """Run the subcommands on their own (the ``tasker`` command wires them in normally)."""
    parser = argparse.ArgumentParser(prog="tasker")
    register(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(argv)
    return int(args.func(args))


if __name__ == "__main__":
    raise SystemExit(main())
