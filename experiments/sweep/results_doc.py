"""``docs/results.md`` from the stored runs of the suspension-strategy experiment.

Everything after the declaration is computed from the two results databases alone: the same
runs give the same text, byte for byte (no date, no host; the commit and the trace digests
of the provenance block are passed in).  Per scenario, never pooled; the declared family of
:mod:`experiments.sweep.experiment` and nothing else is tested.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Sequence
from pathlib import Path

from experiments.analysis.compare import INFEASIBLE
from experiments.analysis.family import BINARY, MIN_PAIRS, Contrast, Test, run_family
from experiments.analysis.paired_tests import bootstrap_interval
from experiments.analysis.stats import ALPHA, estimate
from experiments.analysis.tables import markdown_table
from experiments.inputs.strategy import Strategy
from experiments.metrics.registry import label, numeric_metrics
from experiments.metrics.run import HYSTERESES
from experiments.metrics.store import RunRow, Status
from experiments.sweep import experiment as ex
from experiments.sweep.provenance import Provenance
from experiments.sweep.provenance import render as render_provenance

SHOW_LOSSES = 12
"""Seeds listed per scenario and contrast where the treatment was less safe (the rest are counted)."""


def _name(scenario: str) -> str:
    return Path(scenario).stem


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


def _order(rows: Sequence[RunRow], spec_scenarios: Sequence[str]) -> list[str]:
    present = {r.scenario for r in rows}
    return [s for s in spec_scenarios if s in present]


def _strategies(rows: Sequence[RunRow]) -> list[str]:
    order = {"static": 0, "planned": 1, "derived": 2}
    return sorted({r.strategy for r in rows}, key=lambda s: order.get(_susp(s), 9))


# ------------------------------------------------------------------------------------------ sections


def _pilot(plan: ex.Plan) -> list[str]:
    out = ["## The pilot and the size it fixed", "",
           f"The perturbed arm's first {ex.PILOT_SEEDS} seeds, sized by the declared rule (power 0.8 at "
           f"α = 0.05 / {len(plan.sizes)}; binary: discordant share and difference; seconds: SD of the paired "
           f"differences against {ex.DELTA_S:g} s). \"–\": the pilot gives nothing to size (no discordant pair, no "
           "spread, or no difference).", ""]
    body = []
    for s in plan.sizes:
        measured = (f"discordant {_fmt(s.discordant)}, difference {_fmt(s.difference)}"
                    if s.outcome.kind == BINARY and s.discordant is not None
                    else f"mean difference {_fmt(s.difference)} s, SD {_fmt(s.sd)} s" if s.sd is not None else "–")
        body.append([_name(s.scenario), s.contrast.name, s.outcome.label, str(s.pairs), measured,
                     "–" if s.required is None else str(s.required)])
    out += _table(["scenario", "contrast", "outcome", "pilot pairs", "pilot measured", "pairs needed"], body)
    out += ["n fixed per scenario (at least " f"{ex.MIN_N}, at most {ex.MAX_N}): "
            + ", ".join(f"**{_name(sc)}** {n}" for sc, n in plan.n.items()) + ".", ""]
    under = plan.underpowered()
    if under:
        out += ["Underpowered at the cap (the test needs more pairs than the budget allows): "
                + "; ".join(f"{_name(s.scenario)} {s.contrast.name} {s.outcome.label} ({s.required} needed)"
                            for s in under) + ".", ""]
    return out


def _runs(rows: Sequence[RunRow], scenarios: Sequence[str], title: str) -> list[str]:
    body = []
    fallbacks = 0
    for sc in scenarios:
        for st in _strategies(rows):
            mine = [r for r in rows if (r.scenario, r.strategy) == (sc, st)]
            if not mine:
                continue
            ok = [numeric_metrics(r.metrics) for r in mine if r.status is Status.OK]
            errors = [r for r in mine if r.status is Status.ERROR]
            infeasible = sum(1 for r in errors if INFEASIBLE.search(r.error or ""))
            fb = sum(1 for f in ok if f.get("totals.static_fallbacks", 0.0) > 0)
            fallbacks += fb
            body.append([_name(sc), _susp(st), str(len(ok)), str(infeasible), str(len(errors) - infeasible),
                         f"{sum(f.get('totals.failed', 0.0) for f in ok):.0f}",
                         f"{sum(f.get('totals.unfinished', 0.0) for f in ok):.0f}", str(fb),
                         f"{sum(f.get('suspensions.count', 0.0) for f in ok):.0f}"])
    out = [f"### {title}", "",
           *_table(["scenario", "suspension", "ok runs", "infeasible", "errored", "failed tasks", "unfinished tasks",
                    "runs with a planner fallback to static", "suspensions"], body)]
    if fallbacks:
        out += [f"**{fallbacks} runs had a planner fallback to static** (a planned or derived genSusp the planner "
                "could not solve in time, or at all, ran the static branch instead); they are analysed under "
                "the strategy they were asked for.", ""]
    return out


def _effect(t: Test) -> str:
    e = t.effect
    unit = "" if t.outcome.kind == BINARY else " s"
    return f"{_fmt(e.estimate)}{unit} [{_fmt(e.low)}, {_fmt(e.high)}]"


def _family_table(tests: Sequence[Test]) -> list[str]:
    body = [[_name(t.scenario), t.contrast.name, t.outcome.label, str(t.effect.n), str(t.effect.informative),
             _effect(t), _p(t.effect.p), _p(t.p_holm),
             t.verdict.replace("treatment", t.contrast.treatment).replace("baseline", t.contrast.baseline)]
            for t in tests]
    return _table(["scenario", "contrast", "outcome", "pairs", "informative", "effect [95 % CI]", "p", "p (Holm)",
                   "verdict"], body)


def _answer(tests: Sequence[Test], scenarios: Sequence[str]) -> list[str]:
    out = ["## The answer", "",
           "Per scenario, from the perturbed arm's family (effects are treatment − static: for *every suspension "
           "safe* a difference in the share of runs, for seconds a mean difference; Holm over the family's tests):", ""]
    for sc in scenarios:
        mine = [t for t in tests if t.scenario == sc]
        helps = [t for t in mine if t.verdict == "treatment better"]
        hurts = [t for t in mine if t.verdict == "baseline better"]
        few = [t for t in mine if t.verdict == "too few pairs"]
        same = [t for t in mine if t.verdict == "identical"]
        parts = []
        if helps:
            parts.append("**helps**: " + "; ".join(f"{t.contrast.treatment} on {t.outcome.label} ({_effect(t)})"
                                                   for t in helps))
        if hurts:
            parts.append("**hurts**: " + "; ".join(f"{t.contrast.treatment} on {t.outcome.label} ({_effect(t)})"
                                                   for t in hurts))
        if not helps and not hurts:
            parts.append("no Holm-significant difference from static")
        if few:
            parts.append("too few informative pairs for " + ", ".join(
                f"{t.contrast.name} on {t.outcome.label} ({t.effect.informative} < {MIN_PAIRS})" for t in few))
        if same:
            parts.append("identical in every pair for " + ", ".join(
                f"{t.contrast.name} on {t.outcome.label}" for t in same))
        out.append(f"* **{_name(sc)}**: " + "; ".join(parts) + ".")
    return [*out, ""]


def _secondary(rows: Sequence[RunRow], scenarios: Sequence[str]) -> list[str]:
    out = ["## Secondary outcomes (described, not tested)", "",
           "Mean ± 95 % CI over the perturbed arm's ok runs, and the paired mean difference from static with a "
           "bootstrap 95 % interval.", ""]
    for sc in scenarios:
        flat = {(r.seed, _susp(r.strategy)): numeric_metrics(r.metrics) for r in rows
                if r.scenario == sc and r.status is Status.OK}
        body = []
        for metric in ex.SECONDARY:
            row = [label(metric)]
            for s in ("static", "planned", "derived"):
                vals = [m[metric] for (_, k), m in flat.items() if k == s and metric in m and math.isfinite(m[metric])]
                e = estimate(vals)
                cell = f"{_fmt(e.mean)} ± {_fmt(e.half)}" if e.n > 1 else _fmt(e.mean)
                if s != "static":
                    diffs = [m[metric] - b[metric] for (seed, k), m in sorted(flat.items()) if k == s
                             and (b := flat.get((seed, "static"))) is not None and metric in m and metric in b
                             and math.isfinite(m[metric]) and math.isfinite(b[metric])]
                    if diffs:
                        lo, hi = bootstrap_interval(diffs, f"{sc}|{s}|{metric}")
                        cell += f"; Δ {_fmt(math.fsum(diffs) / len(diffs))} [{_fmt(lo)}, {_fmt(hi)}]"
                row.append(cell)
            body.append(row)
        out += [f"### {_name(sc)}", "", *_table(["metric", "static", "planned (Δ vs static)",
                                                  "derived (Δ vs static)"], body)]
    return out


def _margins(rows: Sequence[RunRow], scenarios: Sequence[str]) -> list[str]:
    out = ["## Alg. 2's decisions: margins and hysteresis", "",
           "Per cell, Alg. 2's finite cost comparisons binned by margin 1 − c_switch / c_wait (a margin near 0 is "
           "a close call), and how many of them a hysteresis of " + ", ".join(f"{h:g}" for h in HYSTERESES)
           + " would have decided the other way (decision by decision; what would have followed is not re-run).",
           ""]
    body = []
    for sc in scenarios:
        for st in _strategies(rows):
            ok = [numeric_metrics(r.metrics) for r in rows
                  if (r.scenario, r.strategy) == (sc, st) and r.status is Status.OK]
            if not ok:
                continue
            bins: Counter[str] = Counter()
            flips: Counter[str] = Counter()
            for m in ok:
                for k, v in m.items():
                    if k.startswith("decisions.margins."):
                        bins[k.removeprefix("decisions.margins.")] += int(v)
                    elif k.startswith("decisions.hysteresis_flips."):
                        flips[k.removeprefix("decisions.hysteresis_flips.")] += int(v)
            compared = int(sum(m.get("decisions.cost_compared", 0.0) for m in ok))
            close = sum(v for k, v in bins.items() if -0.1 <= float(k) < 0.1)
            hist = " ".join(f"{k}:{v}" for k, v in sorted(bins.items(), key=lambda kv: float(kv[0])))
            body.append([_name(sc), _susp(st), str(compared), str(close), hist or "–",
                         *(str(flips.get(f"{h:g}", 0)) for h in HYSTERESES)])
    return out + _table(["scenario", "suspension", "cost decisions", "|margin| < 0.1", "margins (bin:count)",
                         *(f"flips at {h:g}" for h in HYSTERESES)], body)


def _losses(rows: Sequence[RunRow], scenarios: Sequence[str], contrasts: Sequence[Contrast]) -> list[str]:
    out = ["## Where planning the suspension was less safe", "",
           "Each seed where the planned or derived run was less safe than static in the same variant (a suspension "
           "that was not safe where static's were, or more hazard time unattended), at most "
           f"{SHOW_LOSSES} per scenario and contrast. Replay one with every output of `tasker run`: "
           "`tasker results --replay SCENARIO SEED SUSPENSION --out out/replay`.", ""]
    body = []
    counted = []
    for sc in scenarios:
        flat = {(r.seed, _susp(r.strategy)): numeric_metrics(r.metrics) for r in rows
                if r.scenario == sc and r.status is Status.OK}
        for c in contrasts:
            worse = []
            for (seed, s), m in sorted(flat.items()):
                b = flat.get((seed, c.baseline))
                if s != c.treatment or b is None:
                    continue
                unsafe = m.get("suspensions.all_safe", 1.0) < b.get("suspensions.all_safe", 1.0)
                longer = m.get("safety.unattended_alive_s", 0.0) > b.get("safety.unattended_alive_s", 0.0) + 1e-6
                if unsafe or longer:
                    worse.append([_name(sc), c.treatment, str(seed),
                                  "not safe" if unsafe else "safe" if m.get("suspensions.all_safe") else "not safe",
                                  _fmt(b.get("safety.unattended_alive_s", math.nan)),
                                  _fmt(m.get("safety.unattended_alive_s", math.nan))])
            body += worse[:SHOW_LOSSES]
            if worse:
                counted.append(f"{_name(sc)} {c.treatment}: {len(worse)}")
    if not body:
        return [*out, "In no scenario or seed was a planned or derived run less safe than static.", ""]
    return [*out, "Seeds in all: " + "; ".join(counted) + ".", "",
            *_table(["scenario", "suspension", "seed", "its suspensions", "static unattended (s)",
                     "its unattended (s)"], body)]


def render(perturbed: Sequence[RunRow], control: Sequence[RunRow], plan: ex.Plan, scenarios: Sequence[str],
           command: str, provenance: Provenance | None) -> str:
    """The document (deterministic: the same rows and provenance give the same text)."""
    sc_p = _order(perturbed, scenarios)
    sc_c = _order(control, scenarios)
    fam = run_family(perturbed, scenarios, ex.CONTRASTS, ex.OUTCOMES)  # the declared family, data or not
    fam_c = run_family(control, scenarios, ex.CONTRASTS, ex.OUTCOMES)
    wall = math.fsum(r.wall or 0.0 for r in [*perturbed, *control]) / 3600
    out = ["# Planning the suspension: where it helps", "",
           f"Regenerate (resumable: only runs missing from the databases are run; these took {_fmt(wall)} hours of "
           "worker wall time on a shared machine):", "", "```bash", command, "```", "",
           ex.DECLARATION.rstrip(), "", *_pilot(plan), "## The runs", "",
           f"Perturbed arm: {len(perturbed)} runs; control arm: {len(control)} runs.", "",
           *_runs(perturbed, sc_p, "Perturbed arm"), *_runs(control, sc_c, "Control arm (no perturbation)"),
           *_answer(fam, scenarios),
           "## The primary family (perturbed arm)", "",
           f"Holm over these {len(fam)} tests, α = {ALPHA}; `informative`: discordant pairs (McNemar) or pairs with "
           f"a non-zero difference (Wilcoxon); no verdict below {MIN_PAIRS}.", "", *_family_table(fam),
           "## The control arm", "",
           "The same tests without exogenous events (its own Holm family): does a difference need a world that "
           "changes under the robot?", "", *_family_table(fam_c),
           *_secondary(perturbed, sc_p), *_margins(perturbed, sc_p), *_losses(perturbed, sc_p, ex.CONTRASTS)]
    if provenance is not None:
        out += render_provenance(provenance)
    return "\n".join(out).rstrip() + "\n"


__all__ = ["render"]
