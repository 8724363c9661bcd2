"""Robot scenarios: a world, task requests over time, changes during the run, settings.

A scenario file (TOML) says everything a run needs; every field is checked when the
file is loaded and an error names the file and the field.  ``kind = "synthetic"``
files are read by :mod:`experiments.synthetic` instead.  The format is documented in
``docs/scenarios.md``; shipped scenarios live in ``experiments/scenarios/``.

:func:`randomize` derives a variant of a scenario from a seed (request times,
people's positions and walks), for sweeps.
"""

from __future__ import annotations

import dataclasses
import random
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from experiments.actions import TimedAction, read_actions
from experiments.fields import Fields as _Fields
from experiments.fields import ScenarioError
from tasker import schedulers
from tasker.task import POLICIES

SCENARIOS = Path(__file__).resolve().parent / "scenarios"


@dataclass(frozen=True)
class RobotScenario:
    """A checked robot scenario."""

    name: str
    source: str
    world: str
    actions: tuple[TimedAction, ...]
    scheduler: str = "alg2"
    scheduler_options: dict[str, Any] = field(default_factory=dict)
    mode: str = "IT"
    s_freq: float = 1.0
    rep_rate: float = 1.0
    task_exe_rate: float = 10.0
    sp_up_rate: float = 1.0
    update: str = "planned"
    suspension: str = "planned"
    strategies: dict[str, dict[str, str]] = field(default_factory=dict)
    seed: int = 1
    horizon: float = 1800.0
    people: dict[str, dict[str, Any]] = field(default_factory=dict)
    objects: dict[str, dict[str, Any]] = field(default_factory=dict)
    policy: str = "strict"

    def to_json(self) -> dict[str, Any]:
        out = dataclasses.asdict(self)
        out["actions"] = [{"t": a.t, "kind": a.kind, **a.fields} for a in self.actions]
        return out


def resolve(name_or_path: str | Path) -> Path:
    """A shipped scenario name (``paper``) or a path."""
    p = Path(name_or_path)
    if p.suffix in (".toml", ".json") or p.exists():
        if not p.is_file():
            raise ScenarioError(f"{p}: no such scenario file")
        return p
    shipped = SCENARIOS / f"{name_or_path}.toml"
    if shipped.is_file():
        return shipped
    known = sorted(q.stem for q in SCENARIOS.glob("*.toml"))
    raise ScenarioError(f"unknown scenario {str(name_or_path)!r}: not a file, and not a shipped one "
                        f"({', '.join(known)})")


def kind_of(path: Path) -> str:
    try:
        raw = tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{path}: not valid TOML: {exc}") from None
    return str(raw.get("kind", "synthetic"))


def load(path: str | Path) -> RobotScenario:
    """Read and check a robot scenario (``kind = "robot"``)."""
    p = resolve(path)
    source = str(p)
    try:
        raw = tomllib.loads(p.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{source}: not valid TOML: {exc}") from None
    top = _Fields(source, "", raw)
    if top.get("kind", str) != "robot":
        raise top.error("kind", "this loader reads kind = 'robot'")
    world = top.get("world", str)
    world_path = p.parent / world
    if world_path.suffix == ".toml":
        if not world_path.is_file():
            raise top.error("world", f"no world file {world_path}")
        world = str(world_path)
    s = top.sub("settings", {})
    scheduler = s.get("scheduler", str, "alg2")
    if scheduler not in schedulers.names():
        raise s.error("scheduler", f"unknown scheduler {scheduler!r}; known: {schedulers.names()}")
    strategies_f = s.sub("strategies", {})
    strategies: dict[str, dict[str, str]] = {}
    for task in list(strategies_f.table):
        t = strategies_f.sub(task)
        strategies[task] = {k: _strategy(t, k) for k in ("update", "suspension") if k in t.table}
        t.done()
    strategies_f.done()
    actions = read_actions(top, world_events=True)
    people_f = top.sub("people", {})
    people: dict[str, dict[str, Any]] = {}
    for name in list(people_f.table):
        pf = people_f.sub(name)
        entry: dict[str, Any] = {}
        if "pose" in pf.table:
            entry["pose"] = _numbers(pf, "pose", 3)
        if "walk" in pf.table:
            entry["walk"] = [tuple(_numbers(_Fields(source, f"{pf.path('walk')}[{i}]", {"w": w}), "w", 3))
                             for i, w in enumerate(pf.get("walk", list))]
        pf.done()
        people[name] = entry
    objects_f = top.sub("objects", {})
    objects: dict[str, dict[str, Any]] = {}
    for name in list(objects_f.table):
        of = objects_f.sub(name)
        obj: dict[str, Any] = {"type": of.get("type", str), "place": of.get("place", str)}
        facts = of.get("facts", list, [])
        if not all(isinstance(f, list) and f and all(isinstance(x, str) and x for x in f) for f in facts):
            raise of.error("facts", f"expected a list of facts such as [[\"on_counter\", \"{name}\"]], got {facts!r}")
        obj["facts"] = [list(f) for f in facts]
        of.done()
        objects[name] = obj
    objects_f.done()
    scenario = RobotScenario(
        name=top.get("name", str, p.stem), source=source, world=world, actions=actions,
        scheduler=scheduler, scheduler_options=s.get("scheduler_options", dict, {}),
        mode=_choice(s, "mode", ("IT", "CT"), "IT"),
        s_freq=s.get("s_freq", float, 1.0, positive=True), rep_rate=s.get("rep_rate", float, 1.0, positive=True),
        task_exe_rate=s.get("task_exe_rate", float, 10.0, positive=True),
        sp_up_rate=s.get("sp_up_rate", float, 1.0, positive=True),
        update=_strategy(s, "update"), suspension=_strategy(s, "suspension"), strategies=strategies,
        seed=top.get("seed", int, 1), horizon=s.get("horizon", float, 1800.0, positive=True), people=people,
        objects=objects, policy=_choice(s, "policy", POLICIES, "strict"),
    )
    s.done()
    top.done()
    try:
        schedulers.create(scenario.scheduler, **scenario.scheduler_options)
    except Exception as exc:
        raise ScenarioError(f"{source}: settings.scheduler_options: {exc}") from None
    return scenario


def _choice(f: _Fields, key: str, choices: tuple[str, ...], default: str) -> str:
    value = f.get(key, str, default)
    if value not in choices:
        raise f.error(key, f"expected one of {list(choices)}, got {value!r}")
    return str(value)


def _strategy(f: _Fields, key: str) -> str:
    return _choice(f, key, ("planned", "static"), "planned")


def _numbers(f: _Fields, key: str, n: int) -> list[float]:
    value = f.get(key, list)
    if len(value) != n or not all(isinstance(v, int | float) and not isinstance(v, bool) for v in value):
        raise f.error(key, f"expected {n} numbers, got {value!r}")
    return [float(v) for v in value]


def randomize(scenario: RobotScenario, seed: int, *, time_jitter: float = 0.25, pose_jitter: float = 0.5
              ) -> RobotScenario:
    """A variant of ``scenario`` drawn from ``seed``: request and event times scaled by up to
    ``±time_jitter`` (so interruptions fall at other stages), people's scripted walk
    waypoints and explicit poses moved by up to ``pose_jitter`` metres.  The same seed
    gives the same variant."""
    rng = random.Random(f"randomize:{scenario.name}:{seed}")
    # one new time per distinct time (what happens together stays together), order kept
    times = sorted({a.t for a in scenario.actions})
    drawn = sorted(t if t == 0 else max(0.0, t * (1 + rng.uniform(-time_jitter, time_jitter))) for t in times)
    new_t = dict(zip(times, drawn, strict=True))
    actions = [TimedAction(round(new_t[a.t], 3), a.kind, dict(a.fields)) for a in scenario.actions]
    people: dict[str, dict[str, Any]] = {}
    for name, entry in sorted(scenario.people.items()):
        e = dict(entry)
        if "pose" in e:
            x, y, yaw = e["pose"]
            e["pose"] = [x + rng.uniform(-pose_jitter, pose_jitter), y + rng.uniform(-pose_jitter, pose_jitter), yaw]
        if "walk" in e:
            e["walk"] = [(t * (1 + rng.uniform(-time_jitter, time_jitter)), x + rng.uniform(-pose_jitter, pose_jitter),
                          y + rng.uniform(-pose_jitter, pose_jitter)) for t, x, y in e["walk"]]
            e["walk"].sort()
        people[name] = e
    return dataclasses.replace(scenario, actions=tuple(sorted(actions, key=lambda a: a.t)), people=people,
                               seed=seed, name=f"{scenario.name}~{seed}")
