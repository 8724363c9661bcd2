"""The layout of ``paper-2019``, reconstructed from the distances the original verification recorded.

The original TaskER repository (``RCPRG-ros-pkg/tasker``, ``test-plots/test11.bag``, commit
``56ab62c``) recorded, on topic ``/TH/shdl_data``, every comparison the 2019 harmoniser made in
the period of Appendix B: ``cost``, ``cc`` and ``ccps`` of both agents and ``c_switch``,
``c_wait``.  The 2019 cost model (``docs/model.md``: path metres times per-person factors)
makes those values path lengths: :data:`RECORD` lists the rows used here, already divided by
their factors (John 0.15 standing and walking, 0.3 sitting; Alice 0.2 standing; 1 for a fall).

:func:`derive` turns them into coordinates, on an open floor (straight-line paths; the
original walls are not known), in a frame with Alice's destination at the origin and
John's destination on the +x axis.  Each step uses recorded numbers only, never the
outcome of a run:

1. where John waited (``J2``): 4.653 m from Alice's destination (the ``cc`` of 14 rows,
   2521.1-2554.4) and 3.373 m from his own (his walk cost, 2556.5-2560.8), on the +y side;
2. the distance between the two destinations: the straight walk from ``J2`` to John's
   destination that fits the 9 rows of his guidance (2556.5-2580.6) best (least squares);
3. Alice: 4.565 m from John's destination (every row's ``cc``) and, with the robot beside
   John (2550.3-2560.8), 6.44 m of approach and guidance; of the two points, the one that
   fits Alice's path lengths during John's guidance better;
4. John's walk: a straight line to ``J2`` that passes Alice's destination at 0.72 m (the
   least recorded distance, 2514.8), his position on it at each row given by that row's
   distance to Alice's destination; of the two such lines, the one with which the rows
   2508.6-2521.1 leave the smaller residual;
5. the robot when Alice was requested (2508.6): John's 14.547 m and Alice's 7.21 m of
   remaining path; of the two points, the one nearer where it was at 2521.1 (0.44 m from
   John: it moved about 1 m, as Alice's path says);
6. Peter and Sara: 3.636 m and 1.274 m from the robot at the comparison of 2592.7, 4.84 m
   apart; the record has no robot position between 2580.6 and 2592.7, so it is taken
   where it guided John at 2580.6; the direction to Peter is free (not in the record):
   on along the way it was guiding John; of the two points for Sara, the one farther
   from John's start (free too);
7. the robot's speed (:func:`robot_legs`): how fast Alice's remaining path fell between
   consecutive rows of 2508.6-2521.1.  She sat still and had not been greeted (her
   distance to John's destination is the same in every row; her cost is f_stand times
   approach plus guidance), so her guidance part did not change and each fall is the
   robot's progress toward her.  The fastest leg is its driving speed, the slower ones hold
   its stops (guide John's suspension until 2513, starting, turning): as for John's speed
   (the fastest leg of his walk).

The times come from the record too (:data:`EVENTS`; t = recorded t - :data:`CLOCK`).

:func:`residuals` compares the straight-line distances of the result with every
recorded row.  ``experiments/inputs/scenarios/paper-2019.toml`` holds the result (shifted
into the world's room, rounded to centimetres); a test holds the two equal.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq, minimize_scalar

Point = tuple[float, float]

SOURCE = "RCPRG-ros-pkg/tasker@56ab62c test-plots/test11.bag, /TH/shdl_data"

# (t, John's remaining path a+g, Alice's remaining path a+g, |Alice's destination - John|)
# while guide Alice ran or was compared, before John waited (2508.6-2521.1)
RECORD_WALK: tuple[tuple[float, float, float, float], ...] = (
    (2508.6, 14.547, 7.210, 1.167),  # cost 2.182/0.15, cost 1.442/0.2, cc 0.175/0.15
    (2512.7, 14.440, 7.145, 0.920),  # cost 2.166/0.15, cost 1.429/0.2, cc 0.138/0.15
    (2514.8, 14.053, 7.080, 0.720),  # cost 2.108/0.15, cost 1.416/0.2, cc 0.108/0.15
    (2516.8, 10.647, 6.930, 2.500),  # cost 1.597/0.15, cost 1.386/0.2, cc 0.375/0.15
    (2519.0, 5.347, 6.560, 4.373),   # cost 0.802/0.15, cost 1.312/0.2, cc 0.656/0.15
    (2521.1, 3.813, 6.180, 4.653),   # cost 0.572/0.15, cost 1.236/0.2, cc 0.698/0.15
)
WAITED_FROM_ALICE_DEST = 4.653     # cc 0.698/0.15, rows 2521.1-2554.4 (14 rows, all equal)
WAITED_TO_OWN_DEST = 3.373         # cost 0.506/0.15 walking, rows 2556.5-2560.8
ALICE_TO_JOHN_DEST = 4.565         # cc 0.913/0.2, every row 2508.6-2565.0
ALICE_WITH_ROBOT_AT_JOHN = 6.44    # cost ~1.288/0.2, rows 2550.3-2560.8 (John's a = 0)
CLOSEST_TO_ALICE_DEST = 0.720      # the least of the rows above (2514.8)
# (t, John's path to his destination g, |Alice's destination - John|, Alice's a+g) while guided
RECORD_GUIDED: tuple[tuple[float, float, float, float], ...] = (
    (2556.5, 3.373, 4.657, 6.445),   # cost 0.506/0.15, cc 1.397/0.3, cost 1.289/0.2
    (2562.9, 2.993, 4.657, 6.445),
    (2565.0, 2.993, 4.743, 6.545),
    (2567.1, 2.887, 4.737, 6.665),
    (2569.2, 2.780, 5.017, 7.005),
    (2571.3, 2.580, 5.163, 7.135),
    (2573.4, 2.320, 5.323, 7.200),
    (2575.5, 2.267, 5.443, 7.280),
    (2580.6, 2.120, 5.550, 7.340),
)
CLOCK = 2507.6
"""The scenario's t = 0: recorded t - CLOCK puts Alice's request at t = 1.0 (2508.6, her first comparison)."""
PETER_FROM_ROBOT = 3.636           # 2592.7: exec cost (humanFell: the path to the person)
SARA_FROM_ROBOT = 1.274            # 2592.7: dac cost
PETER_SARA = 4.84                  # 2592.7: cc 4.841 and 4.832 (from Sara to Peter and back)




@dataclass(frozen=True)
class Event:
    """A moment of Appendix B the scenario takes from the record (``t``: recorded time, s)."""

    what: str
    t: float
    why: str


EVENTS: tuple[Event, ...] = (
    Event("Peter falls", 2580.6, "the last comparison of John and Alice alone, John still guided (the last row of "
          "RECORD_GUIDED); Peter's task executes at the next row, 2592.7"),
    Event("Sara falls", 2592.7, "her first comparison (with Peter's task executing): she was requested by then"),
    Event("Peter gets up", 2602.0, "Appendix B: at 2602 Peter fell's agent, waiting, learns that Peter is fine"),
)
"""Appendix B's falls, at the recorded rows that bound them (the record has nothing between 2580.6
and 2592.7; Appendix B's own 2540 and 2570 for Peter contradict its rows, which show John and
Alice compared, John guided, until 2580.6)."""


@dataclass(frozen=True)
class Leg:
    """Two consecutive rows of Alice's remaining path (m) while the robot drove toward her."""

    t0: float
    t1: float
    path0: float
    path1: float

    @property
    def speed(self) -> float:
        """How fast her remaining path fell (m/s): the robot's progress toward her."""
        return (self.path0 - self.path1) / (self.t1 - self.t0)


def robot_legs() -> tuple[Leg, ...]:
    """Step 7's legs: Alice's remaining path (:data:`RECORD_WALK`) between consecutive rows."""
    rows = [(t, sa) for t, _, sa, _ in RECORD_WALK]
    return tuple(Leg(t0, t1, a, b) for (t0, a), (t1, b) in zip(rows, rows[1:], strict=False))


@dataclass(frozen=True)
class Layout:
    """The reconstruction, in the frame of :func:`derive` (metres)."""

    alice_dest: Point
    john_dest: Point
    alice: Point
    john_waited: Point
    john_walk: tuple[tuple[float, Point], ...]   # (recorded t, where John was), first = his start
    robot: Point                                 # at 2508.6, when Alice was requested
    peter: Point
    sara: Point
    fit_rms: float                               # of step 2 (m)
    robot_speed: float                           # step 7 (m/s)


def _circles(c1: np.ndarray, r1: float, c2: np.ndarray, r2: float) -> list[np.ndarray]:
    d = float(np.linalg.norm(c2 - c1))
    if d == 0 or d > r1 + r2 or d < abs(r1 - r2):
        return []
    x = (r1 * r1 - r2 * r2 + d * d) / (2 * d)
    h = math.sqrt(max(0.0, r1 * r1 - x * x))
    e = (c2 - c1) / d
    n = np.array([-e[1], e[0]])
    return [c1 + x * e + h * n, c1 + x * e - h * n]


def _waited(d: float) -> np.ndarray:
    """Step 1: the point 4.653 m from the origin and 3.373 m from ``(d, 0)``, ``y > 0``."""
    x = (WAITED_FROM_ALICE_DEST ** 2 - WAITED_TO_OWN_DEST ** 2 + d * d) / (2 * d)
    return np.array([x, math.sqrt(WAITED_FROM_ALICE_DEST ** 2 - x * x)])


def _guided_residuals(d: float) -> np.ndarray:
    dest = np.array([d, 0.0])
    j2 = _waited(d)
    u = (j2 - dest) / WAITED_TO_OWN_DEST
    return np.array([np.linalg.norm(dest + g * u) - r for _, g, r, _ in RECORD_GUIDED])


def _on_line(j2: np.ndarray, side: int, r: float, before: bool) -> np.ndarray:
    """Step 4: the point at ``r`` from the origin on the line through ``j2`` that passes the
    origin at :data:`CLOSEST_TO_ALICE_DEST` (``side`` picks one of the two), before or after
    the closest point (John walks toward ``j2``)."""
    length = float(np.linalg.norm(j2))
    c = CLOSEST_TO_ALICE_DEST
    ang = math.atan2(j2[1], j2[0]) + math.pi + side * math.asin(c / length)
    v = np.array([math.cos(ang), math.sin(ang)])
    closest = j2 + v * math.sqrt(length * length - c * c)
    k = math.sqrt(max(0.0, r * r - c * c))
    return closest + v * k if before else closest - v * k


def _john(j2: np.ndarray, side: int) -> list[tuple[float, np.ndarray]]:
    t_close = min(RECORD_WALK, key=lambda row: row[3])[0]
    return [(t, _on_line(j2, side, r, t < t_close)) for t, _, _, r in RECORD_WALK]


def _walk_rms(john: list[tuple[float, np.ndarray]], alice: np.ndarray, dest: np.ndarray) -> float:
    """How far the rows 2508.6-2521.1 are from any robot position: for each row, the least
    |John's recorded path - straight lines| over the robot's points that fit Alice's path."""
    a_len = float(np.linalg.norm(alice))
    total = 0.0
    for (_, sj, sa, _), (_, j) in zip(RECORD_WALK, john, strict=True):
        b = sa - a_len

        def err(th: float, j: np.ndarray = j, b: float = b, sj: float = sj) -> float:
            r = alice + b * np.array([math.cos(th), math.sin(th)])
            return float((np.linalg.norm(r - j) + np.linalg.norm(j - dest) - sj) ** 2)

        total += min(float(minimize_scalar(err, bounds=(x, x + 0.5), method="bounded").fun)
                     for x in np.arange(0.0, 2 * math.pi, 0.5))
    return math.sqrt(total / len(RECORD_WALK))


def _pt(p: np.ndarray) -> Point:
    return (float(p[0]), float(p[1]))


def derive() -> Layout:
    """Steps 1-7 of the module docstring."""
    longest = WAITED_FROM_ALICE_DEST + WAITED_TO_OWN_DEST - 1e-6  # the two circles of step 1 still meet
    fit = minimize_scalar(lambda d: float(np.sum(_guided_residuals(d) ** 2)), bounds=(5.0, longest), method="bounded")
    d = float(fit.x)
    dest = np.array([d, 0.0])
    j2 = _waited(d)
    u = (dest - j2) / WAITED_TO_OWN_DEST

    def alice_at(th: float) -> np.ndarray:
        return dest + ALICE_TO_JOHN_DEST * np.array([math.cos(th), math.sin(th)])

    def gap(th: float) -> float:
        a = alice_at(th)
        return float(np.linalg.norm(a - j2) + np.linalg.norm(a) - ALICE_WITH_ROBOT_AT_JOHN)

    grid = np.linspace(0.0, 2 * math.pi, 721)
    roots = [brentq(gap, grid[i], grid[i + 1]) for i in range(len(grid) - 1) if gap(grid[i]) * gap(grid[i + 1]) < 0]

    def guided_fit(a: np.ndarray) -> float:  # Alice's path with the robot beside John while guided
        return sum((float(np.linalg.norm(dest - g * u - a) + np.linalg.norm(a)) - sa) ** 2
                   for _, g, _, sa in RECORD_GUIDED)

    alice = min((alice_at(th) for th in roots), key=guided_fit)
    john = min((_john(j2, side) for side in (1, -1)), key=lambda w: _walk_rms(w, alice, dest))
    start = john[0][1]
    _, sj, sa, _ = RECORD_WALK[0]
    robots = _circles(start, sj - float(np.linalg.norm(start - dest)), alice, sa - float(np.linalg.norm(alice)))
    robot = min(robots, key=lambda r: float(np.linalg.norm(r - j2)))
    last = dest - RECORD_GUIDED[-1][1] * u      # where John was guided at 2580.6: the robot beside him
    peter = last + PETER_FROM_ROBOT * u
    cos_psr = ((PETER_FROM_ROBOT ** 2 + SARA_FROM_ROBOT ** 2 - PETER_SARA ** 2)
               / (2 * PETER_FROM_ROBOT * SARA_FROM_ROBOT))
    sides = []
    for s in (1, -1):
        a = math.atan2(u[1], u[0]) + s * math.acos(max(-1.0, min(1.0, cos_psr)))
        sides.append(last + SARA_FROM_ROBOT * np.array([math.cos(a), math.sin(a)]))
    sara = max(sides, key=lambda p: float(np.linalg.norm(p - start)))
    return Layout(_pt(np.zeros(2)), _pt(dest), _pt(alice), _pt(j2), tuple((t, _pt(p)) for t, p in john),
                  _pt(robot), _pt(peter), _pt(sara), float(math.sqrt(fit.fun / len(RECORD_GUIDED))),
                  max(leg.speed for leg in robot_legs()))


def residuals(layout: Layout) -> list[tuple[float, str, float, float]]:
    """``(t, what, recorded, reconstructed)`` for the distances that do not need the robot's
    position: John to Alice's destination, John to his own while guided, Alice to John's."""
    ad, jd, al = (np.array(p) for p in (layout.alice_dest, layout.john_dest, layout.alice))
    out = [(t, "|Alice's destination - John|", r, float(np.linalg.norm(np.array(p) - ad)))
           for (t, _, _, r), (_, p) in zip(RECORD_WALK, layout.john_walk, strict=True)]
    out.append((2508.6, "|John's destination - Alice|", ALICE_TO_JOHN_DEST, float(np.linalg.norm(al - jd))))
    u = (jd - np.array(layout.john_waited)) / WAITED_TO_OWN_DEST
    out += [(t, "|Alice's destination - John| (guided)", r, float(np.linalg.norm(jd - g * u - ad)))
            for t, g, r, _ in RECORD_GUIDED]
    return out
