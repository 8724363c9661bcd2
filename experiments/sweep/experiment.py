"""The suspension-strategy experiment of ``docs/results.md``: its declared design, and running it.

``tasker results`` (:mod:`experiments.cli.results`) runs it in four resumable steps, each only
adding the runs a results database does not hold yet:

1. **the pilot**: the perturbed arm's first :data:`PILOT_SEEDS` seeds of every scenario;
2. **the size**: from the pilot's variances, the pairs each declared test needs
   (:func:`experiments.analysis.family.pilot_sizes`), and so the seeds per scenario
   (:func:`fixed_n`: at least :data:`MIN_N`, at most :data:`MAX_N`);
3. **the perturbed arm** to that many seeds, and **the control arm** (the same variants
   without ``[perturbation]``) to :data:`CONTROL_SEEDS`;
4. **the document** (:mod:`experiments.sweep.results_doc`), whose declaration
   (:data:`DECLARATION`) is written before any run and kept word for word.

Nothing here looks at an effect before the document is written: the size reads the pilot's
spread (discordant share, SD of the paired differences) and the pilot's difference in
proportions only through the sizing rule stated in the declaration.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from experiments.analysis.family import BINARY, SECONDS, Contrast, Outcome, Size, pilot_sizes
from experiments.metrics.store import ResultStore, RunRow
from experiments.sweep.driver import SweepSummary, run_sweep
from experiments.sweep.experiment_paths import CONTROL_DB, DB
from experiments.sweep.provenance import arm
from experiments.sweep.spec import Job, SweepSpec, load_spec

ROOT = Path(__file__).resolve().parents[2]
SPEC = "experiments/sweep/specs/strategies.toml"

PILOT_SEEDS = 20
CONTROL_SEEDS = 30
MIN_N = 100
MAX_N = 200
DELTA_S = 30.0

OUTCOMES = (
    Outcome("suspensions.all_safe", BINARY, "every suspension safe"),
    Outcome("safety.unattended_alive_s", SECONDS, "hazard unattended in its owner's lifetime (s)", delta=DELTA_S),
)
CONTRASTS = (
    Contrast("suspension", "static", "derived"),
    Contrast("suspension", "static", "planned"),
)
SECONDARY = (
    "people.time_to_help_s.mean", "suspensions.time_to_safe_s.mean", "suspensions.unsafe",
    "suspensions.inapplicable_stages", "safety.after_end_s", "safety.unowned_s", "safety.severity_unattended_s",
    "totals.static_fallbacks", "totals.failed", "totals.unfinished",
)
"""Described per cell and as paired differences with bootstrap intervals; never tested, never a verdict."""

DECLARATION = """\
*Declared before running: this section was committed before any run of the experiment
existed, and `experiments/sweep/experiment.py` keeps it word for word.*

## The question

Where does planning the suspension make a task safer when it is interrupted, and where does
it not? Three ways to build genSusp's FSM (`exeSusp`) are compared on the same randomised
variants: **static** (run the stages of the first-match `[[suspension]]` branch of the task
folder), **planned** (plan, from the state as it is, to that branch's goal) and **derived**
(plan to the goal the task folder's declarations give: every hazard the task owns off,
its person in a declared safe role, its declared invariants). Method (static vs planned)
and goal source (the tree vs the declarations) are thus separate contrasts.

## Design

`experiments/sweep/specs/strategies.toml`: suspension {static, planned, derived}, with
`update = planned`, `policy = strict` and hazard-aware waiting off throughout (one factor
changes per contrast). Scenarios: **household** (cook interrupted by a guide request and
Peter's fall), **carry** (a vase carried through a door; Anna falls), **paper** (the paper's
four tasks), **compound** (carry and cook interleaved; Anna falls while cook holds the pan
or has the cooker on) and **water_plants** (a user-style task folder,
`experiments/sweep/specs/tasks/water_plants`, whose `[[suspension]]` tree forgets the tap
it turns on: a known blind spot of the tree, included to measure what each strategy does
with it — its result for derived is expected by construction and is reported as such).
Each seed is one randomised variant, the same for the three strategies: request times
jittered, people moved, the interrupting request placed in the seed's stratum of a grid
over the interrupted task's stages (`[variants]`).

Two arms. **Perturbed** (primary): the spec's `[perturbation]` draws exogenous world events
from the world's own vocabulary — a door opened or closed, a task's object moved, a device
switched, a bystander standing in a doorway — at 3 a minute in a window from 20 s before to
60 s after the interruption (rates fixed here, before any run). **Control**: the same
variants without them, 30 seeds.

## Primary outcomes and the family

1. `suspensions.all_safe` (binary, per run): every suspension of the run was *safe* — at the
   agent's entry into `wait` no hazard it owns is on, and every stage it executed was
   applicable. Exact McNemar test.
2. `safety.unattended_alive_s` (seconds): time a declared hazard was on while its owner was
   alive and did not hold the robot (time after the owner ended is a task-design defect,
   reported apart as `safety.after_end_s`). Wilcoxon signed-rank test; effect = mean paired
   difference with a paired bootstrap 95 % interval.

The family: 5 scenarios × 2 contrasts (derived − static, planned − static) × 2 outcomes = 20
tests, Holm-adjusted together at family-wise α = 0.05. Every declared test stays in the
family whatever the data (identical runs give p = 1). No verdict below 10 informative pairs
(discordant, or a non-zero difference): "too few pairs". The control arm is analysed the same
way as a second, separate family of 20.

## Size

A pilot of the perturbed arm's first 20 seeds fixes n per scenario: for each of its four
tests, the pairs needed for 80 % power at α = 0.05 / 20 — binary: Connor's approximation
from the pilot's discordant share and difference in proportions; seconds: the pilot's SD of
the paired differences against a difference of 30 s (the shortest hazard budget of the
bundled folders) — and n = the largest of the four, at least 100 and at most 200 (the
machine's budget); where a test needs more than 200 the document says it is underpowered.
The pilot's runs are the first seeds of the final sample (an internal pilot: it is used
for variances only).

## Secondary (described, not tested)

Time-to-help, time to a safe state, unsafe suspensions, inapplicable stages, unattended time
after the owner ended, exposure to hazards nobody owns, severity-weighted unattended time,
planner fallbacks to static (a run that had any is counted and named), failed and
unfinished tasks; Alg. 2's decision margins per cell and how many decisions a hysteresis of
0.85, 0.9, 0.95 or 1.0 would flip.
"""


@dataclass(frozen=True)
class Plan:
    """The pilot's sizes and the seeds per scenario they fix."""

    sizes: tuple[Size, ...]
    n: dict[str, int]

    def underpowered(self) -> list[Size]:
        return [s for s in self.sizes if s.required is not None and s.required > self.n[s.scenario]]


def fixed_n(sizes: Sequence[Size], scenarios: Sequence[str]) -> dict[str, int]:
    """Seeds per scenario: the largest pair count its tests need, clamped to [MIN_N, MAX_N]."""
    out = {}
    for sc in scenarios:
        need = [s.required for s in sizes if s.scenario == sc and s.required is not None]
        out[sc] = min(MAX_N, max(MIN_N, max(need, default=MIN_N)))
    return out


def load(root: Path = ROOT) -> SweepSpec:
    return load_spec(root / SPEC)


def seeds(spec: SweepSpec, count: int) -> tuple[int, ...]:
    if count > len(spec.seeds):
        raise ValueError(f"{count} seeds asked, the spec has {len(spec.seeds)}")
    return spec.seeds[:count]


def pilot_jobs(spec: SweepSpec) -> list[Job]:
    return dataclasses.replace(spec, seeds=seeds(spec, PILOT_SEEDS)).jobs()


def perturbed_jobs(spec: SweepSpec, n: dict[str, int]) -> list[Job]:
    return [j for j in spec.jobs() if j.seed in spec.seeds[:n.get(j.scenario, MIN_N)]]


def control_jobs(spec: SweepSpec) -> list[Job]:
    return dataclasses.replace(arm(spec, perturbed=False), seeds=seeds(spec, CONTROL_SEEDS)).jobs()


def rows_of(db: str | Path, jobs: Sequence[Job]) -> list[RunRow]:
    """The stored runs of ``jobs`` (a database may hold more)."""
    if not Path(db).is_file():
        return []
    keys = {j.key for j in jobs}
    with ResultStore(db, readonly=True) as store:
        return [r for r in store.rows() if r.key in keys]


def size(spec: SweepSpec, db: str | Path) -> Plan:
    """The plan the pilot's stored runs give."""
    rows = rows_of(db, pilot_jobs(spec))
    sizes = pilot_sizes(rows, spec.scenarios, CONTRASTS, OUTCOMES)
    return Plan(tuple(sizes), fixed_n(sizes, spec.scenarios))


@dataclass(frozen=True)
class Progress:
    """What :func:`run` did in each step."""

    pilot: SweepSummary | None
    perturbed: SweepSummary | None
    control: SweepSummary | None


def run(spec: SweepSpec, *, db: str | Path = DB, control_db: str | Path = CONTROL_DB, workers: int = 1,
        limit: int | None = None, pilot_only: bool = False, progress: bool = False) -> tuple[Plan, Progress]:
    """Steps 1-3 (each resumable); ``limit`` caps the runs started by this call over all steps."""
    left = limit

    def step(jobs: list[Job], where: str | Path) -> SweepSummary | None:
        nonlocal left
        if left is not None and left <= 0:
            return None
        Path(where).parent.mkdir(parents=True, exist_ok=True)
        summary = run_sweep(jobs, where, workers=workers, max_jobs=left, progress=progress)
        if left is not None:
            left -= summary.ran
        return summary

    pilot = step(pilot_jobs(spec), db)
    plan = size(spec, db)
    if pilot_only or (pilot is not None and pilot.not_run):
        return plan, Progress(pilot, None, None)
    perturbed = step(perturbed_jobs(spec, plan.n), db)
    control = step(control_jobs(spec), control_db)
    return plan, Progress(pilot, perturbed, control)


__all__ = ["CONTRASTS", "DECLARATION", "OUTCOMES", "SECONDARY", "Plan", "fixed_n", "run", "size"]
