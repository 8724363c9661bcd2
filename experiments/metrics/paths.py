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

from experiments.trace.timeline import Timeline, timeline
from tasker import events as ev

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


def abandonments(events: Timeline | Iterable[ev.Event | Mapping[str, Any]], samples: Sequence[_Sample], *,
                 radius: float = RADIUS_M, for_another_task: bool = False) -> dict[str, int]:
    """Per agent whose request is about a fallen person: how many times the robot left them
    (see above); with ``for_another_task``, only while another agent was ``exeDA``."""
    tl = timeline(events)
    need = tl.needs  # a request made again after its task failed is the same need
    ended: dict[str, float] = {}  # need -> when its last task ended (inf while one is requested or runs)
    for a in tl.agents.values():
        ended[need[a.id]] = a.end.t if a.end is not None else math.inf
    out: dict[str, int] = {}
    times = [s.t for s in samples]
    for agent in tl.first_needs():
        a = tl.agents[agent]
        first = _first_at(times, a.request_t)
        if first is None:
            continue
        names = [v for v in a.args.values() if isinstance(v, str)]
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
            if inside and not near and not (for_another_task and need.get(tl.exe_at(s.t) or "") == agent):
                left += 1
            inside = near
        out[agent] = left
    return out


def _first_at(times: Sequence[float], t: float) -> int | None:
    k = bisect.bisect_left(times, t - 1e-9)
    return k if k < len(times) else None


def path_metrics(events: Timeline | Iterable[ev.Event | Mapping[str, Any]], samples: Sequence[_Sample],
                 ) -> dict[str, Any]:
    """``abandonments`` (total, TaBSA's), ``abandoned_falls`` (falls left at least once),
    ``abandonments_other_task`` (left while another task ran), ``travel_m``."""
    tl = timeline(events)
    per = abandonments(tl, samples)
    other = abandonments(tl, samples, for_another_task=True)
    return {"abandonments": sum(per.values()), "abandoned_falls": sum(1 for v in per.values() if v),
            "abandonments_other_task": sum(other.values()), "travel_m": round(travel_m(samples), 3)}
