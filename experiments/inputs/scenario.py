"""Robot scenarios: a world, task requests over time, changes during the run, settings.

A scenario file (TOML) says everything a run needs.  It is read with the strict reader
:mod:`tasker.support.reader` and every field is checked when the file is loaded, with its
cross-references against the world and the task store (:mod:`experiments.inputs.crossref`):
an error names the file, the line, the field, what was expected and "did you mean".  ``kind = "synthetic"``
files are read by :mod:`experiments.inputs.synthetic` instead.  The format is documented in
``docs/scenarios.md``; shipped scenarios live in ``experiments/inputs/scenarios/``.

:func:`randomize` derives a variant of a scenario from a seed (request times,
people's positions and walks), for sweeps.
"""

from __future__ import annotations

import dataclasses
import math
import random
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from experiments.inputs import fields
from experiments.inputs import perturbation as perturbations
from experiments.inputs.actions import TABLES, TimedAction, read_actions
from experiments.inputs.fields import MODES, POLICIES, STRATEGIES, ScenarioError
from experiments.inputs.filekinds import expect
from experiments.inputs.perturbation import Perturbation
from experiments.inputs.robot_scenario import RobotScenario
from tasker.support import reader
from tasker.task import SUSPENSIONS

if TYPE_CHECKING:
    from robot.spec import WorldSpec

__all__ = ["InterruptionGrid", "RobotScenario", "ScenarioError", "load", "randomize", "resolve", "kind_of", "SCENARIOS",
           "with_devices"]

SCENARIOS = Path(__file__).resolve().parent / "scenarios"


SCENARIO_KEYS = ("kind", "name", "world", "seed", "settings", "people", "objects", "devices", *(k for k, _ in TABLES))


def resolve(name_or_path: str | Path) -> Path:
    """A shipped scenario name (``paper``) or a path, as an absolute path."""
    p = Path(name_or_path)
    if p.suffix in (".toml", ".json") or p.exists():
        if not p.is_file():
            hint = ""
            if not p.exists() and (SCENARIOS / f"{p.stem}.toml").is_file() and len(p.parts) == 1:
                hint = f" (the shipped scenario is named without a suffix: {p.stem})"
            raise ScenarioError(str(p), ("no such scenario file" if not p.exists() else "is not a file") + hint)
        return p.resolve()
    shipped = SCENARIOS / f"{name_or_path}.toml"
    if shipped.is_file():
        return shipped
    known = sorted(q.stem for q in SCENARIOS.glob("*.toml"))
    raise ScenarioError(str(name_or_path), f"no such scenario: not a file, and not a shipped one"
                                           f"{reader.suggest(str(name_or_path), known)} (shipped: {', '.join(known)})")


def name_of(path: Path) -> str:
    """The scenario's ``name``, which names its default output folder (``out/NAME``); the file's
    stem when the name is missing or is not a plain folder name (``scenario.toml`` files of
    different task folders differ by their names, not their file names)."""
    try:
        name = reader.load(path, ScenarioError).raw("name", None)
    except ScenarioError:
        return path.stem  # the run itself reports what is wrong with the file
    ok = isinstance(name, str) and re.fullmatch(r"[A-Za-z0-9_.-]+", name) and name not in (".", "..")
    return name if ok else path.stem


def kind_of(path: Path) -> str:
    """``robot`` or ``synthetic`` (the default), read strictly."""
    top = reader.load(path, ScenarioError)
    if "kind" not in top:  # read as synthetic, another file would fail with "tasks: missing" or an unknown key
        if "world" in top and "tasks" not in top:
            raise top.error("kind", 'missing: a scenario with a world is a robot scenario, so write kind = "robot" '
                                    "(without kind a scenario is synthetic, with [tasks.NAME] and no world)")
        expect(top, "scenario")  # a world file, sweep spec or protocol: named for what it is
    return str(top.string("kind", "synthetic", choices=("robot", "synthetic")))



def load(path: str | Path, *, check: bool = True, task_paths: Sequence[str] = ()) -> RobotScenario:
    """Read and check a robot scenario (``kind = "robot"``).

    With ``check`` (the default) every cross-reference is checked against the world and
    the task store too (:mod:`experiments.inputs.crossref`); doubtful but valid inputs are
    :class:`~tasker.support.reader.InputWarning` warnings, kept on ``RobotScenario.warnings``.
    """
    p = resolve(path)
    source = str(p)
    top = reader.load(p, ScenarioError)
    expect(top, "scenario")
    top.string("kind", choices=("robot",))
    world = top.string("world")
    world_file = p.parent / world
    if world_file.suffix == ".toml" or "/" in world:
        if not world_file.is_file():
            raise top.error("world", f"no world file {world_file} (a shipped world name or a .toml file "
                                     "relative to the scenario)")
        world = str(world_file.resolve())
    else:
        from robot.spec import shipped_worlds

        reader.check_name(top, "world", world, shipped_worlds(), "shipped world")
    s = top.table("settings", {})
    sched = fields.scheduler(s)
    strategies: dict[str, dict[str, str]] = {}
    for task, t in s.named("strategies"):
        strategies[task] = {k: str(t.string(k, choices=SUSPENSIONS if k == "suspension" else STRATEGIES))
                            for k in ("update", "suspension") if k in t}
        t.done()
    actions = read_actions(top, world_events=True)
    people: dict[str, dict[str, Any]] = {}
    for name, pf in top.named("people"):
        entry: dict[str, Any] = {}
        if "pose" in pf:
            entry["pose"] = list(pf.numbers("pose", 3, "[x, y, yaw]"))
        if "walk" in pf:
            walk_t = pf.at("walk", {})
            walk: list[tuple[float, ...]] = []
            for i, w in enumerate(pf.array("walk")):
                wp = reader.check_numbers(walk_t, i, w, 3, "[t, x, y]")
                if wp[0] < 0:
                    raise walk_t.error(i, f"expected a time >= 0, got {wp[0]!r}")
                if walk and wp[0] <= walk[-1][0]:
                    raise walk_t.error(i, f"waypoint times must increase: {wp[0]!r} after {walk[-1][0]!r}")
                walk.append(wp)
            entry["walk"] = walk
        pf.done()
        people[name] = entry
    objects: dict[str, dict[str, Any]] = {}
    for name, of in top.named("objects"):
        facts_t = of.at("facts", {})
        facts = []
        for i, fact in enumerate(of.array("facts", [])):
            if not isinstance(fact, list) or not fact or not all(isinstance(a, str) and a for a in fact):
                raise facts_t.error(i, f"expected a fact: a list of non-empty strings, got {fact!r}")
            facts.append([str(a) for a in fact])
        objects[name] = {"type": of.string("type"), "place": of.string("place"), "facts": facts}
        of.done()
    devices: dict[str, dict[str, Any]] = {}
    for name, df in top.named("devices"):  # as a world file's [devices]: a type, a place, a state
        df.done(("type", "place", "state"))  # a misspelt key is named as such, not as a missing one
        devices[name] = {"type": df.string("type"), "place": df.string("place"), "state": df.string("state", "off")}
    scenario = RobotScenario(
        name=str(top.string("name", p.stem)), source=source, world=world, actions=actions,
        scheduler=sched, scheduler_options=dict(s.table("scheduler_options", {}).items()),
        mode=str(s.string("mode", "IT", choices=MODES)),
        s_freq=fields.rate(s, "s_freq", 1.0), rep_rate=fields.rate(s, "rep_rate", 1.0),
        task_exe_rate=fields.rate(s, "task_exe_rate", 10.0), sp_up_rate=fields.rate(s, "sp_up_rate", 1.0),
        update=str(s.string("update", "planned", choices=STRATEGIES)),
        suspension=str(s.string("suspension", "planned", choices=SUSPENSIONS)), strategies=strategies,
        seed=int(top.number("seed", 1, integer=True, min=0, max=reader.MAX_SEED)),
        horizon=float(s.number("horizon", 1800.0, positive=True, max=reader.MAX_SECONDS)),
        people=people, objects=objects, devices=devices, policy=str(s.string("policy", "strict", choices=POLICIES)),
        secure_over_higher=bool(s.boolean("secure_over_higher", False)),
        request_fields=bool(s.boolean("request_fields", False)),
    )
    s.done()
    top.done(SCENARIO_KEYS)
    if not check:
        fields.scheduler_options(s, sched)
        return scenario
    from experiments.inputs import crossref
    from planners.bundled import task_types

    types = task_types(list(task_paths))
    scenario = crossref.check_robot(scenario, top, types)
    # what the scheduler is not told, the task folders may declare (alg2's classes from their priorities)
    options = fields.scheduler_defaults(scenario.scheduler, scenario.scheduler_options, types)
    return scenario if options == scenario.scheduler_options else dataclasses.replace(scenario,
                                                                                      scheduler_options=options)


def with_devices(scenario: RobotScenario, spec: WorldSpec) -> WorldSpec:
    """The world ``spec`` (a :class:`robot.spec.WorldSpec`) with the scenario's ``[devices]``, as if its
    file listed them; a name the world uses or a place it lacks is a :class:`ScenarioError` (a scenario
    loaded with its checks has been refused for these already, with the line)."""
    if not scenario.devices:
        return spec
    from robot.spec import Device

    devices = dict(spec.devices)
    taken = {*spec.places, *spec.people, *spec.devices, *spec.doors, *spec.objects, "robot"}
    for name, d in sorted(scenario.devices.items()):
        if name in taken:
            raise ScenarioError(scenario.source, f"the world {spec.name!r} already has something called {name!r}",
                                field=f"devices.{name}")
        if d["place"] not in spec.places:
            raise ScenarioError(scenario.source, f"no place {d['place']!r} in world {spec.name!r}; known: "
                                                 f"{', '.join(sorted(spec.places))}", field=f"devices.{name}.place")
        devices[name] = Device(name, d["type"], d["place"], d["state"])
    return dataclasses.replace(spec, devices=devices)


@dataclass(frozen=True)
class InterruptionGrid:
    """Where a sweep's variants place "the interruption": a stratified grid of times.

    ``interrupt`` names the request that interrupts (``"requests[1]"``: the second
    ``[[requests]]`` of the scenario file).  The window ``[start, stop)`` is cut into
    strata of ``step`` seconds; the variant of seed ``s`` puts the request — and every
    action written at the same time as it, such as the fall that causes it — at a
    uniformly drawn time inside stratum ``s mod strata``.  So ``strata`` consecutive
    seeds cover every stratum once, and the same seed always gives the same time.
    """

    interrupt: str
    start: float
    stop: float
    step: float

    def __post_init__(self) -> None:
        table, sep, rest = self.interrupt.partition("[")
        if table != "requests" or not sep or not rest.endswith("]") or not rest[:-1].isdigit():
            raise ValueError(f"interrupt: expected 'requests[N]', got {self.interrupt!r}")
        if not (0 <= self.start < self.stop) or not self.step > 0 or not math.isfinite(self.stop):
            raise ValueError(f"times: expected 0 <= start < stop and step > 0, got start={self.start!r}, "
                             f"stop={self.stop!r}, step={self.step!r}")

    @property
    def index(self) -> int:
        return int(self.interrupt.partition("[")[2][:-1])

    @property
    def strata(self) -> int:
        return math.ceil((self.stop - self.start) / self.step - 1e-9)

    def stratum(self, seed: int) -> tuple[float, float]:
        """The ``[low, high)`` window of the seed's stratum."""
        k = seed % self.strata
        low = self.start + k * self.step
        return low, min(self.stop, low + self.step)

    def to_json(self) -> dict[str, Any]:
        return {"interrupt": self.interrupt, "times": {"start": self.start, "stop": self.stop, "step": self.step}}


def placed_time(name: str, seed: int, interruption: InterruptionGrid) -> float:
    """Where the variant of ``seed`` of scenario ``name`` places its interruption: uniform in the seed's
    stratum, drawn on a stream of its own (so it does not depend on how many other times there are)."""
    low, high = interruption.stratum(seed)
    return round(random.Random(f"interrupt:{name}:{seed}").uniform(low, high), 3)


def randomize(scenario: RobotScenario, seed: int, *, time_jitter: float = 0.25, pose_jitter: float = 0.5,
              interruption: InterruptionGrid | None = None,
              perturbation: Perturbation | None = None) -> RobotScenario:
    """A variant of ``scenario`` drawn from ``seed``.

    * Request and event times are scaled by up to ``±time_jitter`` (what happens together
      stays together, order kept).  With an ``interruption`` grid, the interrupting request
      and what happens with it are placed in the seed's stratum instead (see
      :class:`InterruptionGrid`).
    * **Every** person — those of the world file as well as those the scenario lists — has
      the start pose and each scripted walk waypoint moved by up to ``pose_jitter`` metres,
      and walk times scaled like the rest, keeping each point in free space (the person's disc
      clear of walls and furniture, :class:`robot.scene.Scene`) and each leg clear of walls;
      a draw that fails 20 times keeps the original point.
    * With a ``perturbation`` (and an ``interruption`` grid), exogenous world events are drawn
      around the placed interruption (:mod:`experiments.inputs.perturbation`); everything else
      is drawn exactly as without it, so the control arm is the same variant unperturbed.

    The same seed gives the same variant."""
    from robot.scene import PERSON_RADIUS, Scene
    from robot.spec import load_world

    rng = random.Random(f"randomize:{scenario.name}:{seed}")
    # one new time per distinct time (what happens together stays together), order kept
    times = sorted({a.t for a in scenario.actions})
    drawn = sorted(t if t == 0 else max(0.0, t * (1 + rng.uniform(-time_jitter, time_jitter))) for t in times)
    new_t = dict(zip(times, drawn, strict=True))
    placed: float | None = None
    if interruption is not None:
        origin = ("requests", interruption.index)
        hit = [a for a in scenario.actions if a.origin == origin]
        if not hit:
            n = sum(1 for a in scenario.actions if a.kind == "request")
            raise ScenarioError(scenario.source, f"variants: interrupt: no {interruption.interrupt} (the scenario "
                                                 f"has {n} requests, requests[0]..requests[{n - 1}])")
        placed = placed_time(scenario.name, seed, interruption)
        new_t[hit[0].t] = placed
    actions = [TimedAction(round(new_t[a.t], 3), a.kind, dict(a.fields), a.origin) for a in scenario.actions]
    spec = load_world(scenario.world)
    scene = Scene(spec, PERSON_RADIUS["standing"])

    def moved(x: float, y: float, prev: tuple[float, float] | None) -> tuple[float, float]:
        for _ in range(20):
            nx, ny = x + rng.uniform(-pose_jitter, pose_jitter), y + rng.uniform(-pose_jitter, pose_jitter)
            if not scene.static_free(nx, ny):
                continue
            if prev is not None and not scene.segments_free(np.array([prev]), np.array([(nx, ny)]), dynamic=False,
                                                            static=True)[0] and \
                    scene.segments_free(np.array([prev]), np.array([(x, y)]), dynamic=False, static=True)[0]:
                continue  # the original leg was clear: keep it clear
            return round(nx, 3), round(ny, 3)
        return x, y

    people: dict[str, dict[str, Any]] = {}
    for name in sorted(set(spec.people) | set(scenario.people)):
        e = dict(scenario.people.get(name, {}))
        world = spec.people.get(name)
        pose = e.get("pose", list(world.pose) if world else None)
        walk = e.get("walk", [tuple(w) for w in world.walk] if world else [])
        here: tuple[float, float] | None = None
        if pose is not None:
            x, y, yaw = pose
            here = moved(float(x), float(y), None)
            e["pose"] = [here[0], here[1], yaw]
        if walk:
            new_walk = []
            for t, x, y in walk:
                here = moved(float(x), float(y), here)
                new_walk.append((round(t * (1 + rng.uniform(-time_jitter, time_jitter)), 3), *here))
            new_walk.sort()
            e["walk"] = [w for i, w in enumerate(new_walk) if i == 0 or w[0] > new_walk[i - 1][0]]
        people[name] = e
    if perturbation is not None:
        if placed is None:
            raise ScenarioError(scenario.source, "perturbation: needs an interruption grid ([variants.NAME]) to "
                                                 "place its window around")
        if perturbation.mode == "untargeted":  # a targeted change is chosen while the run runs (run.targeting)
            offer = perturbations.candidates(with_devices(scenario, spec), scenario.objects, actions, people)
            drawn_events = perturbations.events(perturbation, f"{scenario.name}:{seed}", placed, **offer)
            actions += [dataclasses.replace(a, origin=("perturbation", k)) for k, a in enumerate(drawn_events)]
    return dataclasses.replace(scenario, actions=tuple(sorted(actions, key=lambda a: a.t)), people=people,
                               seed=seed, name=f"{scenario.name}~{seed}")
