"""The suspension-strategy experiment of ``docs/results.md``: its declared design, and running it.

``tasker results`` (:mod:`experiments.cli.results`) runs it in resumable steps, each only adding the
runs a results database does not hold yet:

1. **the pilot**: the targeted arm's first :data:`PILOT_SEEDS` seeds of every cell;
2. **the size**: from the pilot's discordant shares, the pairs each declared test needs
   (:func:`experiments.analysis.family.pilot_sizes`), and so the seeds per scenario
   (:func:`fixed_n`: at least :data:`MIN_N`, at most :data:`MAX_N`);
3. **the targeted arm** to that many seeds, **the untargeted** and **the control arm** to
   :data:`OTHER_SEEDS` each (the same variants, with today's random perturbations, and without any);
4. **the document** (:mod:`experiments.sweep.results_doc`), whose declaration (:data:`DECLARATION`)
   is committed before any run and kept word for word.

A *cell* is a scenario run with one of its decision trees (the spec's ``[variants.NAME] trees``):
strategies are compared within a cell, paired by seed.  Every run plans with cold caches (the spec's
``cold_caches = true``: ``RunOptions.cold``), so genSusp's wall time is a first run's.  Nothing here looks at an effect
before the document is written: the size reads the pilot's discordant shares and differences only
through the sizing rule stated in the declaration.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from experiments.analysis.family import BINARY, Contrast, Outcome, Size, pilot_sizes
from experiments.inputs.perturbation import KINDS, Perturbation
from experiments.inputs.strategy import Strategy
from experiments.metrics.store import ResultStore, RunRow
from experiments.sweep.driver import SweepSummary, run_sweep
from experiments.sweep.experiment_paths import RESULTS
from experiments.sweep.spec import Job, SweepSpec, load_spec
from tasker.task import DEFAULT_TREE

ROOT = Path(__file__).resolve().parents[2]
SPEC = "experiments/sweep/specs/strategies.toml"

ARMS = ("targeted", "untargeted", "control")
"""The arms, the primary first: each has its results database (:func:`db_of`)."""
PILOT_SEEDS = 20
OTHER_SEEDS = 30
MIN_N = 40
MAX_N = 100
UNTARGETED = Perturbation(rate_per_min=3.0, before_s=20.0, after_s=60.0, kinds=KINDS, stand_s=(10.0, 40.0))
"""The untargeted arm's perturbation: 0.3's experiment's, with its defects fixed (doors and devices
toggled as they are when the event happens, any movable object moved, relations moved with it)."""

OUTCOMES = (Outcome("suspensions.all_safe", BINARY, "every suspension safe"),)
CONTRASTS = (
    Contrast("suspension", "static", "planned"),
    Contrast("suspension", "static", "fallback"),
    Contrast("suspension", "static", "derived"),
)
H1_MIN = 0.10
"""H1: in the targeted arm, planned − static (and fallback − static) is at least this, its lower bound > 0."""
H2_MARGIN = 0.03
"""H2: in the untargeted and control arms, planned − static lies within ± this (TOST: the 90 % interval)."""
HELP_MARGIN_S = 5.0
"""Time-to-help: the equivalence margin (s) its paired difference is read against (90 % interval)."""
SECONDARY = (
    "safety.unattended_s", "carried.seconds", "people.time_to_help_s.mean", "suspensions.goal_unmet",
    "suspensions.already_done_stages", "suspensions.fallback_planned", "totals.static_fallbacks", "totals.failed",
)
"""Described per cell and as paired differences with bootstrap intervals; never tested, never a verdict."""

DECLARATION = """\
*Declared before running: this section was committed before any run of the experiment
existed, and `experiments/sweep/experiment.py` keeps it word for word.*

## The question

Where does planning the suspension make a task safer when it is interrupted, and where does
it not? A task folder's decision tree (`[[suspension]]`, eq. 47) is written for the task's own
states; the question is what happens when the world breaks what its branch assumes. Four ways
to build genSusp's FSM (`exeSusp`) are compared on the same randomised variants: **static**
(run the stages of the tree's first-match branch), **planned** (plan, from the state as it is,
to that branch's goal), **derived** (plan to the goal the folder's declarations give: every
hazard the task owns off, its person in a declared safe role, its invariants) and **fallback**
(run the branch where its stages can run in the world as it is; plan to the derived goal where
a stage cannot, the branch cannot be reached, genSusp fails, or a stage of `exeSusp` cannot run
when its turn comes).

## Design

`experiments/sweep/specs/strategies.toml`: suspension {static, planned, derived, fallback}, with
`update = planned`, `policy = strict` and hazard-aware waiting off throughout (one factor changes
per contrast). Six task folders: the bundled four (cook, carry_object, guide_human, human_fell),
water_plants and hot_pot (user-style folders under `experiments/sweep/specs/tasks/`; hot_pot was
written from `docs/domains.md` alone), each with at least two trees written from different
assumptions, every tree complete by `tasker check`'s report (each branch chosen on the folder's
`[example]` reaches its goal and leaves every declared hazard off). Scenarios: household (cook),
carry (carry_object), compound (carry_object and cook, their default trees), paper (guide_human
and human_fell), water_plants and hot_pot; each scenario is run with each tree its spec lists
(`[variants.NAME] trees`): a **cell** is a scenario with one tree. Each seed is one randomised
variant, the same for the four strategies of a cell: request times jittered, people moved, the
interrupting request placed in the seed's stratum of a grid over the interrupted task's stages.
Every run starts with the planning caches cold.

The world gives the tree something to break: places are `clear` only while no movable object rests
there, a hot pan or pot goes down only on a clear heat-proof spot, a fragile object only on a clear
surface, the paper world's doors are in its domains, and the worlds hold clutter someone may move.

Three arms, each its own family. **Targeted** (primary): one change per variant aimed at what the
tree's branch depends on — a movable object put on a place a stage needs clear, a door on its
route opened or closed, a device it names switched — timed, by the seed, either up to 20 s before
the interruption (aimed at the branch the executing task would choose then) or up to 8 s after
the interrupted task entered genSusp (aimed at the branch it chose); the change is the same for
the four strategies of a variant. **Untargeted**: 0.3's random perturbations (3 events a minute
from 20 s before to 60 s after the interruption: doors, movable objects, devices, bystanders).
**Control**: the same variants without either, 30 seeds. Untargeted: 30 seeds.

## Primary outcome, the families and the hypotheses

`suspensions.all_safe` (binary, per run): every suspension of the run was *safe* — as it ended,
the goal its `exeSusp` aimed for held and no hazard its agent owns, nor one the robot carries, was
on; a stage whose effects already held is no failure; a genSusp with no plan is not safe. Exact
McNemar test per cell and contrast (planned − static, fallback − static, derived − static); each
arm's family is every cell × 3 contrasts, Holm-adjusted at α = 0.05; no verdict below 10
discordant pairs ("too few pairs"). Every declared test stays in its family whatever the data.

* **H1** (targeted arm, pooled over cells): planned − static ≥ 0.10 with the 95 % interval's
  lower bound > 0. **H1b**: the same for fallback − static.
* **H2** (untargeted and control arms, pooled over cells): planned − static lies within ± 0.03
  (TOST: the 90 % paired bootstrap interval inside the margin).

Each can fail: H1 fails if the pooled difference is below 0.10 or its lower bound is not above 0;
H2 fails if the interval leaves the margin.

## Size

A pilot of the targeted arm's first 20 seeds fixes n per scenario: for each of its cells' tests,
the pairs needed for 80 % power at α = 0.05 / m (m the family's size), by Connor's approximation
from the pilot's discordant share and difference in proportions; n = the largest, at least 40 and
at most 100 (the machine's budget). Where a test needs more, the document says it is
underpowered. The pilot's runs are the first seeds of the final sample.

## Secondary (described, not tested)

Per cell and strategy, with paired differences from static and bootstrap intervals: hazard seconds
unattended including after the owner ended (`safety.unattended_s`), time spent with a hazard
carried into another task, time-to-help (read against an equivalence margin of ± 5 s: the 90 %
interval), suspensions whose goal was unmet, stages already done, fallbacks that planned, planner
fallbacks to static, failed tasks; genSusp's planner wall time with cold caches (median and p99
per strategy); how often the targeted change found a target; and the primary effect again over
the pairs whose two runs had the same schedule (the same agents held the robot in the same
order), with the pairs whose schedule differed counted apart.
"""


def db_of(arm: str, results: Path = ROOT / RESULTS) -> Path:
    """The results database of ``arm`` in the folder ``results``."""
    if arm not in ARMS:
        raise ValueError(f"arm: expected one of {list(ARMS)}, got {arm!r}")
    return Path(results) / f"{arm}.db"


@dataclass(frozen=True)
class Plan:
    """The pilot's sizes and the seeds per scenario they fix."""

    sizes: tuple[Size, ...]
    n: dict[str, int]

    def underpowered(self) -> list[Size]:
        return [s for s in self.sizes if s.required is not None and s.required > self.n[scenario_of(s.scenario)]]


def cell(scenario: str, tree: str | None) -> str:
    """A cell's name: the scenario, and the tree its strategies ran with (``household [cook:cooker]``)."""
    return f"{scenario} [{tree or DEFAULT_TREE}]"


def scenario_of(cell_name: str) -> str:
    return cell_name.rpartition(" [")[0] or cell_name


def cells(spec: SweepSpec) -> list[str]:
    """Every cell of the spec, scenario-major, in the order of its trees."""
    return [cell(sc, tree) for sc in spec.scenarios for tree in (spec.trees.get(sc) or (None,))]


def by_cell(rows: Sequence[RunRow]) -> list[RunRow]:
    """``rows`` with each run's scenario replaced by its cell and the tree dropped from its strategy
    (so that strategies pair within a cell by the spec's contrasts)."""
    out = []
    for r in rows:
        st = Strategy.parse(r.strategy)
        out.append(dataclasses.replace(r, scenario=cell(r.scenario, st.tree),
                                       strategy=dataclasses.replace(st, tree=None).label))
    return out


def fixed_n(sizes: Sequence[Size], scenarios: Sequence[str]) -> dict[str, int]:
    """Seeds per scenario: the largest pair count its cells' tests need, clamped to [MIN_N, MAX_N]."""
    out = {}
    for sc in scenarios:
        need = [s.required for s in sizes if scenario_of(s.scenario) == sc and s.required is not None]
        out[sc] = min(MAX_N, max(MIN_N, max(need, default=MIN_N)))
    return out


def load(root: Path = ROOT) -> SweepSpec:
    return load_spec(root / SPEC)


def arm_spec(spec: SweepSpec, arm: str) -> SweepSpec:
    """The spec as run in ``arm``: its own targeted perturbation, the untargeted one, or none."""
    if arm == "targeted":
        return spec
    if arm == "untargeted":
        return dataclasses.replace(spec, perturbation=UNTARGETED)
    if arm == "control":
        return dataclasses.replace(spec, perturbation=None)
    raise ValueError(f"arm: expected one of {list(ARMS)}, got {arm!r}")


def _seeds(spec: SweepSpec, count: int) -> tuple[int, ...]:
    if count > len(spec.seeds):
        raise ValueError(f"{count} seeds asked, the spec has {len(spec.seeds)}")
    return spec.seeds[:count]


def pilot_jobs(spec: SweepSpec) -> list[Job]:
    return dataclasses.replace(spec, seeds=_seeds(spec, PILOT_SEEDS)).jobs()


def arm_jobs(spec: SweepSpec, arm: str, n: dict[str, int] | None = None) -> list[Job]:
    """The jobs of ``arm``: the targeted arm to ``n`` seeds per scenario, the others to :data:`OTHER_SEEDS`."""
    s = arm_spec(spec, arm)
    if arm != "targeted":
        return dataclasses.replace(s, seeds=_seeds(s, OTHER_SEEDS)).jobs()
    n = n or {}
    return [j for j in s.jobs() if j.seed in s.seeds[:n.get(j.scenario, MIN_N)]]


def rows_of(db: str | Path, jobs: Sequence[Job]) -> list[RunRow]:
    """The stored runs of ``jobs`` (a database may hold more)."""
    if not Path(db).is_file():
        return []
    keys = {j.key for j in jobs}
    with ResultStore(db, readonly=True) as store:
        return [r for r in store.rows() if r.key in keys]


def size(spec: SweepSpec, db: str | Path) -> Plan:
    """The plan the pilot's stored runs give."""
    rows = by_cell(rows_of(db, pilot_jobs(spec)))
    names = cells(spec)
    sizes = pilot_sizes(rows, names, CONTRASTS, OUTCOMES, family_size=len(names) * len(CONTRASTS))
    return Plan(tuple(sizes), fixed_n(sizes, spec.scenarios))


@dataclass(frozen=True)
class Progress:
    """What :func:`run` did in each step (None: not reached)."""

    pilot: SweepSummary | None
    arms: dict[str, SweepSummary | None]


def run(spec: SweepSpec, *, results: Path = ROOT / RESULTS, workers: int = 1, limit: int | None = None,
        pilot_only: bool = False, progress: bool = False) -> tuple[Plan, Progress]:
    """Steps 1-3 (each resumable); ``limit`` caps the runs started by this call over all steps."""
    left = limit

    def step(jobs: list[Job], where: Path) -> SweepSummary | None:
        nonlocal left
        if left is not None and left <= 0:
            return None
        where.parent.mkdir(parents=True, exist_ok=True)
        summary = run_sweep(jobs, where, workers=workers, max_jobs=left, progress=progress)
        if left is not None:
            left -= summary.ran
        return summary

    pilot = step(pilot_jobs(spec), db_of("targeted", results))
    plan = size(spec, db_of("targeted", results))
    done: dict[str, SweepSummary | None] = {a: None for a in ARMS}
    if pilot_only or (pilot is not None and pilot.not_run):
        return plan, Progress(pilot, done)
    for a in ARMS:
        done[a] = step(arm_jobs(spec, a, plan.n), db_of(a, results))
    return plan, Progress(pilot, done)


__all__ = ["ARMS", "CONTRASTS", "DECLARATION", "OUTCOMES", "SECONDARY", "Plan", "arm_jobs", "cells", "fixed_n",
           "run", "size"]
