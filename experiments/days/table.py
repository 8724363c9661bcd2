"""The table that compares schedulers (and strategies) over many days: means with 95 % CIs, paired tests.

:func:`report` is what ``tasker day`` writes to ``table.md``: :func:`table` per strategy
(metrics per scheduler, mean ± half-width of the 95 % t interval over days; how the days
ended; ``lookahead`` against each baseline, paired by seed, Wilcoxon signed-rank,
Holm-corrected), the strategies against the first under every scheduler, and the days that
failed to run.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from scipy import stats

from experiments.analysis.stats import estimate, holm
from experiments.metrics.day import ENDINGS


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


PAIRED = ("dead", "abandonments", "lateness", "gap", "completed", "interruptions", "travel")
STRATEGY_PAIRED = (*PAIRED, "suspensions", "susp_time", "hazard_s", "hazard_after", "overruns", "left_on")
"""Strategies differ in how a task suspends: their comparison adds what the suspensions cost."""


def _wilcoxon(diff: np.ndarray) -> float:
    if len(diff) == 0 or np.all(diff == 0):
        return 1.0
    return float(stats.wilcoxon(diff, zero_method="zsplit").pvalue)


def table(results: Sequence[Mapping[str, Any]], *, reference: str = "lookahead", title: str = "") -> str:
    """The Markdown report: metrics per scheduler (mean ± 95 % CI over days), endings, paired tests."""
    names = list(dict.fromkeys(r["scheduler"] for r in results))
    by = {n: [r for r in results if r["scheduler"] == n] for n in names}
    types = sorted({t for r in results for t in r["per_type"]})
    rows = _metric_rows(types)
    days = len(by[names[0]]) if names else 0
    out = [f"## {title}" if title else "", f"{days} days per scheduler; mean ± half-width of the 95 % CI over days.",
           "", "| metric | " + " | ".join(names) + " |", "|---|" + "---|" * len(names)]
    for label, _, get in rows:
        cells = []
        for n in names:
            vals = [v for v in (get(r) for r in by[n]) if v is not None]
            cells.append(_fmt(*_ci(vals)) if vals else "–")
        if any(c != "–" for c in cells):  # e.g. path metrics exist only on the robot backend
            out.append(f"| {label} | " + " | ".join(cells) + " |")
    out += ["", "How the days ended (TaBSA's first stopping condition; the day is run to its end):", "",
            "| ending | " + " | ".join(names) + " |", "|---|" + "---|" * len(names)]
    for ending in ENDINGS:
        out.append(f"| {ending} | " + " | ".join(str(sum(1 for r in by[n] if r["ending"] == ending)) for n in names)
                   + " |")
    if reference in by and len(names) > 1:
        out += ["", f"Paired over days: {reference} − baseline (mean ± 95 % CI; negative is fewer/earlier); "
                "Wilcoxon signed-rank, Holm-corrected over every test in this table.", "",
                "| metric | baseline | difference | p (Holm) |", "|---|---|---|---|"]
        out += _paired(rows, [(n, by[reference], by[n]) for n in names if n != reference])
    return "\n".join(line for line in out if line is not None).lstrip("\n") + "\n"


def _paired(rows: Sequence[tuple[str, str, Any]],
            groups: Sequence[tuple[str, Sequence[Mapping[str, Any]], Sequence[Mapping[str, Any]]]],
            keys: Sequence[str] = PAIRED) -> list[str]:
    """Table lines ``| metric | name | a − b | p (Holm) |`` for each metric of ``keys`` and each
    ``(name, a days, b days)``, paired by seed; Holm over every line."""
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
            tests.append((label, name, diff, _wilcoxon(diff)))
    adjusted = holm([p for *_, p in tests])
    return [f"| {label} | {n} | {_fmt(*_ci(list(diff)))} | {p:.3g} |"
            for (label, n, diff, _), p in zip(tests, adjusted, strict=True)]


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
                 "Paired over days (mean ± 95 % CI; negative is fewer/earlier); Wilcoxon signed-rank, "
                 "Holm-corrected over every test in this table.", "",
                 "| metric | strategy, scheduler | difference | p (Holm) |", "|---|---|---|---|"]
        lines += _paired(_metric_rows(types), [(f"`{lb}`, {n}", of[lb, n], of[first, n])
                                               for lb in labels[1:] for n in names], STRATEGY_PAIRED)
        text = "\n".join(parts) + "\n" + "\n".join(lines) + "\n"
    if failed:
        text += ("\nDays that did not run to their end (not in the tables above; stored with their error):\n\n"
                 + "\n".join(f"- `{r.get('strategy', 'default')}`, {r['scheduler']}, seed {r['seed']}: {r['error']}"
                             for r in failed) + "\n")
    return text
