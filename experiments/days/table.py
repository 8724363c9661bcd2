"""The table that compares schedulers (and strategies) over many days: means with 95 % CIs, paired tests.

:func:`report` is what ``tasker day`` writes to ``table.md``: :func:`table` per strategy
(metrics per scheduler, mean ± half-width of the 95 % t interval over days; how the days
ended, by TaBSA's stopping rule and by ours; ``lookahead`` against each baseline, paired by
seed), the strategies against the first under every scheduler, and the days that failed to run.

**Every comparison** gives its effect size — the mean paired difference over days with its
95 % t interval, and how many days it was lower, tied, higher — the Wilcoxon signed-rank p
Holm-corrected over every test of the table, and a verdict from the metric's registered
direction (:mod:`experiments.metrics.registry`): *better*, *worse*, or *no difference shown*.
**No verdict below a minimum number of days** (:func:`min_days`), fixed by the family's size
before any result: with n paired days the signed-rank test's smallest two-sided p is
2^(1 − n) (every day differing in one direction), and Holm multiplies the smallest p by the
number m of tests, so below n = ⌈log2(2m / α)⌉ days no test of the table could reject at
α = 0.05 and "no difference shown" would be a statement about the number of days, not the
schedulers: the verdict reads *too few days* instead.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from scipy import stats

from experiments.analysis.stats import ALPHA, estimate, holm
from experiments.analysis.tables import markdown_table
from experiments.metrics.day import ENDINGS, TABSA_ENDINGS
from experiments.metrics.registry import Direction, direction

OURS = ("simple", "simple2", "distance")
"""Our priority-first readings of TaBSA's agents: labelled "(ours)" beside TaBSA's own (``tabsa-*``)."""


def _ci(values: Sequence[float]) -> tuple[float, float]:
    """Mean and the half-width of its 95 % t confidence interval (:func:`experiments.analysis.stats.estimate`)."""
    e = estimate([float(v) for v in values])
    return e.mean, e.half


def _fmt(mean: float, half: float) -> str:
    if math.isnan(mean):
        return "–"
    return f"{mean:.2f} ± {half:.2f}" if not math.isnan(half) else f"{mean:.2f}"


def _robot(r: Mapping[str, Any], value: Any) -> Any:
    return value if r.get("backend") == "robot" else None


def _metric_rows(types: Sequence[str]) -> list[tuple[str, str, Any]]:
    rows: list[tuple[str, str, Any]] = [
        ("completed (of requested)", "completed", lambda r: r["completed"]),
        *((f"completed: {t}", f"completed_{t}", lambda r, t=t: r["per_type"].get(t, {}).get("completed", 0))
          for t in types),
        ("completion − deadline, mean (s)", "gap", lambda r: r["completion_minus_deadline_s"]),
        ("lateness, sum over tasks (s)", "lateness", lambda r: r["lateness_s"]),
        *((f"completion − deadline: {t} (s)", f"gap_{t}",
           lambda r, t=t: r["per_type"].get(t, {}).get("completion_minus_deadline_s")) for t in types),
        ("dead falls", "dead", lambda r: r["dead_falls"]),
        ("completion − death time: fall (s, TaBSA)", "death_gap", lambda r: r.get("completion_minus_death_s")),
        ("completed by TaBSA's stop (TaBSA)", "tabsa_completed", lambda r: r.get("tabsa_completed")),
        # robot rows: synthetic stages never fail; a day stored before renewals existed made none
        ("failed tasks not served by their renewals (robot)", "failed", lambda r: _robot(r, r["failed"])),
        ("requests made again after a failed task (robot)", "renewals", lambda r: _robot(r, r.get("renewals", 0))),
        ("interruptions", "interruptions", lambda r: r["interruptions"]),
        *((f"interruptions per task: {t}", f"int_{t}",
           lambda r, t=t: r["per_type"].get(t, {}).get("interruptions_per_task")) for t in types),
        # a day stored before suspensions_with_stages existed called it suspensions
        ("suspensions that ran an exeSusp (ours)", "suspensions",
         lambda r: r.get("suspensions_with_stages", r.get("suspensions"))),
        ("time suspending (s, ours)", "susp_time", lambda r: r["suspension_time_s"]),
        ("switches (ours)", "switches", lambda r: r["switches"]),
        ("hazard time unattended (s, ours)", "hazard_s", lambda r: r.get("hazard_unattended_s")),
        ("… of it after its task ended (s, ours)", "hazard_after", lambda r: r.get("hazard_after_end_s")),
        ("hazard budget overruns (ours)", "overruns", lambda r: r.get("hazard_overruns")),
        ("hazards left on at a switch (ours)", "left_on", lambda r: r.get("hazards_left_at_switch")),
        ("abandonments (robot leaves a fallen person's 2 m circle)", "abandonments", lambda r: r.get("abandonments")),
        ("falls abandoned at least once", "abandoned", lambda r: r.get("abandoned_falls")),
        ("abandonments for another task (ours: not while driving to the person)", "abandon_other",
         lambda r: r.get("abandonments_other_task")),
        ("travel distance (m)", "travel", lambda r: r.get("travel_m")),
        ("longest queue ordered (lookahead)", "longest", lambda r: r["longest_order"] or None),
        ("decisions not proven optimal (lookahead)", "anytime", lambda r: r["anytime_decisions"] if r["longest_order"]
         else None),
    ]
    return rows


PAIRED = ("dead", "abandonments", "lateness", "gap", "completed", "tabsa_completed", "interruptions", "travel")
STRATEGY_PAIRED = (*PAIRED, "suspensions", "susp_time", "hazard_s", "hazard_after", "overruns", "left_on")
"""Strategies differ in how a task suspends: their comparison adds what the suspensions cost."""
REGISTERED = {"dead": "day.dead_falls", "abandonments": "day.abandonments", "lateness": "day.lateness_s",
              "gap": "day.completion_minus_deadline_s", "completed": "day.completed",
              "tabsa_completed": "day.tabsa_completed", "interruptions": "day.interruptions",
              "travel": "day.travel_m", "suspensions": "day.suspensions_with_stages",
              "susp_time": "day.suspension_time_s", "hazard_s": "day.hazard_unattended_s",
              "hazard_after": "day.hazard_after_end_s", "overruns": "day.hazard_overruns",
              "left_on": "day.hazards_left_at_switch"}
"""Each compared row's registered metric: its direction gives the verdict."""


def min_days(tests: int, alpha: float = ALPHA) -> int:
    """The fewest paired days at which a Wilcoxon signed-rank test, Holm-corrected over ``tests``
    tests, could reject at ``alpha``: the smallest n with 2^(1 − n) · tests < alpha."""
    return max(2, math.ceil(math.log2(2 * max(1, tests) / alpha) + 1e-12))


def _wilcoxon(diff: np.ndarray) -> float:
    if len(diff) == 0 or np.all(diff == 0):
        return 1.0
    return float(stats.wilcoxon(diff, zero_method="zsplit").pvalue)


def _header(name: str) -> str:
    return f"{name} (ours)" if name.split(":")[0] in OURS else name


def table(results: Sequence[Mapping[str, Any]], *, reference: str = "lookahead", title: str = "") -> str:
    """The Markdown report: metrics per scheduler (mean ± 95 % CI over days), endings, paired tests."""
    names = list(dict.fromkeys(r["scheduler"] for r in results))
    by = {n: [r for r in results if r["scheduler"] == n] for n in names}
    types = sorted({t for r in results for t in r["per_type"]})
    rows = _metric_rows(types)
    days = len(by[names[0]]) if names else 0
    heads = [_header(n) for n in names]
    out = [f"## {title}" if title else "", f"{days} days per scheduler; mean ± half-width of the 95 % CI over days.",
           ""]
    metric_rows = []
    for label, _, get in rows:
        cells = []
        for n in names:
            vals = [v for v in (get(r) for r in by[n]) if v is not None]
            cells.append(_fmt(*_ci(vals)) if vals else "–")
        if any(c != "–" for c in cells):  # e.g. path metrics exist only on the robot backend
            metric_rows.append([label, *cells])
    out += markdown_table(["metric", *heads], metric_rows)
    if any("tabsa_ending" in r for r in results):  # days stored before TaBSA's rule was read have none
        out += ["", "How the days end by TaBSA's rule (`test_planner.py` stops its day at the first of these; "
                "its oscillation: the task of a step with more than 2 gaps in 180 s; the day is run to its end "
                "here, so the rows above count the whole day):", "",
                *markdown_table(["ending (TaBSA)", *heads],
                                [[ending, *(sum(1 for r in by[n] if r.get("tabsa_ending") == ending) for n in names)]
                                 for ending in TABSA_ENDINGS])]
    out += ["", "How the days ended by our rule (our oscillation: a task's third start within 180 s):", "",
            *markdown_table(["ending (ours)", *heads],
                            [[ending, *(sum(1 for r in by[n] if r["ending"] == ending) for n in names)]
                             for ending in ENDINGS])]
    if reference in by and len(names) > 1:
        out += ["", *_paired_intro(f"{reference} − baseline")]
        out += _paired(rows, [(n, by[reference], by[n]) for n in names if n != reference])
    return "\n".join(line for line in out if line is not None).lstrip("\n") + "\n"


def _paired_intro(what: str) -> list[str]:
    return [f"Paired over days: {what}.  Effect: the mean difference with its 95 % t interval (negative: "
            "fewer/earlier), and the days it was lower / tied / higher.  p: Wilcoxon signed-rank, Holm-corrected "
            "over every test of this table; verdict from the metric's registered direction, none below the "
            "minimum number of days (see docs/benchmark.md).", ""]


PAIRED_HEADER = ("metric", "compared with", "days", "difference (95 % CI)", "lower / tied / higher", "p (Holm)",
                 "verdict")


def _verdict(key: str, mean: float, p: float, n: int, least: int) -> str:
    if n < least:
        return f"too few days (< {least})"
    if math.isnan(p) or p >= ALPHA:
        return "no difference shown"
    way = direction(REGISTERED.get(key, ""))
    if way is None or way is Direction.NEITHER:
        return "differs"
    return "better" if (mean < 0) == (way is Direction.LOWER) else "worse"


def _paired(rows: Sequence[tuple[str, str, Any]],
            groups: Sequence[tuple[str, Sequence[Mapping[str, Any]], Sequence[Mapping[str, Any]]]],
            keys: Sequence[str] = PAIRED) -> list[str]:
    """A table (:data:`PAIRED_HEADER`, after :func:`_paired_intro`) with a line for each metric of ``keys``
    and each ``(name, a days, b days)``, ``a − b`` paired by seed; Holm over every line, verdicts from
    :data:`REGISTERED`."""
    tests = []
    getters = {key: (label, get) for label, key, get in rows}
    for key in keys:
        label, get = getters[key]
        for name, a_days, b_days in groups:
            ref = {r["seed"]: get(r) for r in a_days}
            pairs = [(ref[r["seed"]], get(r)) for r in b_days if ref.get(r["seed"]) is not None and get(r) is not None]
            if not pairs:
                continue
            diff = np.array([a - b for a, b in pairs], dtype=float)
            tests.append((key, label, name, diff, _wilcoxon(diff)))
    adjusted = holm([p for *_, p in tests])
    least = min_days(len(tests))
    out = []
    for (key, label, n, diff, _), p in zip(tests, adjusted, strict=True):
        mean, half = _ci(list(diff))
        counts = f"{int(np.sum(diff < 0))} / {int(np.sum(diff == 0))} / {int(np.sum(diff > 0))}"
        out.append([label, _header(n), len(diff), _fmt(mean, half), counts, f"{p:.3g}",
                    _verdict(key, mean, p, len(diff), least)])
    return markdown_table(PAIRED_HEADER, out)


def report(results: Sequence[Mapping[str, Any]], *, reference: str = "lookahead", title: str = "") -> str:
    """:func:`table` per strategy; with several strategies, each against the first under every
    scheduler (paired by seed); and the days that failed to run, listed, never dropped silently."""
    ok = [r for r in results if "error" not in r]
    failed = [r for r in results if "error" in r]
    labels = list(dict.fromkeys(r.get("strategy", "default") for r in ok))
    if len(labels) <= 1:
        text = table(ok, reference=reference, title=title) if ok else f"## {title}\nNo day ran to its end.\n"
    else:
        parts = [table([r for r in ok if r.get("strategy", "default") == label], reference=reference,
                       title=f"{title}, strategy `{label}`") for label in labels]
        first = labels[0]
        names = list(dict.fromkeys(r["scheduler"] for r in ok))
        of = {(lb, n): [r for r in ok if r.get("strategy", "default") == lb and r["scheduler"] == n]
              for lb in labels for n in names}
        types = sorted({t for r in ok for t in r["per_type"]})
        lines = [f"## Strategies compared: each − `{first}`, under the same scheduler",
                 *_paired_intro(f"each strategy − `{first}`, under the same scheduler")]
        lines += _paired(_metric_rows(types), [(f"`{lb}`, {n}", of[lb, n], of[first, n])
                                               for lb in labels[1:] for n in names], STRATEGY_PAIRED)
        text = "\n".join(parts) + "\n" + "\n".join(lines) + "\n"
    if failed:
        text += ("\nDays that did not run to their end (not in the tables above; stored with their error):\n\n"
                 + "\n".join(f"- `{r.get('strategy', 'default')}`, {r['scheduler']}, seed {r['seed']}: {r['error']}"
                             for r in failed) + "\n")
    return text
