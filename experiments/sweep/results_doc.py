"""``docs/results.md`` from the stored runs of the suspension-strategy experiment.

Everything after the declaration is computed from the arms' results databases alone: the same runs
give the same text, byte for byte (no date, no host; the commit and the trace digests of the
provenance block are passed in).  Per cell (a scenario with one of its trees), never pooled except
where the declaration pools (H1, H2); the declared families of :mod:`experiments.sweep.experiment`
and nothing else are tested.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Mapping, Sequence
from pathlib import Path

from experiments.analysis.compare import INFEASIBLE
from experiments.analysis.family import MIN_PAIRS, Contrast, Test, run_family
from experiments.analysis.paired_tests import BOOTSTRAP, bootstrap_interval
from experiments.analysis.stats import ALPHA, estimate
from experiments.analysis.tables import markdown_table
from experiments.inputs.strategy import Strategy
from experiments.metrics.registry import label, numeric_metrics
from experiments.metrics.store import RunRow, Status
from experiments.sweep import experiment as ex
from experiments.sweep.provenance import Provenance
from experiments.sweep.provenance import render as render_provenance

SHOW_LOSSES = 12
"""Seeds listed per cell and contrast where the treatment was less safe (the rest are counted)."""
LEVELS = ("static", "planned", "derived", "fallback")
SAFE = ex.OUTCOMES[0].metric


def _name(cell: str) -> str:
    sc, _, tree = cell.rpartition(" [")
    return f"{Path(sc).stem} [{tree}" if sc else Path(cell).stem


def _susp(label_: str) -> str:
    return str(Strategy.parse(label_).suspension)


def _fmt(x: float | None) -> str:
    if x is None or math.isnan(x):
        return "–"
    return f"{x:.3g}" if abs(x) < 1000 else f"{x:.0f}"


def _p(p: float) -> str:
    return "–" if math.isnan(p) else "<0.001" if p < 0.001 else f"{p:.3f}"


def _table(header: Sequence[str], body: Sequence[Sequence[str]]) -> list[str]:
    return [*markdown_table(header, body), ""]


def _ok(rows: Sequence[RunRow]) -> dict[tuple[str, int, str], dict[str, float]]:
    """(cell, seed, suspension) -> the run's numeric metrics, for the ok runs."""
    return {(r.scenario, r.seed, _susp(r.strategy)): numeric_metrics(r.metrics) for r in rows
            if r.status is Status.OK}


def _pairs(flat: Mapping[tuple[str, int, str], dict[str, float]], cells: Sequence[str], treatment: str,
           metric: str) -> list[tuple[str, int, float, float]]:
    """(cell, seed, static's value, treatment's value) of every pair that has the metric."""
    out = []
    for (c, seed, s), m in sorted(flat.items()):
        b = flat.get((c, seed, "static"))
        if s != treatment or c not in cells or b is None or metric not in m or metric not in b:
            continue
        if math.isfinite(m[metric]) and math.isfinite(b[metric]):
            out.append((c, seed, b[metric], m[metric]))
    return out


def _interval(diffs: Sequence[float], seed: str, level: float) -> tuple[float, float]:
    """The ``level`` percentile bootstrap interval of the mean of ``diffs`` (0.95 or 0.90)."""
    if level == 0.95:
        return bootstrap_interval(diffs, seed)
    import random

    if not diffs:
        return math.nan, math.nan
    rng = random.Random(f"bootstrap:{seed}")
    n = len(diffs)
    means = sorted(math.fsum(diffs[rng.randrange(n)] for _ in range(n)) / n for _ in range(BOOTSTRAP))
    tail = (1 - level) / 2
    return means[int(tail * BOOTSTRAP)], means[int((1 - tail) * BOOTSTRAP) - 1]


# ------------------------------------------------------------------------------------------ sections


def _pilot(plan: ex.Plan) -> list[str]:
    m = len(plan.sizes)
    out = ["## The pilot and the size it fixed", "",
           f"The targeted arm's first {ex.PILOT_SEEDS} seeds, sized by the declared rule (power 0.8 at α = 0.05 / "
           f"{m}: Connor's approximation from the discordant share and the difference). \"–\": the pilot gives "
           "nothing to size (no discordant pair, or no difference).", ""]
    body = [[_name(s.scenario), s.contrast.name, str(s.pairs),
             f"discordant {_fmt(s.discordant)}, difference {_fmt(s.difference)}" if s.discordant is not None else "–",
             "–" if s.required is None else str(s.required)] for s in plan.sizes]
    out += _table(["cell", "contrast", "pilot pairs", "pilot measured", "pairs needed"], body)
    out += [f"n fixed per scenario (at least {ex.MIN_N}, at most {ex.MAX_N}): "
            + ", ".join(f"**{Path(sc).stem}** {n}" for sc, n in plan.n.items()) + ".", ""]
    under = plan.underpowered()
    if under:
        out += ["Underpowered at the cap (the test needs more pairs than the budget allows): "
                + "; ".join(f"{_name(s.scenario)} {s.contrast.name} ({s.required} needed)" for s in under) + ".", ""]
    return out


def _runs(arms: Mapping[str, Sequence[RunRow]], cells: Sequence[str]) -> list[str]:
    body = []
    for arm, rows in arms.items():
        for c in cells:
            for s in LEVELS:
                mine = [r for r in rows if r.scenario == c and _susp(r.strategy) == s]
                if not mine:
                    continue
                ok = [numeric_metrics(r.metrics) for r in mine if r.status is Status.OK]
                errors = [r for r in mine if r.status is Status.ERROR]
                infeasible = sum(1 for r in errors if INFEASIBLE.search(r.error or ""))
                aimed = sum(1 for r in mine if r.status is Status.OK and _targeted(r))
                body.append([arm, _name(c), s, str(len(ok)), str(infeasible), str(len(errors) - infeasible),
                             f"{sum(f.get('totals.failed', 0.0) for f in ok):.0f}",
                             f"{sum(f.get('suspensions.count', 0.0) for f in ok):.0f}",
                             str(aimed) if arm == "targeted" else "–"])
    return ["## The runs", "", *_table(["arm", "cell", "suspension", "ok runs", "infeasible", "errored",
                                        "failed tasks", "suspensions", "targeted change made"], body)]


def _targeted(r: RunRow) -> bool:
    """Whether the targeted change was made in run ``r`` (its world event is in the metrics' count)."""
    return float(numeric_metrics(r.metrics).get("run.targeted_changes", 0.0)) > 0


def _effect(t: Test) -> str:
    e = t.effect
    return f"{_fmt(e.estimate)} [{_fmt(e.low)}, {_fmt(e.high)}]"


def _family_table(tests: Sequence[Test]) -> list[str]:
    body = [[_name(t.scenario), t.contrast.name, str(t.effect.n), str(t.effect.informative), _effect(t),
             _p(t.effect.p), _p(t.p_holm),
             t.verdict.replace("treatment", t.contrast.treatment).replace("baseline", t.contrast.baseline)]
            for t in tests]
    return _table(["cell", "contrast", "pairs", "discordant", "difference [95 % CI]", "p", "p (Holm)", "verdict"],
                  body)


def _answer(tests: Sequence[Test], cells: Sequence[str]) -> list[str]:
    out = ["## The answer", "",
           "Per cell, from the targeted arm's family (differences are treatment − static in the share of runs "
           "whose every suspension was safe; Holm over the family):", ""]
    for c in cells:
        mine = [t for t in tests if t.scenario == c]
        helps = [t for t in mine if t.verdict == "treatment better"]
        hurts = [t for t in mine if t.verdict == "baseline better"]
        few = [t for t in mine if t.verdict == "too few pairs"]
        same = [t for t in mine if t.verdict == "identical"]
        none = [t for t in mine if t.verdict == "no pairs"]
        parts = []
        if helps:
            parts.append("**helps**: " + "; ".join(f"{t.contrast.treatment} ({_effect(t)})" for t in helps))
        if hurts:
            parts.append("**loses**: " + "; ".join(f"{t.contrast.treatment} ({_effect(t)})" for t in hurts))
        if none:
            parts.append("no pairs yet for " + ", ".join(t.contrast.treatment for t in none))
        if not helps and not hurts and len(none) < len(mine):
            parts.append("no Holm-significant difference from static")
        if few:
            parts.append("too few discordant pairs for " + ", ".join(
                f"{t.contrast.treatment} ({t.effect.informative} < {MIN_PAIRS})" for t in few))
        if same:
            parts.append("identical in every pair for " + ", ".join(t.contrast.treatment for t in same))
        out.append(f"* **{_name(c)}**: " + "; ".join(parts) + ".")
    return [*out, ""]


def _held(held: bool, diffs: Sequence[float]) -> str:
    """A hypothesis' verdict; with no pair it is not tested (an interim document before its arm ran)."""
    if not diffs:
        return "untested: no pairs yet"
    return "**supported**" if held else "**not supported**"


def _hypotheses(arms: Mapping[str, Sequence[RunRow]], cells: Sequence[str]) -> list[str]:
    out = ["## The hypotheses", "",
           "Pooled over the cells, each seed of a cell one pair; intervals are paired bootstrap percentile "
           f"intervals ({BOOTSTRAP} resamples, seeded).", ""]
    body = []
    for name, arm, treatment in (("H1", "targeted", "planned"), ("H1b", "targeted", "fallback")):
        diffs = [t - b for _, _, b, t in _pairs(_ok(arms.get(arm, ())), cells, treatment, SAFE)]
        mean = math.fsum(diffs) / len(diffs) if diffs else math.nan
        lo, hi = _interval(diffs, f"{name}|{arm}", 0.95)
        held = bool(diffs) and mean >= ex.H1_MIN and lo > 0
        body.append([name, arm, f"{treatment} − static ≥ {ex.H1_MIN:g}, lower bound > 0", str(len(diffs)),
                     f"{_fmt(mean)} [{_fmt(lo)}, {_fmt(hi)}] (95 %)", _held(held, diffs)])
    for arm in ("untargeted", "control"):
        diffs = [t - b for _, _, b, t in _pairs(_ok(arms.get(arm, ())), cells, "planned", SAFE)]
        mean = math.fsum(diffs) / len(diffs) if diffs else math.nan
        lo, hi = _interval(diffs, f"H2|{arm}", 0.90)
        held = bool(diffs) and -ex.H2_MARGIN < lo and hi < ex.H2_MARGIN
        body.append(["H2", arm, f"planned − static within ± {ex.H2_MARGIN:g} (TOST)", str(len(diffs)),
                     f"{_fmt(mean)} [{_fmt(lo)}, {_fmt(hi)}] (90 %)", _held(held, diffs)])
    return [*out, *_table(["hypothesis", "arm", "claim", "pairs", "difference [interval]", "verdict"], body)]


def _schedules(rows: Sequence[RunRow], cells: Sequence[str]) -> list[str]:
    """The primary difference over the pairs whose runs had the same schedule, the others counted apart."""
    order = {(r.scenario, r.seed, _susp(r.strategy)): str((r.metrics.get("switching") or {}).get("schedule", ""))
             for r in rows if r.status is Status.OK}
    flat = _ok(rows)
    body = []
    for treatment in LEVELS[1:]:
        for c in cells:
            pairs = _pairs(flat, [c], treatment, SAFE)
            same = [t - b for _, seed, b, t in pairs
                    if order.get((c, seed, treatment)) == order.get((c, seed, "static"))]
            differ = len(pairs) - len(same)
            lo, hi = _interval(same, f"schedule|{c}|{treatment}", 0.95)
            body.append([_name(c), f"{treatment} vs static", str(len(same)),
                         f"{_fmt(math.fsum(same) / len(same) if same else math.nan)} [{_fmt(lo)}, {_fmt(hi)}]",
                         str(differ)])
    return ["## Pairs with the same schedule", "",
            "The primary difference again, over the pairs whose two runs gave the robot to the same agents in the "
            "same order (a difference there comes from the suspension itself, not from a schedule it changed); "
            "the pairs whose schedule differed are counted apart.", "",
            *_table(["cell", "contrast", "same-schedule pairs", "difference [95 % CI]", "pairs whose schedule "
                     "differed"], body)]


def _secondary(rows: Sequence[RunRow], cells: Sequence[str]) -> list[str]:
    out = ["## Secondary outcomes (described, not tested)", "",
           "Mean ± 95 % CI over the targeted arm's ok runs, and the paired mean difference from static with a "
           "bootstrap 95 % interval; time to help also with its 90 % interval against the declared ± "
           f"{ex.HELP_MARGIN_S:g} s (*equivalent* when inside it).", ""]
    flat = _ok(rows)
    for c in cells:
        body = []
        for metric in ex.SECONDARY:
            row = [label(metric)]
            for s in LEVELS:
                vals = [m[metric] for (cc, _, k), m in flat.items() if cc == c and k == s and metric in m
                        and math.isfinite(m[metric])]
                e = estimate(vals)
                text = f"{_fmt(e.mean)} ± {_fmt(e.half)}" if e.n > 1 else _fmt(e.mean)
                if s != "static":
                    diffs = [t - b for _, _, b, t in _pairs(flat, [c], s, metric)]
                    if diffs:
                        lo, hi = bootstrap_interval(diffs, f"{c}|{s}|{metric}")
                        text += f"; Δ {_fmt(math.fsum(diffs) / len(diffs))} [{_fmt(lo)}, {_fmt(hi)}]"
                        if metric == "people.time_to_help_s.mean":
                            lo9, hi9 = _interval(diffs, f"{c}|{s}|{metric}|90", 0.90)
                            inside = -ex.HELP_MARGIN_S < lo9 and hi9 < ex.HELP_MARGIN_S
                            text += " (equivalent)" if inside else " (not shown equivalent)"
                row.append(text)
            body.append(row)
        out += [f"### {_name(c)}", "", *_table(["metric", *[f"{s}" + ("" if s == "static" else " (Δ vs static)")
                                                           for s in LEVELS]], body)]
    return out


def _walls(rows: Sequence[RunRow]) -> list[str]:
    by: dict[str, list[float]] = defaultdict(list)
    for r in rows:
        if r.status is Status.OK:
            by[_susp(r.strategy)] += [float(x) for x in r.metrics.get("gensusp_wall_s", []) or []]
    body = []
    for s in LEVELS:
        vals = sorted(by.get(s, []))
        if not vals:
            body.append([s, "0", "–", "–"])
            continue
        p99 = vals[min(len(vals) - 1, math.ceil(0.99 * len(vals)) - 1)]
        body.append([s, str(len(vals)), f"{1000 * vals[len(vals) // 2]:.1f}", f"{1000 * p99:.1f}"])
    return ["## genSusp's planner wall time, cold caches", "",
            "Each planned genSusp's planner wall time over the targeted arm's runs (every run starts with the "
            "planning caches forgotten; a tree's stages take none): host-dependent, measured on a shared 2-core "
            "machine.", "", *_table(["suspension", "planned genSusps", "median (ms)", "p99 (ms)"], body)]


def _losses(rows: Sequence[RunRow], cells: Sequence[str]) -> list[str]:
    out = ["## Where planning the suspension was less safe", "",
           "Each seed where a planned, derived or fallback run was less safe than static in the same variant (a "
           f"suspension that was not safe where static's were), at most {SHOW_LOSSES} per cell and contrast. Replay "
           "one with every output of `tasker run`: `tasker results --replay SCENARIO SEED SUSPENSION [--tree TREE] "
           "--out out/replay`.", ""]
    flat = _ok(rows)
    body, counted = [], []
    for c in cells:
        for s in LEVELS[1:]:
            worse = [(seed, b, t) for _, seed, b, t in _pairs(flat, [c], s, SAFE) if t < b]
            body += [[_name(c), s, str(seed), _fmt(flat[(c, seed, s)].get("safety.unattended_s", math.nan)),
                      _fmt(flat[(c, seed, "static")].get("safety.unattended_s", math.nan))]
                     for seed, _, _ in worse[:SHOW_LOSSES]]
            if worse:
                counted.append(f"{_name(c)} {s}: {len(worse)}")
    if not body:
        return [*out, "In no cell or seed was a planned, derived or fallback run less safe than static.", ""]
    return [*out, "Seeds in all: " + "; ".join(counted) + ".", "",
            *_table(["cell", "suspension", "seed", "its hazard time unattended (s)",
                     "static's hazard time unattended (s)"], body)]


def render(arms: Mapping[str, Sequence[RunRow]], plan: ex.Plan, cells: Sequence[str], command: str,
           provenance: Provenance | None) -> str:
    """The document (deterministic: the same rows and provenance give the same text); ``arms``' rows are
    by cell (:func:`experiments.sweep.experiment.by_cell`)."""
    families = {a: run_family(arms.get(a, ()), cells, ex.CONTRASTS, ex.OUTCOMES) for a in ex.ARMS}
    wall = math.fsum(r.wall or 0.0 for rows in arms.values() for r in rows) / 3600
    counts = ", ".join(f"{a}: {len(arms.get(a, ()))}" for a in ex.ARMS)
    out = ["# Planning the suspension: where it helps", "",
           f"Regenerate (resumable: only runs missing from the databases are run; these took {_fmt(wall)} hours of "
           "worker wall time on a shared machine):", "", "```bash", command, "```", "",
           ex.DECLARATION.rstrip(), "", *_pilot(plan), *_runs(arms, cells), f"Runs per arm: {counts}.", "",
           *_answer(families["targeted"], cells), *_hypotheses(arms, cells)]
    for a in ex.ARMS:
        fam = families[a]
        out += [f"## The {a} arm's family", "",
                f"Holm over these {len(fam)} tests, α = {ALPHA}; no verdict below {MIN_PAIRS} discordant pairs.", "",
                *_family_table(fam)]
    targeted = arms.get("targeted", ())
    out += [*_schedules(targeted, cells), *_secondary(targeted, cells), *_walls(targeted), *_losses(targeted, cells)]
    if provenance is not None:
        out += render_provenance(provenance)
    return "\n".join(out).rstrip() + "\n"


def contrast_names() -> list[str]:
    return [c.name for c in ex.CONTRASTS]


__all__ = ["Contrast", "render"]
