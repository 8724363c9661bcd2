"""Plan steps and static templates become :class:`~tasker.stage.Stage` objects.

One builder for both, so a planned and a static ``exeTsk`` carry the same skills,
kinds, durations and grounded effects (``data["add"]``/``data["delete"]``, applied by
the executor to the world's symbolic state when the stage succeeds).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from planners.problem import DomainModel
from planners.taskspec import Literal, StageTemplate, TaskSpec
from tasker.errors import PlanningFailed
from tasker.stage import Stage
from tasker.world import WorldState

ROBOT_TYPE = "robot"


class _Fmt(dict[str, Any]):
    def __missing__(self, key: str) -> str:
        return "{" + key + "}"


def robot_name(world: WorldState | None) -> str:
    """The robot's object name: the first object of type ``robot`` (``"robot"`` if none)."""
    if world is not None:
        robots = sorted(n for n, t in world.objects.items() if t == ROBOT_TYPE)
        if robots:
            return robots[0]
    return "robot"


def place_of(world: WorldState, name: str) -> str | None:
    """Where ``name`` is: the place of its ``at`` fact, or the robot's place if the robot holds it."""
    for f in world.matching("at"):
        if len(f) == 3 and f[1] == name:
            return f[2]
    for f in world.matching("holding"):
        if len(f) == 3 and f[2] == name:
            return place_of(world, f[1])
    return None


class Bindings:
    """Resolves the tokens of ``task.toml``: ``$arg``, ``$robot``, ``$at:x``, and ``?x`` once a
    suspension branch's ``when`` bound it (:meth:`match`); others are literal."""

    def __init__(self, args: Mapping[str, Any], world: WorldState | None,
                 variables: Mapping[str, str] | None = None) -> None:
        self.args = args
        self.world = world
        self.vars = dict(variables or {})

    def token(self, tok: str) -> str:
        if tok.startswith("?"):
            return self.vars.get(tok, tok)
        if not tok.startswith("$"):
            return tok
        key = tok[1:]
        if key == "robot":
            return robot_name(self.world)
        if key.startswith("at:"):
            inner = key[3:]
            target = self.token("$" + inner) if inner == "robot" or inner in self.args else inner
            place = place_of(self.world, target) if self.world is not None else None
            if place is None:
                raise PlanningFailed("error", f"no place known for {target!r} (needed by {tok})")
            return place
        if key in self.args and self.args[key] is not None:
            return str(self.args[key])
        raise PlanningFailed("error", f"{tok}: no request argument {key!r}")

    def literals(self, lits: Sequence[Literal]) -> list[Literal]:
        return [tuple(self.token(t) for t in lit) for lit in lits]

    def _distance(self, env: Mapping[str, str]) -> float:
        """How far the things ``env`` names are from the robot (straight line; 0 without poses)."""
        if self.world is None:
            return 0.0
        robot = self.world.poses.get(robot_name(self.world))
        if robot is None:
            return 0.0
        return sum(math.dist(robot[:2], self.world.poses[v][:2]) for v in env.values() if v in self.world.poses)

    def match(self, when: Sequence[Literal], facts: frozenset[tuple[str, ...]]) -> Bindings | None:
        """These bindings extended by the first assignment of ``when``'s ``?vars`` under which
        every literal holds — candidates nearest the robot first (straight line), then by
        name — or None if none does.  A negated literal
        holds when no fact matches it."""
        def solve(k: int, env: dict[str, str]) -> dict[str, str] | None:
            if k == len(when):
                return env
            lit = tuple(self.token(t) if not t.startswith("?") else env.get(t, t) for t in when[k])
            negated = lit[0] == "not"
            atom = lit[1:] if negated else lit
            found = []
            for f in sorted(facts):
                if len(f) != len(atom) or f[0] != atom[0]:
                    continue
                new = dict(env)
                if all((new.setdefault(a, v) == v) if a.startswith("?") else a == v
                       for a, v in zip(atom[1:], f[1:], strict=True)):
                    found.append(new)
            if negated:
                return solve(k + 1, env) if not found else None
            found.sort(key=lambda e: (self._distance(e), sorted(e.items())))
            for new in found:
                done = solve(k + 1, new)
                if done is not None:
                    return done
            return None

        env = solve(0, dict(self.vars))
        return None if env is None else Bindings(self.args, self.world, env)


class StageBuilder:
    """Builds stages for one task type from plan steps or from static templates."""

    def __init__(self, spec: TaskSpec, domain: DomainModel) -> None:
        self.spec = spec
        self.domain = domain

    def from_step(self, step: Sequence[str], travel: Mapping[tuple[str, str], float],
                  args: Mapping[str, Any]) -> Stage:
        """The stage that executes one ground action ``(name, arg, ...)``."""
        name, actual = step[0], tuple(step[1:])
        spec = self.spec.actions[name]
        model = self.domain.actions[name]
        bind = {f"?{p}": a for p, a in zip(model.params, actual, strict=True)}
        if spec.travel is not None:
            a, b = (bind[spec.travel[0]], bind[spec.travel[1]])
            duration = 0.0 if a == b else travel.get((a, b), self.spec.travel_s)
            if not math.isfinite(duration):
                raise PlanningFailed("unsolvable", f"{name}{actual}: {b!r} is unreachable from {a!r}")
        elif spec.duration is not None:
            duration = spec.duration
        else:
            duration = model.constant_cost if model.constant_cost is not None else 0.0
        add, delete = self.domain.ground(name, actual)
        data: dict[str, Any] = {"add": [list(f) for f in add], "delete": [list(f) for f in delete]}
        if spec.to is not None:
            data["to"] = bind.get(spec.to, spec.to)
        if spec.text is not None:
            fmt = _Fmt({k: str(v) for k, v in args.items()})
            fmt.update({p[1:]: v for p, v in bind.items()})
            data["text"] = spec.text.format_map(fmt)
        return Stage(name, actual, spec.kind, spec.skill, float(duration), data)

    def from_steps(self, steps: Sequence[Sequence[str]], travel: Mapping[tuple[str, str], float],
                   args: Mapping[str, Any]) -> tuple[Stage, ...]:
        return tuple(self.from_step(s, travel, args) for s in steps)

    def from_templates(self, templates: Sequence[StageTemplate], bindings: Bindings,
                       travel: Mapping[tuple[str, str], float], suspended: bool) -> tuple[Stage, ...]:
        """A static strategy: each template's action (its ``suspended`` variant if the task was
        suspended before, Alg. 3) with its arguments resolved on the world now."""
        steps = []
        for t in templates:
            action = t.suspended if (suspended and t.suspended) else t.action
            steps.append((action, *(bindings.token(a) for a in t.args)))
        return self.from_steps(steps, travel, bindings.args)
