"""Targeted perturbation: one change of the world aimed at what the suspension tree's branch depends on.

Installed on a run by :func:`experiments.run.runner.run_scenario` when its perturbation's ``mode`` is
``targeted`` (:mod:`experiments.inputs.perturbation`).  The variant's
:class:`~experiments.inputs.perturbation.TargetDraw` says when, and in what order of preference; what
to change is found while the run runs:

* **when** — ``before``: ``delay_s`` before the interruption, aimed at the branch the executing
  agent's tree would choose if it were interrupted then; ``during``: ``delay_s`` after the
  interrupted agent (the first to enter genSusp by a ``susp`` at or after the interruption) entered
  genSusp, aimed at the branch its tree chose then — the same tree whatever strategy runs
  (``Strategy.tree``), so the change falls in its ``exeSusp``;
* **what** — the branch's stages, bound in the world of that moment as ``static`` would run them:
  ``place``: a movable object no request names is put on a place a stage needs clear (its
  action's precondition asks ``(clear place)``, the world's derived fact,
  :data:`robot.sim.CLEAR`); ``door``: a door on the route of a navigation stage — a
  ``door_between`` fact of its two places, or a door whose doorway the robot's path between
  them passes (the motion model's, as the robot would drive it now) — opened or closed,
  whichever it is not then; ``device``: a device a stage names is switched, on if it is off
  then, else off.  The first kind in the draw's order with a candidate is taken, the candidate
  chosen by the draw's ``pick`` among them in sorted order;
* **how** — as an ordinary world event, traced as ``world`` with a note beginning
  ``perturbation (targeted``: every strategy of a variant meets the same change at the same time
  as long as their runs agree up to it (they differ only in genSusp).

When there is no agent to aim at, or the branch offers no target, nothing happens and nothing is
traced: that run is its control arm's.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

from experiments.inputs.actions import TimedAction
from experiments.inputs.perturbation import NOTE, TOGGLE, TargetDraw
from experiments.run.simulation import SimulatedWorld
from robot.sim import CLEAR, DOOR_BETWEEN
from tasker import events as ev
from tasker.agent import DynamicAgent
from tasker.errors import PlanningFailed
from tasker.loop import SimulationLoop
from tasker.stage import Stage
from tasker.world import WorldState

SUSPEND = "suspend"


@dataclass(frozen=True, slots=True)
class Target:
    """One change to make: the world event (``what``, ``value``) and why (for the trace's note)."""

    kind: str
    what: str
    value: tuple[str, Any]
    why: str


class Targeter:
    """Aims one world change at the suspension tree's branch of a run (see the module docstring)."""

    def __init__(self, loop: SimulationLoop, sim: SimulatedWorld, apply: Callable[[TimedAction], None],
                 draw: TargetDraw, placed: float, asked: set[str]) -> None:
        self.loop, self.sim, self.apply, self.draw, self.placed = loop, sim, apply, draw, placed
        self.asked = asked
        self._armed = draw.timing == "during"
        if draw.timing == "before":
            loop.at(max(0.0, round(placed - draw.delay_s, 3)), self._before)
        else:
            loop.trace.subscribe(self._watch)

    # -- when -------------------------------------------------------------------------------------------

    def _agent(self, agent_id: str | None) -> DynamicAgent | None:
        return next((a for a in self.loop.all_agents if a.id == agent_id), None)

    def _before(self) -> None:
        agent = self._agent(self.loop.harmoniser.exe_da)
        target = self._target(agent) if agent is not None else None
        if target is not None:
            self._fire(target, f"before the interruption, at {agent.id if agent else '?'}'s branch")

    def _watch(self, e: ev.Event) -> None:
        if not (self._armed and isinstance(e, ev.Transition) and e.target == "genSusp" and e.trigger == SUSPEND
                and e.t >= self.placed - 1e-9):
            return
        self._armed = False
        agent = self._agent(e.agent)
        target = self._target(agent) if agent is not None else None
        if target is not None:
            when = f"during {e.agent}'s suspension"
            self.loop.at(round(e.t + self.draw.delay_s, 3), lambda: self._fire(target, when))

    def _fire(self, target: Target, when: str) -> None:
        note = f"{NOTE} (targeted, {when}): {target.why}"  # experiments.metrics.run.TARGETED reads its start
        self.apply(TimedAction(self.loop.now, "world", {"what": target.what, "value": list(target.value),
                                                         "note": note}))

    # -- what -------------------------------------------------------------------------------------------

    def _target(self, agent: DynamicAgent) -> Target | None:
        """The change aimed at ``agent``'s branch now, or None (no tree, no branch, no candidate)."""
        task = agent.task
        static = getattr(task, "static_suspension", None)
        world = self.sim.snapshot()
        if static is None or agent.ended or not isinstance(world, WorldState):
            return None
        ctx = replace(agent.ctx, suspended=True, world=world, now=self.loop.now, recovering=None)
        try:
            plan = static(ctx)
        except PlanningFailed:
            return None
        label = (plan.note or "").removeprefix("decision tree: ")
        domain = getattr(task, "domain", None)

        def needs_clear(stage: Stage, place: str) -> bool:
            if domain is None or stage.action not in domain.actions:
                return False
            unmet = domain.unmet(stage.action, stage.args, world.facts - {(CLEAR, place)}) or []
            return (CLEAR, place) in unmet

        found = candidates(plan.stages, world, clutter=self._clutter(world), devices=self.sim.device_state,
                           doors=self.sim.spec.doors, route=self._route, needs_clear=needs_clear, label=label)
        for kind in self.draw.kinds:
            options = found.get(kind, [])
            if options:
                return options[min(int(self.draw.pick * len(options)), len(options) - 1)]
        return None

    def _route(self, a: str, b: str) -> list[tuple[float, float]]:
        """The robot's path from place ``a`` to place ``b`` as the motion model plans it now (empty if none)."""
        places = self.sim.spec.places
        if a not in places or b not in places:
            return []
        est = self.sim.motion.estimate((*places[a],), (*places[b],))
        return [(float(x), float(y)) for x, y in est.path] if est.reachable else []

    def _clutter(self, world: WorldState) -> list[str]:
        """Movable objects no request names and the robot does not hold."""
        held = set(self.sim.held)
        return sorted(o for o in self.sim.spec.objects if o not in self.asked and o not in held
                      and o in world.objects)


def candidates(stages: Sequence[Stage], world: WorldState, *, clutter: Sequence[str], devices: Mapping[str, str],
               doors: Mapping[str, Any], route: Callable[[str, str], Sequence[tuple[float, float]]],
               needs_clear: Callable[[Stage, str], bool], label: str) -> dict[str, list[Target]]:
    """Every change aimed at ``stages`` (a branch bound in ``world``), by kind (see the module docstring)."""
    out: dict[str, list[Target]] = {"place": [], "door": [], "device": []}
    said = f"the branch '{label}'" if label else "the branch"
    used = sorted({a for s in stages for a in s.args
                   if world.objects.get(a) == "place" and (CLEAR, a) in world.facts and needs_clear(s, a)})
    if clutter:
        out["place"] = [Target("place", "move", (clutter[0], p), f"someone put {clutter[0]} on {p}, which "
                                                                  f"{said} uses") for p in used]
    routes = [(legs[0], legs[-1]) for s in stages if s.skill == "navigate"
              if len(legs := [a for a in s.args if world.objects.get(a) == "place"]) >= 2 and legs[0] != legs[-1]]
    on_route: set[str] = set()
    for a, b in routes:
        on_route |= {f[1] for f in world.matching(DOOR_BETWEEN) if len(f) == 4 and (f[2], f[3]) == (a, b)}
        path = list(route(a, b))
        on_route |= {d for d, door in doors.items() for p, q in zip(path, path[1:], strict=False)
                     if crosses(p, q, door.box)}
    out["door"] = [Target("door", "door", (d, TOGGLE), f"door {d}, on {said}'s route, opened or closed")
                   for d in sorted(on_route)]
    named = sorted({a for s in stages for a in s.args if a in devices})
    out["device"] = [Target("device", "device", (d, TOGGLE), f"someone switched {d}, which {said} uses")
                     for d in named]
    return out


def crosses(a: Sequence[float], b: Sequence[float], box: Sequence[float]) -> bool:
    """Whether the segment ``a``–``b`` meets the rectangle ``box`` = (xmin, ymin, xmax, ymax) (clipping)."""
    (x0, y0), (x1, y1) = (float(a[0]), float(a[1])), (float(b[0]), float(b[1]))
    lo, hi = 0.0, 1.0
    for p, q in ((-(x1 - x0), x0 - box[0]), (x1 - x0, box[2] - x0), (-(y1 - y0), y0 - box[1]), (y1 - y0, box[3] - y0)):
        if p == 0:
            if q < 0:
                return False
            continue
        r = q / p
        if p < 0:
            lo = max(lo, r)
        else:
            hi = min(hi, r)
        if lo > hi:
            return False
    return True
