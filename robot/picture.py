"""Top-down pictures of a world: rooms, obstacles, doors, places, people and robot paths.

Drawn with matplotlib's Agg backend (headless, no OpenGL needed).  Symbols follow the
paper's Fig. 10 where it has one: the robot is a pentagon, people are circles
(dashed when fallen, pale when sitting), places are small arrows.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from robot.spec import WorldSpec
from tasker.world import Pose

_FILL = {"wall": "#6b6259", "furniture": "#b08d62"}


def draw_world(spec: WorldSpec, out: str | Path, *, robot: Pose | None = None,
               paths: Sequence[Sequence[tuple[float, float]]] = (),
               people: Mapping[str, tuple[Pose, str]] | None = None,
               doors_open: Mapping[str, bool] | None = None, title: str | None = None,
               decorate: Callable[[Any], None] | None = None, show_walks: bool = True) -> Path:
    """Write a PNG of ``spec`` to ``out`` and return its path.

    ``robot``, ``people`` (name → (pose, posture)) and ``doors_open`` default to the
    world file's initial state; ``paths`` are polylines drawn over the plan;
    ``decorate(ax)`` draws more on the matplotlib axes before the file is written.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle, Rectangle, RegularPolygon

    (x0, y0), (x1, y1) = spec.bounds
    fig, ax = plt.subplots(figsize=(max(4.0, (x1 - x0) * 0.8), max(3.0, (y1 - y0) * 0.8)), dpi=100)
    for name, (rx0, _ry0, rx1, ry1) in spec.rooms.items():
        ax.text((rx0 + rx1) / 2, ry1 - 0.35, name, ha="center", va="top", fontsize=8, color="#555")
    for o in spec.obstacles:
        bx0, by0, bx1, by1 = o.box
        ax.add_patch(Rectangle((bx0, by0), bx1 - bx0, by1 - by0, color=_FILL[o.kind], lw=0))
    state = {n: d.open for n, d in spec.doors.items()} | dict(doors_open or {})
    for n, d in spec.doors.items():
        bx0, by0, bx1, by1 = d.box
        ax.add_patch(Rectangle((bx0, by0), bx1 - bx0, by1 - by0, fill=not state[n], color="#7a4f2a",
                               lw=0.8, ls="--" if state[n] else "-"))
    for name, (px, py, pyaw) in spec.places.items():
        ax.annotate("", (px + 0.3 * math.cos(pyaw), py + 0.3 * math.sin(pyaw)), (px, py),
                    arrowprops={"arrowstyle": "->", "color": "#2a7a2a", "lw": 1})
        ax.text(px, py - 0.15, name, fontsize=6, color="#2a7a2a", ha="center", va="top")
    for path in paths:
        if len(path) > 1:
            xs, ys = zip(*path, strict=False)
            ax.plot(xs, ys, "-", color="#1f5fbf", lw=1.5)
    for p in spec.people.values():
        if p.walk and show_walks:
            ax.plot([w[1] for w in p.walk], [w[2] for w in p.walk], ":", color="#c0392b", lw=1)
    now = people if people is not None else {n: (p.pose, p.posture) for n, p in spec.people.items()}
    for name, ((px, py, _), posture) in now.items():
        ax.add_patch(Circle((px, py), 0.25, fill=posture != "sitting", alpha=0.85,
                            color="#c0392b", ls="--" if posture == "fallen" else "-", lw=1.2))
        ax.text(px, py + 0.32, f"{name} ({posture})", fontsize=7, ha="center")
    rx, ry, ryaw = robot if robot is not None else spec.robot.pose
    ax.add_patch(RegularPolygon((rx, ry), 5, radius=0.3, orientation=ryaw - math.pi / 2, color="#1f5fbf"))
    if decorate is not None:
        decorate(ax)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    ax.set_title(title or f"{spec.name}: {spec.description}", fontsize=9)
    ax.tick_params(labelsize=7)
    fig.tight_layout()
    out = Path(out)
    fig.savefig(out, metadata={"Software": "tasker"})
    plt.close(fig)
    return out
