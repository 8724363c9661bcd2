"""Drawing a day of a protocol: its requests from a seed, and the synthetic backend's scenario.

:func:`draw` gives the requests of day ``seed`` (:class:`DayRequest`: call, type, site,
destination, deadline, priority, weight and what the type draws per request); both backends
are built from this one draw (:mod:`experiments.days.pipeline`).  :func:`generate` is that day
as a :class:`experiments.inputs.synthetic.SyntheticScenario` of :mod:`experiments.days.daytask`
task types.  Every request records its ``deadline`` and, for a fall, ``death_at`` (deadline +
``death_after_s``), so the metrics can judge from the trace alone.

Arrivals (``[arrivals] process``): ``uniform`` draws the call over ``[0, last_call_s)`` and
the deadline a window after it; ``before_deadline`` (TaBSA, ``my_tasks.py``) draws the
deadline over the day and the call uniformly over ``[−call_lead_s, deadline − call_lead_s)``,
a call before the day's start being made at its start; a type with ``deadline_draws = n``
draws n such pairs and takes the latest deadline and the earliest call (TaBSA's
pick-and-place is three such tasks).  With ``[apartment] positions = "rooms"`` the person of
a transport or a fall is anywhere free in a room, as TaBSA draws positions: uniform over
the rooms of the sites' places, at least ``clearance_m`` from the room's walls and from
every wall and piece of furniture; the request's site is the site whose place is nearest
in that room.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass
from typing import Any

from experiments.days.daytask import task_types
from experiments.days.protocol import Pose, Protocol, TaskSpec
from experiments.inputs.actions import TimedAction
from experiments.inputs.synthetic import SyntheticScenario
from tasker.agent import Rates
from tasker.errors import ConfigError

PEOPLE_KINDS = ("transport", "fall")
"""The types whose request is about a person (placed anywhere free with ``positions = "rooms"``)."""
MAX_TRIES = 100_000
"""Rejection sampling of a free position gives up after this many tries (a world with no free room)."""


@dataclass(frozen=True)
class DayRequest:
    """One request of a drawn day, before any backend gives it a form.

    ``site`` and ``dest`` are site names of the protocol; ``deadline`` and ``death_at``
    absolute seconds; ``work`` (falls) and ``walk_speed`` (transports) as drawn; ``pick``,
    ``place`` and ``carry_speed`` (pick-and-place) when the protocol draws them; ``xy`` where
    the person is when the protocol draws positions in rooms (else the site's spot).
    """

    t: float
    kind: str
    site: str
    dest: str
    deadline: float
    priority: int
    weight: float
    work: float | None = None
    walk_speed: float | None = None
    death_at: float | None = None
    pick: float | None = None
    place: float | None = None
    carry_speed: float | None = None
    xy: Pose | None = None


def _times(protocol: Protocol, spec: TaskSpec, rng: random.Random) -> tuple[float, float]:
    """``(call, deadline)`` of one request (see the module docstring)."""
    if protocol.process == "uniform":
        assert spec.deadline_s is not None
        call = round(rng.uniform(0.0, protocol.last_call_s), 1)
        return call, round(call + rng.uniform(*spec.deadline_s), 1)
    pairs = []
    for _ in range(spec.deadline_draws):
        deadline = rng.uniform(0.0, protocol.length_s)
        pairs.append((max(0.0, rng.uniform(-protocol.call_lead_s, deadline - protocol.call_lead_s)), deadline))
    return round(min(c for c, _ in pairs), 1), round(max(d for _, d in pairs), 1)


class _Rooms:
    """Free positions in the rooms of a protocol's sites (``positions = "rooms"``)."""

    def __init__(self, protocol: Protocol) -> None:
        from robot.spec import load_world, room_of

        assert protocol.robot is not None
        world = load_world(protocol.robot.world)
        self.clearance = protocol.clearance_m
        self.boxes = [o.box for o in world.obstacles]
        self.bounds = world.bounds
        places = {site: world.places[place][:2] for site, place in protocol.robot.places.items()}
        self.sites: dict[str, list[tuple[str, Pose]]] = {}
        for site, xy in sorted(places.items()):
            room = room_of(world, xy[0], xy[1])
            if room is not None:
                self.sites.setdefault(room, []).append((site, xy))
        self.rooms = {r: world.rooms[r] for r in sorted(self.sites)}
        if not self.rooms:
            raise ConfigError(f"{protocol.source}: no site's place lies in a room of {world.name!r}")
        self.box = (min(b[0] for b in self.rooms.values()), min(b[1] for b in self.rooms.values()),
                    max(b[2] for b in self.rooms.values()), max(b[3] for b in self.rooms.values()))

    def draw(self, rng: random.Random) -> tuple[str, Pose]:
        """A uniform free point and its site."""
        from robot.spec import disc_clear

        c = self.clearance
        for _ in range(MAX_TRIES):
            x = round(rng.uniform(self.box[0], self.box[2]), 2)
            y = round(rng.uniform(self.box[1], self.box[3]), 2)
            room = next((r for r, b in self.rooms.items() if b[0] + c <= x <= b[2] - c and b[1] + c <= y <= b[3] - c),
                        None)
            if room is not None and disc_clear(self.boxes, self.bounds, c, x, y):
                site = min(self.sites[room], key=lambda s: (math.hypot(s[1][0] - x, s[1][1] - y), s[0]))[0]
                return site, (x, y)
        raise ConfigError(f"no free position found in {MAX_TRIES} tries: rooms {sorted(self.rooms)} leave no point "
                          f"{c:g} m clear of walls and furniture")


def draw(protocol: Protocol, seed: int) -> tuple[DayRequest, ...]:
    """The requests of day ``seed``, in call order: the same seed gives the same day.

    Each task type draws its own stream (``random.Random(f"{name}:{seed}:{kind}")``), so
    adding a type to a protocol leaves the other types' draws unchanged; what a protocol
    does not ask for (per-request priorities, pick and place times, positions in rooms) is
    never drawn, so the shipped protocols' days stay what they were.
    """
    sites = sorted(protocol.sites)
    rooms = _Rooms(protocol) if protocol.positions == "rooms" else None
    requests: list[tuple[float, int, DayRequest]] = []
    for kind, spec in protocol.tasks.items():
        rng = random.Random(f"{protocol.name}:{seed}:{kind}")
        for _ in range(spec.count):
            call, deadline = _times(protocol, spec, rng)
            a, b = rng.sample(sites, 2)
            extra: dict[str, Any] = {}
            if kind == "transport":
                extra["walk_speed"] = round(rng.uniform(*spec.person_speed), 3)
            elif kind == "fall":
                extra["work"] = round(rng.uniform(*spec.work_s), 1)
                assert spec.death_after_s is not None
                extra["death_at"] = round(deadline + spec.death_after_s, 1)
            else:
                for key in ("pick", "place"):
                    value = getattr(spec, f"{key}_s")
                    if isinstance(value, tuple):
                        extra[key] = round(rng.uniform(*value), 1)
                if spec.carry_speed is not None:
                    extra["carry_speed"] = round(rng.uniform(*spec.carry_speed), 3)
            priority = rng.choice(spec.priorities) if spec.priorities else spec.priority
            if rooms is not None and kind in PEOPLE_KINDS:
                a, extra["xy"] = rooms.draw(rng)
                if b == a:  # the destination is another site
                    b = rng.choice([s for s in sites if s != a])
            requests.append((call, len(requests), DayRequest(call, kind, a, b, deadline, priority, spec.weight,
                                                             **extra)))
    requests.sort(key=lambda r: (r[0], r[1]))
    return tuple(r for *_, r in requests)


def generate(protocol: Protocol, seed: int, *, scheduler: str = "alg2",
             scheduler_options: dict[str, Any] | None = None) -> SyntheticScenario:
    """Day ``seed`` of ``protocol`` (:func:`draw`) as a synthetic scenario."""
    actions = []
    for r in draw(protocol, seed):
        site = list(r.xy) if r.xy is not None else list(protocol.sites[r.site])
        args: dict[str, Any] = {"site": site, "deadline": r.deadline, "priority": r.priority, "weight": r.weight}
        if r.kind == "transport":
            args["dest"] = list(protocol.sites[r.dest])
            args["walk_speed"] = r.walk_speed
        elif r.kind == "fall":
            args["work"] = r.work
            args["death_at"] = r.death_at
        else:
            args["dest"] = list(protocol.sites[r.dest])
            args |= {k: v for k, v in (("pick", r.pick), ("place", r.place), ("carry_speed", r.carry_speed))
                     if v is not None}
        actions.append(TimedAction(r.t, "request", {"task": r.kind, "args": args}))
    rate = 1.0 / protocol.step_s
    return SyntheticScenario(
        name=f"{protocol.name}-day{seed}", tasks=task_types(protocol), actions=tuple(actions), scheduler=scheduler,
        scheduler_options=dict(scheduler_options or {}), mode="IT", s_freq=rate, rates=Rates(rate, rate, rate),
        jitter=0.0, seed=seed, horizon=protocol.length_s,
    )
