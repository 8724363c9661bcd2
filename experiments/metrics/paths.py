"""Metrics of a robot day that need the robot's path: abandonment and travel distance.

They read the trace (requests, ends) and the recorded trajectory
(``trajectory.jsonl``, :mod:`robot.recording`: the robot and every person with their
posture, at 10 Hz), never the model.

**Abandonment** (TaBSA): the robot leaves a 2 m circle around a fallen person before
helping.  A request is *about a fallen person* when one of its arguments names a person
whose posture is ``fallen`` at the first sample at or after the request.  From the request
until its agent ends (finished: help was given; or ended otherwise; a fall requested again
after its task failed, ``renews`` in the trace, runs on until its last task ends) and while
the person is still fallen, each time the robot, having been within ``RADIUS_M`` of the person,
is next seen farther away counts as one abandonment.  Passing by on another task and
going on counts too: the robot was there and left the person lying.

**Abandonment for another task** (ours, beside TaBSA's): the same count, less the times
the robot left the circle while the fall's own agent was the executing one (``exeDA`` of
the trace's ``roles`` events).  TaBSA's circle ignores walls: a robot 1.9 m from a person
lying behind a wall must leave the circle to drive round to them, which TaBSA's count
calls abandonment; this one does not.  The robot leaving because another task took it
still counts.

**Travel distance**: the length of the robot's sampled path (x, y), in metres.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Iterable, Mapping, Sequence
from typing import Any, Protocol

from tasker.trace import needs

RADIUS_M = 2.0
FALLEN = "fallen"


class _Person(Protocol):
    name: str
    x: float
    y: float
    posture: str


class _Sample(Protocol):
    t: float
    robot: tuple[float, ...]
    people: tuple[_Person, ...]


def travel_m(samples: Sequence[_Sample]) -> float:
    """Length of the robot's path over the samples (x, y only)."""
    return sum(math.hypot(b.robot[0] - a.robot[0], b.robot[1] - a.robot[1]) for a, b in zip(samples, samples[1:],
                                                                                             strict=False))


def abandonments(events: Iterable[Mapping[str, Any]], samples: Sequence[_Sample], *,
                 radius: float = RADIUS_M, for_another_task: bool = False) -> dict[str, int]:
    """Per agent whose request is about a fallen person: how many times the robot left them
    (see above); with ``for_another_task``, only while another agent was ``exeDA``."""
    events = list(events)
    need = needs(events)  # a request made again after its task failed is the same need
    requests: list[tuple[str, float, list[str]]] = []
    ended: dict[str, float] = {}  # need -> when its last task ended (inf while one is requested or runs)
    roles: list[tuple[float, str | None]] = []  # (t, exeDA) as the trace's roles events set it
    for e in events:
        if e["event"] == "request":
            if e["agent"] == need[e["agent"]]:
                names = [v for v in e["args"].values() if isinstance(v, str)]
                requests.append((e["agent"], float(e["t"]), names))
            ended[need[e["agent"]]] = math.inf
        elif e["event"] == "end" and e["agent"] in need:
            ended[need[e["agent"]]] = float(e["t"])
        elif e["event"] == "roles":
            roles.append((float(e["t"]), e.get("exeDA")))
    role_times = [t for t, _ in roles]
    out: dict[str, int] = {}
    times = [s.t for s in samples]
    for agent, t0, names in requests:
        first = _first_at(times, t0)
        if first is None:
            continue
        at_call = {p.name: p for p in samples[first].people}
        person = next((n for n in names if n in at_call and at_call[n].posture == FALLEN), None)
        if person is None:
            continue
        stop = ended.get(agent, math.inf)
        inside = False
        left = 0
        for s in samples[first:]:
            if s.t >= stop:
                break
            p = next(q for q in s.people if q.name == person)
            if p.posture != FALLEN:
                break
            near = math.hypot(s.robot[0] - p.x, s.robot[1] - p.y) <= radius
            if inside and not near and not (for_another_task and need.get(_executing(roles, role_times, s.t) or "")
                                                == agent):
                left += 1
            inside = near
        out[agent] = left
    return out


def _executing(roles: Sequence[tuple[float, str | None]], times: Sequence[float], t: float) -> str | None:
    """``exeDA`` at time ``t``: the last ``roles`` event at or before it."""
    k = bisect.bisect_right(times, t) - 1
    return roles[k][1] if k >= 0 else None


def _first_at(times: Sequence[float], t: float) -> int | None:
    k = bisect.bisect_left(times, t - 1e-9)
    return k if k < len(times) else None


def path_metrics(events: Iterable[Mapping[str, Any]], samples: Sequence[_Sample]) -> dict[str, Any]:
    """``abandonments`` (total, TaBSA's), ``abandoned_falls`` (falls left at least once),
    ``abandonments_other_task`` (left while another task ran), ``travel_m``."""
    events = list(events)
    per = abandonments(events, samples)
    other = abandonments(events, samples, for_another_task=True)
    return {"abandonments": sum(per.values()), "abandoned_falls": sum(1 for v in per.values() if v),
            "abandonments_other_task": sum(other.values()), "travel_m": round(travel_m(samples), 3)}
