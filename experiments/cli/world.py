"""Command-line subcommands of ``tasker`` for worlds: ``world`` and ``cost``.

``world --json`` prints :func:`robot.describe.describe_world`.

``register(subparsers)`` adds them to an :mod:`argparse` parser; each handler returns
the exit status.  ``cost`` answers the travel-time matrix of every given place or
point in one process; it exits 0 when every pair is reachable, 1 when one is not and
2 on bad input (:mod:`experiments.cli.args`; one line on stderr, never a traceback).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from experiments.cli.args import EXIT_FAILED, EXIT_OK, UsageError, did_you_mean, seed, show_progress, writable_file
from tasker.errors import BadInput as BadInput  # defined there; re-exported here
from tasker.world import MotionEstimate, MotionModel, Pose

if TYPE_CHECKING:
    from robot.spec import WorldSpec


def _pose(spec: WorldSpec, text: str, argument: str = "PLACE") -> Pose:
    if text in spec.places:
        return spec.places[text]
    parts = text.split(",")
    try:
        values = [float(p) for p in parts]
    except ValueError:
        values = []
    if len(values) not in (2, 3) or not all(math.isfinite(v) for v in values):
        raise BadInput(argument, f"{text!r} is neither a place of {spec.name}{did_you_mean(text, spec.places)} "
                                 f"({', '.join(sorted(spec.places))}) nor x,y[,yaw]")
    from robot.spec import point_problem, robot_problem

    # where no robot can be: not "unreachable" (as a goal; a start would be moved), a wrong point
    why = point_problem(spec, values[0], values[1])
    if why:
        raise BadInput(argument, f"{text!r} is {why} of world {spec.name}; expected a point in free space")
    why = robot_problem(spec, values[0], values[1])
    if why:
        raise BadInput(argument, f"{text!r}: {why} of world {spec.name}; expected a point with room for the robot")
    return (values[0], values[1], values[2] if len(values) == 3 else 0.0)


def _load(world: str) -> WorldSpec:
    from robot.spec import load_world, shipped_worlds

    p = Path(world)
    if p.suffix != ".toml" and not p.exists() and world not in shipped_worlds():
        raise UsageError("WORLD", f"unknown world {world!r}{did_you_mean(world, shipped_worlds())}; shipped: "
                                  f"{', '.join(shipped_worlds())}, or give a world file (.toml)")
    if p.suffix == ".toml" and not p.is_file():
        hint = (f" (the shipped world is named without a suffix: {p.stem})"
                if p.stem in shipped_worlds() and len(p.parts) == 1 else "")
        raise UsageError("WORLD", f"{world}: no such world file{hint}")
    return load_world(world)


def travel_matrix(model: MotionModel, poses: Sequence[Pose], progress: bool = False) -> list[list[MotionEstimate]]:
    """Every ordered pair's estimate: ``m[i][j]`` from ``poses[i]`` to ``poses[j]``.

    One function so that a faster batch query of the motion model can replace the
    per-pair :meth:`~robot.planner.MotionEstimator.estimate` calls without touching callers.
    """
    pairs = [(i, j) for i in range(len(poses)) for j in range(len(poses))]
    it: Any = pairs
    if progress and len(pairs) > 16:
        from tqdm import tqdm

        it = tqdm(pairs, desc="travel times", unit="pair", leave=False, file=sys.stderr)
    out: list[list[MotionEstimate]] = [[] for _ in poses]
    for i, j in it:
        out[i].append(model.estimate(poses[i], poses[j]))
    return out


def _picture_file(text: str) -> Path:
    """``--out``: a ``.png`` file name that can be written (the picture is a PNG; matplotlib would
    refuse another suffix after the work, or add ``.png`` to a name without one)."""
    p = Path(text)
    if p.suffix.lower() != ".png":
        raise UsageError("--out", f"{text}: expected a file name ending in .png (the picture is a PNG)")
    return writable_file(p, "--out")


def _world(args: argparse.Namespace) -> int:
    out = _picture_file(args.out) if args.out else None  # before the work, like every argument
    spec = _load(args.world)
    if out is not None:
        from robot.picture import draw_world

        draw_world(spec, out)
    if args.json:
        from robot.describe import describe_world

        print(json.dumps(describe_world(spec, None if args.no_roadmap else args.seed), indent=2))
    elif not args.out:
        print(f"{spec.name}: {spec.description}")
        print(f"  bounds {spec.bounds}, {len(spec.rooms)} rooms, {len(spec.obstacles)} obstacles, "
              f"{len(spec.doors)} doors")
        for n, p in spec.places.items():
            print(f"  place  {n:18s} {p[0]:6.2f} {p[1]:6.2f} {p[2]:6.2f}")
        for n, per in spec.people.items():
            print(f"  person {n:18s} {per.pose[0]:6.2f} {per.pose[1]:6.2f}  {per.posture}")
    return EXIT_OK


def _cost(args: argparse.Namespace) -> int:
    from robot.estimator import motion_model

    if len(args.points) < 2:
        raise UsageError("PLACE", f"expected at least two places or points, got {len(args.points)}")
    spec = _load(args.world)
    poses = [_pose(spec, t) for t in args.points]
    m = travel_matrix(motion_model(spec, seed=args.seed), poses, progress=show_progress(args))
    reachable = all(e.reachable for row in m for e in row)
    if args.json:
        print(json.dumps({
            "world": spec.name, "seed": args.seed, "points": list(args.points), "poses": [list(p) for p in poses],
            "reachable": [[e.reachable for e in row] for row in m],
            "time_s": [[e.time_s if e.reachable else None for e in row] for row in m],
            "distance_m": [[e.distance_m if e.reachable else None for e in row] for row in m],
        }))
    elif len(poses) == 2:
        e = m[0][1]
        what = f"{e.distance_m:.2f} m, {e.time_s:.1f} s, {len(e.path)} waypoints" if e.reachable else "unreachable"
        print(f"{args.points[0]} -> {args.points[1]}: {what}")
    else:
        width = max(8, *(len(t) for t in args.points))
        print("travel time (s), from row to column")
        print(" " * width + "".join(f" {t[:width]:>{width}}" for t in args.points))
        for name, row in zip(args.points, m, strict=True):
            cells = "".join(f" {(f'{e.time_s:.1f}' if e.reachable else '-'):>{width}}" for e in row)
            print(f"{name:<{width}}{cells}")
    return EXIT_OK if reachable else EXIT_FAILED


def register(subparsers: Any) -> None:
    """Add ``world`` and ``cost`` to ``subparsers`` (from ``ArgumentParser.add_subparsers``)."""
    p = subparsers.add_parser(
        "world", help="show a world: places, people; draw it",
        description="Load and check a world (a shipped name or a .toml file); print its places and people, "
                    "as text or JSON, and draw it from above.",
        epilog="examples:\n  tasker world paper\n  tasker world flat --json\n  tasker world paper --json --no-roadmap\n"
               "  tasker world my_flat.toml --out flat.png")
    p.add_argument("world", metavar="WORLD", help="a shipped world name (paper, flat) or a .toml path")
    p.add_argument("--out", metavar="PNG", help="write a top-down picture (a .png file)")
    p.add_argument("--json", action="store_true",
                   help="print the whole world as JSON (format tasker.world/1, see docs/robot.md): places, rooms, "
                        "doors, devices, people, objects and the roadmap's statistics")
    p.add_argument("--seed", type=seed, default=1, help="roadmap seed for --json, 0 <= N < 2**32 (default 1)")
    p.add_argument("--no-roadmap", action="store_true", help="with --json: leave the roadmap out (no OMPL run)")
    p.set_defaults(func=_world)
    c = subparsers.add_parser(
        "cost", help="travel times of the robot between places (a matrix, one call)",
        description="The robot's travel time and path length between every ordered pair of the given places or "
                    "points, from OMPL paths over TIAGo's base in the world. Exits 1 when a pair is unreachable.",
        epilog="examples:\n"
               "  tasker cost paper kitchen bedroom\n"
               "  tasker cost paper kitchen bedroom hall living --json   # the 4 x 4 matrix\n"
               "  tasker cost flat 5.0,2.0 2.5,1.8,0 --seed 7")
    c.add_argument("world", metavar="WORLD", help="a shipped world name (paper, flat) or a .toml path")
    c.add_argument("points", metavar="PLACE", nargs="+", help="two or more place names or x,y[,yaw] points")
    c.add_argument("--json", action="store_true", help="print the matrices as JSON")
    c.add_argument("--seed", type=seed, default=1, help="roadmap seed, 0 <= N < 2**32 (default 1)")
    c.set_defaults(func=_cost)
