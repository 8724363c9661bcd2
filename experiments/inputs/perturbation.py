"""A world that changes under the robot: exogenous events drawn around a variant's interruption.

A sweep spec's ``[perturbation]`` table (pre-registered: its rates are fixed before any run
and written into every run's ``run.json``) makes each randomised variant of a scenario also
change its world.  Its ``mode`` says how:

``untargeted`` (the default) draws world events from the world's own vocabulary, in a window
around the time the variant placed its interruption
(:class:`~experiments.inputs.scenario.InterruptionGrid`):

* ``door`` — a door is opened or closed: whichever it is not when the event happens (the robot
  or an earlier event may have changed it: :data:`TOGGLE`);
* ``move`` — a movable object (one a request names, or any other the world or the scenario
  has) is moved to another of the world's places: its relations to other things go with it
  (:meth:`robot.sim.Simulation.move`); nothing happens if the robot holds it then;
* ``device`` — a device is switched: on if it is off when the event happens, else off;
* ``bystander`` — a person no request names walks into a doorway, stands there a while, and
  walks back to where the scenario starts them.

``targeted`` aims one change at what the suspension tree's branch depends on, chosen while the
run runs (:mod:`experiments.run.targeting`): a movable object put on a place its stages use, a
door on its route opened or closed, a device its stages assume switched; timed before the
interruption or during the interrupted task's ``exeSusp``.  What is drawn from the seed (the
timing, the order of the kinds, the choice among candidates) is :class:`TargetDraw`.

The number of events is Poisson with mean ``rate_per_min`` × the window's minutes, their times
uniform in the window, each kind drawn uniformly among those the world and the scenario offer.
Everything is drawn from the variant's seed on streams of its own, so the same seed gives the
same events, and the variant without ``[perturbation]`` (the control arm) has the same times,
poses and interruption.  The events are ordinary ``[[world_events]]`` (with a ``note`` saying
they are perturbations), so they are traced as ``world`` events like any other.
"""

from __future__ import annotations

import math
import random
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from experiments.inputs.actions import TimedAction

if TYPE_CHECKING:
    from robot.spec import WorldSpec

KINDS = ("door", "move", "device", "bystander")
NOTE = "perturbation"
TOGGLE = "toggle"
"""A door's or device's value that means "whichever it is not when the event happens": the robot, a
task or an earlier event may have changed it since the events were drawn."""


MODES = ("untargeted", "targeted")
TARGET_KINDS = ("place", "door", "device")
"""What a targeted change aims at: a place the branch's stages use, a door on its route, a device its stages use."""
TIMINGS = ("before", "during")
"""When a targeted change happens: before the interruption, or during the interrupted task's exeSusp."""


@dataclass(frozen=True)
class Perturbation:
    """The pre-registered rates of exogenous events (see the module docstring).  ``mode`` is
    ``untargeted`` (``rate_per_min`` events of ``kinds`` in the window ``before_s`` before to
    ``after_s`` after the interruption) or ``targeted`` (one change aimed at the tree's branch,
    ``before_s`` at most before the interruption or ``during_s`` at most after genSusp began)."""

    rate_per_min: float = 3.0
    before_s: float = 20.0
    after_s: float = 60.0
    kinds: tuple[str, ...] = KINDS
    stand_s: tuple[float, float] = (10.0, 40.0)
    mode: str = "untargeted"
    during_s: float = 8.0

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise ValueError(f"mode: expected one of {list(MODES)}, got {self.mode!r}")
        if not (math.isfinite(self.during_s) and self.during_s > 0):
            raise ValueError(f"during_s: expected a finite number > 0, got {self.during_s!r}")
        if not (math.isfinite(self.rate_per_min) and self.rate_per_min >= 0):
            raise ValueError(f"rate_per_min: expected a finite number >= 0, got {self.rate_per_min!r}")
        if not (math.isfinite(self.before_s) and math.isfinite(self.after_s) and self.before_s >= 0
                and self.after_s >= 0 and self.before_s + self.after_s > 0):
            raise ValueError(f"before_s, after_s: expected finite numbers >= 0 that make a window, got "
                             f"{self.before_s!r}, {self.after_s!r}")
        bad = [k for k in self.kinds if k not in KINDS]
        if bad or not self.kinds or len(set(self.kinds)) != len(self.kinds):
            raise ValueError(f"kinds: expected distinct kinds among {list(KINDS)}, got {list(self.kinds)}")
        lo, hi = self.stand_s
        if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo <= hi):
            raise ValueError(f"stand_s: expected [low, high] with 0 < low <= high, got {list(self.stand_s)}")

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {"rate_per_min": self.rate_per_min, "before_s": self.before_s, "after_s": self.after_s,
                               "kinds": list(self.kinds), "stand_s": list(self.stand_s)}
        if self.mode != "untargeted":  # an untargeted arm's record reads as before
            out |= {"mode": self.mode, "during_s": self.during_s}
        return out


@dataclass(frozen=True)
class TargetDraw:
    """What a targeted variant draws from its seed, so every strategy of it meets the same change:
    ``timing`` (``before`` or ``during``), ``delay_s`` (how long before the interruption, or after the
    interrupted task entered genSusp), ``kinds`` (the order in which the kinds of target are tried)
    and ``pick`` (a number in [0, 1) choosing among the candidates of the first kind the branch offers)."""

    timing: str
    delay_s: float
    kinds: tuple[str, ...]
    pick: float

    @classmethod
    def of(cls, p: Perturbation, seed: str) -> TargetDraw:
        rng = random.Random(f"target:{seed}")
        timing = rng.choice(TIMINGS)
        window = p.before_s if timing == "before" else p.during_s
        delay = round(rng.uniform(0.1 * window, window), 3)
        kinds = list(TARGET_KINDS)
        rng.shuffle(kinds)
        return cls(timing, delay, tuple(kinds), rng.random())


def _poisson(rng: random.Random, mean: float) -> int:
    """A Poisson draw (Knuth's method: the means here are a few events)."""
    limit, k, p = math.exp(-mean), 0, 1.0
    while True:
        p *= rng.random()
        if p <= limit:
            return k
        k += 1


def named(actions: Sequence[TimedAction]) -> set[str]:
    """Every string a request's arguments name (people and objects the tasks are about)."""
    out: set[str] = set()
    for a in actions:
        if a.kind == "request":
            out |= {v for v in a.fields.get("args", {}).values() if isinstance(v, str)}
    return out


def events(p: Perturbation, seed: str, around: float, *, doors: Mapping[str, tuple[float, float, bool]],
           objects: Sequence[str], places: Sequence[str], devices: Mapping[str, str],
           bystanders: Mapping[str, tuple[float, float]]) -> list[TimedAction]:
    """The world events of one untargeted variant: ``doors`` name -> (centre x, y, open in the world
    file), ``objects`` the movable things, ``places`` where they may go, ``devices`` name -> state in the
    world file, ``bystanders`` person -> where they start.  A door or device event toggles what it
    finds when it happens (:data:`TOGGLE`)."""
    rng = random.Random(f"perturb:{seed}")
    offer = {"door": bool(doors), "move": bool(objects) and len(places) > 1, "device": bool(devices),
             "bystander": bool(bystanders) and bool(doors)}
    kinds = [k for k in p.kinds if offer[k]]
    window = p.before_s + p.after_s
    n = _poisson(rng, p.rate_per_min * window / 60.0)
    out: list[TimedAction] = []
    times = sorted(round(max(0.0, around - p.before_s + rng.uniform(0.0, window)), 3) for _ in range(n))
    for t in times:
        if not kinds:
            continue
        kind = rng.choice(kinds)
        if kind == "door":
            name = rng.choice(sorted(doors))
            out.append(TimedAction(t, "world", {"what": "door", "value": [name, TOGGLE],
                                                "note": f"{NOTE}: door {name} opened or closed (as it was not)"}))
        elif kind == "move":
            thing = rng.choice(sorted(objects))
            to = rng.choice(sorted(places))
            out.append(TimedAction(t, "world", {"what": "move", "value": [thing, to],
                                                "note": f"{NOTE}: someone moved {thing} to {to}"}))
        elif kind == "device":
            name = rng.choice(sorted(devices))
            out.append(TimedAction(t, "world", {"what": "device", "value": [name, TOGGLE],
                                                "note": f"{NOTE}: someone switched {name} (on if off, else off)"}))
        else:
            who = rng.choice(sorted(bystanders))
            door = rng.choice(sorted(doors))
            x, y, _ = doors[door]
            stay = round(rng.uniform(*p.stand_s), 3)
            home = bystanders[who]
            out.append(TimedAction(t, "world", {"what": "walk", "value": [who, round(x, 3), round(y, 3)],
                                                "note": f"{NOTE}: {who} stands in doorway {door} for {stay:g} s"}))
            out.append(TimedAction(round(t + stay, 3), "world", {"what": "walk", "value": [who, *home],
                                                                "note": f"{NOTE}: {who} walks back"}))
    return out


def candidates(spec: WorldSpec, scenario_objects: Mapping[str, Mapping[str, Any]], actions: Sequence[TimedAction],
               people: Mapping[str, Mapping[str, Any]]) -> dict[str, Any]:
    """What a world (a :class:`robot.spec.WorldSpec`) and a scenario offer :func:`events`."""
    asked = named(actions)
    things = sorted(set(spec.objects) | set(scenario_objects))
    doors = {n: ((d.box[0] + d.box[2]) / 2, (d.box[1] + d.box[3]) / 2, bool(d.open)) for n, d in spec.doors.items()}
    bystanders = {}
    for name in sorted((set(spec.people) | set(people)) - asked):
        pose = people.get(name, {}).get("pose") or (list(spec.people[name].pose) if name in spec.people else None)
        if pose is not None:
            bystanders[name] = (round(float(pose[0]), 3), round(float(pose[1]), 3))
    return {"doors": doors, "objects": things, "places": sorted(spec.places),
            "devices": {n: d.state for n, d in spec.devices.items()}, "bystanders": bystanders}
