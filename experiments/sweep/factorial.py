"""``python -m experiments.sweep.factorial``: run the factorial sweep and regenerate ``docs/results.md`` from it.

One command, three steps, each resumable:

1. ``tasker sweep SPEC --db DB --workers N`` (:func:`experiments.sweep.driver.run_sweep`): only the runs
   the database does not hold yet are run;
2. ``tasker report --db DB --out OUT`` (:func:`experiments.sweep.report.build_report`): every metric,
   CSV files and plots;
3. ``docs/results.md``: the declaration (:data:`DECLARATION`, written before any run and kept
   word for word), then tables and sentences computed from the database alone — per scenario,
   paired by seed, Holm-adjusted over the family of tests the document shows, failed /
   unfinished / infeasible counted apart, constant metrics dropped.  No number in it is typed:
   the same database gives the same file, byte for byte (no date, no host).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path

from experiments.analysis.compare import INFEASIBLE, Paired, PrimaryOutcome, constant_metrics, paired
from experiments.analysis.stats import ALPHA, Estimate, estimate, holm
from experiments.analysis.tables import markdown_table
from experiments.inputs.strategy import Strategy
from experiments.metrics.registry import host_dependent, numeric_metrics
from experiments.metrics.store import ResultStore, RunRow, Status
from experiments.sweep.driver import run_sweep
from experiments.sweep.report import build_report
from experiments.sweep.spec import SweepSpec, load_spec

ROOT = Path(__file__).resolve().parents[2]
SPEC = "experiments/sweep/specs/factorial.toml"
DB = "out/factorial.db"
OUT = "out/factorial-report"
MARKDOWN = "docs/results.md"
NOTES = "experiments/sweep/specs/factorial-notes.md"
"""Hand-written notes from reading the traces, included verbatim after the generated findings (no numbers)."""

PRIMARY = PrimaryOutcome()
HAZARD, HELP = PRIMARY.hazard[0], PRIMARY.help[0]

TESTED = (
    HAZARD, HELP, "safety.budget_overruns", "safety.overrun_s", "safety.violations_at_switch",
    "people.people_waiting_s", "derived.finished_duration_s.mean", "totals.suspension_s.mean",
    "totals.failed", "totals.unfinished",
)
"""The metrics this document tests: the primary pair first, then the declared secondary ones.  Holm's
family is every (factor comparison, scenario, metric) test of these."""

LABELS = {
    HAZARD: "hazard unattended (s)", HELP: "time to help (s)", "safety.budget_overruns": "budget overruns",
    "safety.overrun_s": "overrun (s)", "safety.violations_at_switch": "own hazards left on at a switch",
    "people.people_waiting_s": "people waiting (s)", "derived.finished_duration_s.mean": "duration, finished (s)",
    "totals.suspension_s.mean": "suspension (s)", "totals.failed": "failed tasks", "totals.unfinished":
    "unfinished tasks",
}

AFTER_END = "safety.after_end_s"
"""Shown beside the hazard coordinate, descriptive only (not in Holm's family): unattended time no suspension
or waiting could attend to, because the hazard's task had ended."""

FACTOR_ORDER = ("suspension", "policy", "hazard_waiting")

DECLARATION = """\
*Declared before running (this section is committed before any number of the sweep
below exists; `experiments/sweep/factorial.py` keeps it word for word).*

## Design

`experiments/sweep/specs/factorial.toml`: a full factorial over the robot scenarios —
**suspension** {static, planned} × **policy** {strict, conditional} ×
**hazard-aware waiting** {off, on}, `update = planned` throughout — on **household**
(cook interrupted by a guide request and by Peter's fall), **carry** (a vase carried
through a door; Anna falls), **paper** (the paper's four tasks) and **compound**
(`experiments/sweep/specs/scenarios/compound.toml`: the carry task holds the vase with the
door open when cook is requested; Anna falls while cook holds the pan or has the cooker
on). Each seed is one randomised variant, the same for all eight cells (so every
comparison is paired by seed): request times jittered, every person moved — also those
defined only in the world file — and the interrupting request placed in the seed's
stratum of a grid that spans every stage of the interrupted task (`[variants]` in the
spec).

## Primary outcome

Per scenario and cell, the pair (**hazard-unattended seconds**, `safety.unattended_s`:
time a declared hazard was on while its task did not own the robot; **time-to-help**,
`people.time_to_help_s.mean`: request → first `helped` of the people who need help).
Neither is traded against the other in a single score: the report shows the frontier
(`plots/primary_frontier.png`) and, for each factor, the paired difference of each
coordinate. **The primary question**: with identical suspension goals (the goals come
from one `[[suspension]]` list, so static and planned differ only in method), is planned
suspension ever less safe than static, and what does it cost in time-to-help?

## Analysis

Per scenario, never pooled. Each factor's two levels are compared holding the other
factors fixed, paired by seed: mean difference with its 95 % Student-t CI, wins / ties
/ losses, the paired t-test's p-value, Holm-adjusted over the family of every test this
document shows (the metrics named here × every factor comparison × every scenario;
family-wise α = 0.05). `tasker report` also writes every other metric, Holm-adjusted
over its own, larger family (`out/factorial-report/`). Failed tasks, unfinished tasks and infeasible or errored runs are
counted separately and never enter a duration mean; a metric constant over every run is
dropped with a note; non-finite values are counted, never averaged. Secondary: budget
overruns, hazards left on at a switch, people's waiting, task durations over finished
tasks, and the estimate calibration (`calibration.*`, `docs/metrics.md`).

Hazard-aware waiting is being implemented by another engineer in parallel: if it is
still a no-op in the code that ran, its on/off factor can show no effect, and the text
says so.
"""


# ----------------------------------------------------------------------------------------- helpers


def _fmt(x: float) -> str:
    if math.isnan(x):
        return "–"
    return f"{x:.3g}" if abs(x) < 1000 else f"{x:.0f}"


def _ci(e: Estimate) -> str:
    """``mean ± half (n)``, or ``– (0)``."""
    if e.n == 0:
        return "– (0)"
    half = "" if math.isnan(e.half) else f" ± {_fmt(e.half)}"
    return f"{_fmt(e.mean)}{half} (n {e.n})"


def _table(header: Sequence[str], body: Iterable[Sequence[str]]) -> list[str]:
    return [*markdown_table(header, body), ""]


def _name(scenario: str) -> str:
    return Path(scenario).stem


def _factors(label: str) -> dict[str, str]:
    return {k: ("on" if v else "off") if isinstance(v, bool) else str(v)
            for k, v in Strategy.parse(label).items()}


def _cell(label: str, without: str = "") -> str:
    """A strategy label in short: ``static/strict/off`` (suspension/policy/hazard waiting), leaving out
    the factor ``without``."""
    f = _factors(label)
    return "/".join(f.get(k, "·") for k in FACTOR_ORDER if k != without)


def _verdict(p: Paired) -> str:
    if p.wins == p.losses == 0:
        return "identical"
    if math.isnan(p.p_holm):
        return "too few pairs"
    if p.p_holm >= ALPHA:
        return "no significant difference"
    return "treatment better" if (p.diff.mean < 0) == (p.better == "lower") else "baseline better"


def _levels(dim: str, p: Paired) -> tuple[str, str]:
    return _factors(p.treatment)[dim], _factors(p.baseline)[dim]


# ----------------------------------------------------------------------------------------- analysis


def tested_pairs(rows: Sequence[RunRow]) -> tuple[list[Paired], list[Paired], dict[str, float]]:
    """(the pairs of :data:`TESTED`, Holm-adjusted over exactly them; every pair; the constant metrics)."""
    constant = constant_metrics(rows)
    every = paired(rows, drop=constant)
    mine = [p for p in every if p.metric in TESTED and p.dimension in FACTOR_ORDER]
    adjusted = holm([p.p for p in mine])
    return ([Paired(p.dimension, p.treatment, p.baseline, p.scenario, p.metric, p.diff, p.wins, p.ties, p.losses,
                    p.nonfinite, p.p, a) for p, a in zip(mine, adjusted, strict=True)], every, constant)


def _runs_table(rows: Sequence[RunRow], scenarios: Sequence[str], strategies: Sequence[str]) -> list[str]:
    body = []
    for sc in scenarios:
        for st in strategies:
            mine = [r for r in rows if (r.scenario, r.strategy) == (sc, st)]
            ok = [numeric_metrics(r.metrics) for r in mine if r.status is Status.OK]
            errors = [r for r in mine if r.status is Status.ERROR]
            infeasible = sum(1 for r in errors if INFEASIBLE.search(r.error or ""))
            body.append([_name(sc), _cell(st), str(len(ok)), str(infeasible), str(len(errors) - infeasible),
                         f"{sum(f.get('totals.failed', 0.0) for f in ok):.0f}",
                         f"{sum(f.get('totals.unfinished', 0.0) for f in ok):.0f}",
                         f"{sum(f.get('run.horizon_reached', 0.0) for f in ok):.0f}",
                         f"{sum(f.get('people.not_helped', 0.0) for f in ok):.0f}"])
    return _table(["scenario", "suspension/policy/hazard waiting", "ok runs", "infeasible runs", "errored runs",
                   "failed tasks", "unfinished tasks", "runs cut by the horizon", "people never helped"], body)


def _values(rows: Sequence[RunRow], sc: str, st: str, metric: str) -> tuple[list[float], int]:
    vals = [numeric_metrics(r.metrics).get(metric) for r in rows
            if (r.scenario, r.strategy) == (sc, st) and r.status is Status.OK]
    present = [v for v in vals if v is not None]
    return [v for v in present if math.isfinite(v)], sum(1 for v in present if not math.isfinite(v))


def _primary_table(rows: Sequence[RunRow], sc: str, strategies: Sequence[str]) -> list[str]:
    body = []
    for st in strategies:
        h, hn = _values(rows, sc, st, HAZARD)
        w, wn = _values(rows, sc, st, HELP)
        o, _ = _values(rows, sc, st, "safety.budget_overruns")
        a, _ = _values(rows, sc, st, AFTER_END)
        body.append([_cell(st), _ci(estimate(h)) + (f", {hn} non-finite" if hn else ""),
                     _ci(estimate(a)) if a else "not measured", _ci(estimate(w)) + (f", {wn} non-finite" if wn else ""),
                     f"{sum(1 for v in o if v > 0)} of {len(o)}"])
    return _table(["suspension/policy/hazard waiting", "hazard unattended (s)",
                   "of which after its task ended (s)", "time to help (s)", "runs with a budget overrun"], body)


def _p(p: float) -> str:
    return "–" if math.isnan(p) else "<0.001" if p < 0.001 else f"{p:.3f}"


def _effect_table(pairs: Sequence[Paired], dim: str, sc: str, constant: Mapping[str, float]) -> list[str]:
    mine = [p for p in pairs if p.dimension == dim and p.scenario == sc]
    if not mine:
        return []
    contexts = sorted({_cell(p.treatment, without=dim) for p in mine})
    cells = {(_cell(p.treatment, without=dim), p.metric): p for p in mine}
    body = []
    for metric in TESTED:
        if metric in constant:
            body.append([LABELS[metric], *(f"constant ({_fmt(constant[metric])} in every run)" for _ in contexts)])
            continue
        if not any(q.metric == metric for q in mine):
            continue  # no run of this scenario has it
        row = [LABELS[metric]]
        for c in contexts:
            p = cells.get((c, metric))
            if p is None:
                row.append("–")
                continue
            extra = f", {p.nonfinite} non-finite" if p.nonfinite else ""
            row.append(f"{_ci(p.diff)}{extra}; {p.wins}/{p.ties}/{p.losses}; p_H {_p(p.p_holm)}")
        body.append(row)
    t, b = _levels(dim, mine[0])
    others = "/".join(k.replace("_", " ") for k in FACTOR_ORDER if k != dim)
    return [f"{dim.replace('_', ' ')} = {t} − {dim.replace('_', ' ')} = {b}, by {others} "
            "(difference ± 95 % CI (pairs); wins/ties/losses of "
            f"{t}; Holm-adjusted p):", "", *_table(["metric", *contexts], body)]


def _sentence(p: Paired) -> str:
    return (f"{_ci(p.diff)}, {p.wins}/{p.ties}/{p.losses}, p_H {_p(p.p_holm)}: {_verdict(p)}"
            .replace("treatment better", f"{_levels(p.dimension, p)[0]} better")
            .replace("baseline better", f"{_levels(p.dimension, p)[1]} better"))


def _findings(rows: Sequence[RunRow], pairs: Sequence[Paired], every: Sequence[Paired],
              scenarios: Sequence[str]) -> list[str]:
    out = ["## What it shows", "",
           "Generated from the runs: for each scenario, planned − static on the primary pair, in each "
           "policy/hazard-waiting context (difference ± 95 % CI (pairs), wins/ties/losses of planned, Holm p).",
           ""]
    for sc in scenarios:
        mine = [p for p in pairs if p.dimension == "suspension" and p.scenario == sc and p.metric in (HAZARD, HELP)]
        out.append(f"* **{_name(sc)}**")
        if not mine:
            out.append("  no paired runs (or both metrics constant).")
            continue
        helps, hurts = [], []
        for p in sorted(mine, key=lambda p: (p.metric != HAZARD, _cell(p.treatment, without="suspension"))):
            ctx = _cell(p.treatment, without="suspension")
            out.append(f"  * {LABELS[p.metric]}, {ctx}: {_sentence(p)}")
            v = _verdict(p)
            if v == "treatment better":
                helps.append(f"{LABELS[p.metric]} ({ctx})")
            elif v == "baseline better":
                hurts.append(f"{LABELS[p.metric]} ({ctx})")
        worse = [w for w in worse_outcomes(rows) if w[0] == sc]
        if worse:
            n_planned = sum(1 for r in rows if r.scenario == sc and r.status is Status.OK
                            and _factors(r.strategy).get("suspension") == "planned")
            out.append(f"  * planned left more people never helped, or failed more tasks, than static in "
                       f"{len(worse)} of {n_planned} planned runs — see *Where planned was less safe* below.")
        less_safe = [p for p in mine if p.metric == HAZARD and p.losses > 0]
        if helps:
            out.append(f"  * planning the suspension **helps** (Holm-significant): {', '.join(helps)}.")
        if hurts:
            out.append(f"  * planning the suspension **hurts** (Holm-significant): {', '.join(hurts)}.")
        if not helps and not hurts:
            out.append("  * no Holm-significant difference between planned and static on the primary pair; "
                       "the CIs above bound the effect.")
        if less_safe:
            out.append("  * planned left a hazard unattended longer than static in "
                       + "; ".join(f"{p.losses} of {p.diff.n} seeds ({_cell(p.treatment, without='suspension')})"
                                   for p in less_safe) + " — see *Where planned was less safe* below.")
        else:
            out.append("  * planned never left hazards unattended longer than static here (in no seed).")
    out.append("")
    hw = [p for p in every if p.dimension == "hazard_waiting" and not host_dependent(p.metric)]
    on_runs = [numeric_metrics(r.metrics) for r in rows
               if r.status is Status.OK and _factors(r.strategy).get("hazard_waiting") == "on"]
    secured = [sum(v for k, v in f.items() if k.startswith("decisions.decisions_by.") and k.endswith("/secure"))
               for f in on_runs]
    acts = (f"With it on, the harmoniser made {sum(secured):.0f} securing decisions (`decision` rule `secure`) in "
            f"{sum(1 for x in secured if x > 0)} of {len(on_runs)} runs.")
    if hw and all(p.wins == p.losses == 0 for p in hw):
        out += ["**Hazard-aware waiting changed nothing in these runs**: on and off gave identical values of every "
                f"metric in every one of the {len({(p.scenario, p.treatment) for p in hw})} paired cells "
                f"(scenario × context). {acts}"
                + (" No waiting task's hazard came near its budget in these variants, or hazard-aware waiting was "
                   "not active in the code that ran (it was implemented by another engineer while this experiment "
                   "was set up); the budget overruns in the primary tables are then hazards no waiting can attend "
                   "to (`safety.after_end_s`: their task had ended)." if sum(secured) == 0 else ""), ""]
    elif hw:
        out += [f"Hazard-aware waiting changed some runs: its paired effects are in the tables below. {acts}", ""]
    return out


def worse_outcomes(rows: Sequence[RunRow]) -> list[tuple[str, str, int, dict[str, float], dict[str, float], str]]:
    """Every (scenario, planned cell, seed) where planned suspension left more people never helped or more
    tasks failed than static in the same variant: ``(scenario, label, seed, planned, static, reasons)``."""
    by = {(r.scenario, r.strategy, r.seed): r for r in rows if r.status is Status.OK}
    out = []
    for (sc, st, seed), r in sorted(by.items()):
        if _factors(st).get("suspension") != "planned":
            continue
        base = Strategy(**{**dict(Strategy.parse(st).items()), "suspension": "static"}).label
        b = by.get((sc, base, seed))
        if b is None:
            continue
        m, bm = numeric_metrics(r.metrics), numeric_metrics(b.metrics)
        keys = ("people.not_helped", "totals.failed")
        if any(m.get(k, 0.0) > bm.get(k, 0.0) for k in keys):
            totals = r.metrics.get("totals", {})
            reasons = totals.get("failure_reasons", []) if isinstance(totals, dict) else []
            out.append((sc, st, seed, {k: m.get(k, 0.0) for k in keys}, {k: bm.get(k, 0.0) for k in keys},
                        "; ".join(str(x) for x in reasons)))
    return out


def _worse_outcomes(rows: Sequence[RunRow]) -> list[str]:
    worse = worse_outcomes(rows)
    if not worse:
        return ["In no scenario, context or seed did planned suspension leave more people unhelped or fail more "
                "tasks than static.", ""]
    body = [[_name(sc), _cell(st, without="suspension"), str(seed),
             f"{b['people.not_helped']:.0f} / {b['totals.failed']:.0f}",
             f"{m['people.not_helped']:.0f} / {m['totals.failed']:.0f}", why[:300]]
            for sc, st, seed, m, b, why in worse]
    return ["Seeds where planned suspension left more people never helped, or failed more tasks, than static in "
            "the same variant (the time-to-help means above leave such people out: they were never helped):", "",
            *_table(["scenario", "policy/hazard waiting", "seed", "static: never helped / failed",
                     "planned: never helped / failed", "planned's failure reasons"], body)]


def _household_check(rows: Sequence[RunRow], scenarios: Sequence[str]) -> list[str]:
    sc = next((s for s in scenarios if _name(s) == "household"), None)
    if sc is None:
        return []
    out = ["## Household, conditional policy: hazards past their budget", "",
           "Runs (of the ok runs) in which some hazard stayed unattended past its budget "
           "(`safety.budget_overruns` > 0), and the total overrun; the issue asks that with hazard-aware "
           "waiting on there be none.", ""]
    body = []
    for st in sorted({r.strategy for r in rows if r.scenario == sc}):
        f = _factors(st)
        if f.get("policy") != "conditional":
            continue
        o, _ = _values(rows, sc, st, "safety.budget_overruns")
        s, _ = _values(rows, sc, st, "safety.overrun_s")
        body.append([f.get("suspension", "·"), f.get("hazard_waiting", "·"),
                     f"{sum(1 for v in o if v > 0)} of {len(o)}", _ci(estimate(s))])
    return out + _table(["suspension", "hazard waiting", "runs with an overrun", "overrun (s)"], body)


def _less_safe(rows: Sequence[RunRow], scenarios: Sequence[str]) -> list[str]:
    """Every (scenario, context, seed) where planned's hazard-unattended time exceeds static's, with the
    hazards whose unattended time grew."""
    flat: dict[tuple[str, str, int], dict[str, float]] = {
        (r.scenario, r.strategy, r.seed): numeric_metrics(r.metrics) for r in rows if r.status is Status.OK}
    lines = []
    for (sc, st, seed), m in sorted(flat.items()):
        f = _factors(st)
        if f.get("suspension") != "planned":
            continue
        other = Strategy.parse(st)
        base = Strategy(**{**{k: v for k, v in other.items()}, "suspension": "static"}).label
        b = flat.get((sc, base, seed))
        if b is None or HAZARD not in m or HAZARD not in b:
            continue
        if m[HAZARD] > b[HAZARD] + 1e-6:
            grew = sorted(k.split(".")[2] for k in m if k.startswith("safety.hazards.") and k.endswith(".unattended_s")
                          and m[k] > b.get(k, 0.0) + 1e-6)
            lines.append([_name(sc), _cell(st, without="suspension"), str(seed), _fmt(b[HAZARD]), _fmt(m[HAZARD]),
                          ", ".join(grew) or "–"])
    out = ["## Where planned was less safe", ""]
    out += _worse_outcomes(rows)
    if not lines:
        return out + ["In no scenario, context or seed did planned suspension leave hazards unattended longer "
                      "than static.", ""]
    out += ["Each seed where planned suspension left hazards unattended longer than static in the same "
            "variant, with the hazards whose unattended time grew. Replay one, with every output of `tasker run`: "
            "`python -m experiments.sweep.factorial --replay SCENARIO SEED planned/POLICY/WAITING "
            "--out out/replay`.", ""]
    return out + _table(["scenario", "policy/hazard waiting", "seed", "static (s)", "planned (s)", "hazards"], lines)


def _calibration(rows: Sequence[RunRow], scenarios: Sequence[str]) -> list[str]:
    out = ["## Calibration of the estimates (descriptive, no test)", "",
           "Over every ok run of each scenario (all cells): each task's cTime at its first start against the time "
           "it then owned the robot, for tasks that finished; each suspension's expected interruption "
           "(`expected_s`) against the realised one (wait → next start). Error = realised − estimate (positive: "
           "the estimate was too short). Definitions: `docs/metrics.md`, `calibration`.", ""]
    body = []
    for sc in scenarios:
        ok = [numeric_metrics(r.metrics) for r in rows if r.scenario == sc and r.status is Status.OK]
        if not ok:
            continue

        def col(metric: str, ok: list[dict[str, float]] = ok) -> list[float]:
            return [f[metric] for f in ok if metric in f and math.isfinite(f[metric])]

        def tot(metric: str, ok: list[dict[str, float]] = ok) -> int:
            return int(sum(f.get(metric, 0.0) for f in ok))

        body.append([_name(sc),
                     _ci(estimate(col("calibration.estimates.error_s.mean"))),
                     _ci(estimate(col("calibration.estimates.abs_error_s.mean"))),
                     f"{tot('calibration.estimates.underestimated')} of {tot('calibration.estimates.compared')}",
                     str(tot("calibration.estimates.not_compared")),
                     str(tot("calibration.estimates.nonfinite")),
                     _ci(estimate(col("calibration.interruptions.error_s.mean"))),
                     f"{tot('calibration.interruptions.underestimated')} of "
                     f"{tot('calibration.interruptions.compared')}",
                     str(tot("calibration.interruptions.censored"))])
    return out + _table(["scenario", "cTime error, run mean (s)", "cTime abs error (s)", "tasks underestimated",
                         "tasks not compared", "infinite cTime at start", "interruption error, run mean (s)",
                         "interruptions underestimated", "censored"], body)


def render(rows: Sequence[RunRow], command: str, notes: str = "") -> str:
    """``docs/results.md`` from the stored runs (deterministic: same rows, same text)."""
    import tasker

    scenarios = sorted({r.scenario for r in rows}, key=lambda s: (_name(s) != "household", _name(s) != "carry",
                                                                   _name(s)))
    strategies = sorted({r.strategy for r in rows}, key=lambda s: [_factors(s).get(k, "") for k in FACTOR_ORDER])
    ok = [r for r in rows if r.status is Status.OK]
    pairs, every, constant = tested_pairs(rows)
    versions = sorted({str(r.record.get("tasker_version", "?")) for r in ok})
    out = ["# Static versus planned suspension: results", "",
           "Regenerate (the sweep resumes: only runs missing from the database are run, on one worker unless "
           "`--workers N` says more; the runs "
           f"below took {_fmt(math.fsum(r.wall or 0.0 for r in rows) / 60)} minutes of worker wall time on a "
           "shared machine):", "", "```bash", command, "```", "",
           DECLARATION.rstrip(), "",
           "## The runs", "",
           f"{len(rows)} runs ({len(ok)} ok): {len(scenarios)} scenarios × {len({r.seed for r in rows})} seeds × "
           f"{len(strategies)} cells; tasker {', '.join(versions) or tasker.__version__}. Seeds "
           f"{', '.join(str(s) for s in sorted({r.seed for r in rows}))}. Failed and unfinished tasks are counted "
           "here and never enter a duration mean; infeasible runs (no plan) and errored runs are counted apart.", "",
           *_runs_table(rows, scenarios, strategies)]
    if constant:
        shown = [m for m in constant if m in TESTED or m.startswith(("safety.", "people.", "calibration."))]
        out += ["Dropped as constant over every run (no information): "
                + ", ".join(f"`{m}` = {_fmt(constant[m])}" for m in shown) + (
                    f" (and {len(constant) - len(shown)} more, listed in the report)" if len(constant) > len(shown)
                    else "") + ".", ""]
    out += _findings(rows, pairs, every, scenarios)
    if notes.strip():
        out += [notes.strip(), ""]
    out += ["## Primary outcome per cell", "",
            "Mean ± 95 % CI (runs) of each coordinate, and the part of the hazard time that came after the "
            "hazard's task had ended (`safety.after_end_s`, descriptive, not tested); the frontier is "
            "`out/factorial-report/plots/primary_frontier.png`.", ""]
    for sc in scenarios:
        out += [f"### {_name(sc)}", "", *_primary_table(rows, sc, strategies)]
    out += _less_safe(rows, scenarios)
    out += _household_check(rows, scenarios)
    n_tests = sum(1 for p in pairs if not math.isnan(p.p))
    out += ["## Paired effects of each factor", "",
            f"Holm's family: the {n_tests} paired t-tests in the tables below (metrics × factor comparisons × "
            f"scenarios; pairs with no difference or n < 2 have no test). α = {ALPHA}.", ""]
    for dim in FACTOR_ORDER:
        for sc in scenarios:
            table = _effect_table(pairs, dim, sc, constant)
            if table:
                out += [f"### {dim.replace('_', ' ')} — {_name(sc)}", "", *table]
    out += _calibration(rows, scenarios)
    return "\n".join(out).rstrip() + "\n"


def replay(spec: SweepSpec, scenario: str, seed: str, cell: str, *, out: Path) -> int:
    """Run the job ``(scenario, seed, cell)`` of ``spec`` again — the same variant, interruption grid
    included — and write every output of ``tasker run`` into ``out``."""
    from experiments.run.runner import run_scenario

    by_name = {_name(sc): sc for sc in spec.scenarios}
    if scenario not in by_name:
        print(f"python -m experiments.sweep.factorial: --replay: no scenario {scenario!r} in the spec "
              f"(scenarios: {', '.join(sorted(by_name))})", file=sys.stderr)
        return 2
    jobs = {(str(j.seed), _cell(j.strategy.label)): j for j in spec.jobs() if j.scenario == by_name[scenario]}
    job = jobs.get((seed, cell))
    if job is None:
        cells = sorted({c for _, c in jobs})
        print(f"python -m experiments.sweep.factorial: --replay: no job {scenario} seed {seed} cell {cell!r} "
              f"(seeds: {', '.join(sorted({s for s, _ in jobs}, key=int))}; cells: {', '.join(cells)})",
              file=sys.stderr)
        return 2
    st = job.strategy
    run_scenario(job.source, seed=job.seed, update=st.update, suspension=st.suspension, scheduler=st.scheduler,
                 randomize=True, task_paths=job.task_paths, policy=st.policy, hazard_waiting=st.hazard_waiting,
                 interruption=job.interruption, out=out)
    print(f"wrote {out}/ ({scenario}, seed {seed}, {st.label})")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m experiments.sweep.factorial", description=__doc__.splitlines()[0])
    ap.add_argument("--spec", default=SPEC, help=f"sweep spec (default {SPEC})")
    ap.add_argument("--db", default=DB, help=f"results database (default {DB})")
    ap.add_argument("--out", default=OUT, help=f"report folder (default {OUT})")
    ap.add_argument("--markdown", default=MARKDOWN, help=f"the document to write (default {MARKDOWN})")
    ap.add_argument("--workers", type=int, default=1, help="local worker processes (default 1)")
    ap.add_argument("--seeds", type=int, default=None, metavar="N",
                    help="only the spec's first N seeds (a smaller run for a busy machine)")
    ap.add_argument("--replay", nargs=3, metavar=("SCENARIO", "SEED", "CELL"), default=None,
                    help="run one job of the spec again with every output (trace, report.html, plots) into --out: "
                         "SCENARIO as in the tables (e.g. compound), SEED, CELL as suspension/policy/hazard waiting "
                         "(e.g. planned/strict/off)")
    ap.add_argument("--no-run", action="store_true", help="do not run missing jobs; report what the database holds")
    args = ap.parse_args(argv)
    from tasker.support.reader import InputError

    try:
        spec = load_spec(args.spec)
    except InputError as exc:
        print(f"python -m experiments.sweep.factorial: {exc}", file=sys.stderr)
        return 2
    if args.replay is not None:
        return replay(spec, *args.replay, out=Path(args.out))
    if args.seeds is not None:
        if not 1 <= args.seeds <= len(spec.seeds):
            print(f"python -m experiments.sweep.factorial: --seeds: expected 1..{len(spec.seeds)}, got {args.seeds}",
                  file=sys.stderr)
            return 2
        spec = dataclasses.replace(spec, seeds=spec.seeds[:args.seeds])
    if not args.no_run:
        Path(args.db).parent.mkdir(parents=True, exist_ok=True)
        run_sweep(spec, args.db, workers=args.workers, progress=False)
    build_report(args.db, args.out)
    with ResultStore(args.db, readonly=True) as store:
        keys = {j.key for j in spec.jobs()}
        rows = [r for r in store.rows() if (r.scenario, r.seed, r.strategy) in keys]
    given = argv if argv is not None else sys.argv[1:]
    command = " ".join(["python -m experiments.sweep.factorial", *(a for a in given if a != "--no-run")]).strip()
    notes = ROOT / NOTES
    text = render(rows, command, notes.read_text(encoding="utf-8") if notes.is_file() else "")
    Path(args.markdown).write_text(text, encoding="utf-8")
    print(f"wrote {args.markdown} ({len(rows)} runs) and {args.out}/")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())


__all__ = ["DECLARATION", "TESTED", "main", "render", "tested_pairs"]
