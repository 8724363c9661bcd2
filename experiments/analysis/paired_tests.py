"""Paired tests for the question an experiment asks, with effect sizes and the pairs they need.

Two strategies run on the same seeds (the same randomised variant), so every comparison is
paired.  For a **binary** outcome (was every suspension safe?) the exact McNemar test counts
only the discordant pairs; for **seconds** (hazard time unattended) the Wilcoxon signed-rank
test ranks the non-zero paired differences.  Each comes with an effect size and a 95 %
interval — the paired difference in proportions, or the mean difference in seconds, both
with a seeded percentile bootstrap over pairs — and no verdict below :data:`MIN_PAIRS`
informative pairs ("too few pairs"): with fewer, no Holm-adjusted p-value of a family of
sixteen can fall below 0.05 however large the effect (an exact two-sided test of n
discordant pairs cannot go below 2 / 2^n).

:func:`required_pairs` turns a pilot's variances into the number of pairs a test needs.
"""

from __future__ import annotations

import math
import random
from collections.abc import Sequence
from dataclasses import dataclass

MIN_PAIRS = 10
"""Below this many informative pairs (discordant, or with a non-zero difference) a test gives no
verdict: 2 / 2**9 = 0.0039 > 0.05 / 16, so nine pairs could never pass Holm in a family of 16."""

BOOTSTRAP = 4000
"""Bootstrap resamples for the intervals (seeded: the same pairs give the same interval)."""


@dataclass(frozen=True)
class Effect:
    """An effect and its 95 % interval; ``n`` pairs in all, ``informative`` of them counted by the test."""

    estimate: float
    low: float
    high: float
    n: int
    informative: int
    p: float
    test: str

    @property
    def enough(self) -> bool:
        return self.informative >= MIN_PAIRS


def bootstrap_interval(diffs: Sequence[float], seed: str) -> tuple[float, float]:
    """95 % percentile interval of the mean of ``diffs``, resampling pairs (seeded)."""
    if not diffs:
        return math.nan, math.nan
    rng = random.Random(f"bootstrap:{seed}")
    n = len(diffs)
    means = sorted(math.fsum(diffs[rng.randrange(n)] for _ in range(n)) / n for _ in range(BOOTSTRAP))
    return means[int(0.025 * BOOTSTRAP)], means[int(0.975 * BOOTSTRAP) - 1]


def mcnemar(baseline: Sequence[bool], treatment: Sequence[bool], *, seed: str = "") -> Effect:
    """Exact McNemar on paired binary outcomes: the effect is the difference in proportions
    (treatment − baseline), its interval bootstrapped over pairs; ``informative`` the discordant pairs."""
    from scipy import stats

    if len(baseline) != len(treatment):
        raise ValueError("mcnemar: the two arms must be paired (same length)")
    up = sum(1 for a, b in zip(baseline, treatment, strict=True) if b and not a)
    down = sum(1 for a, b in zip(baseline, treatment, strict=True) if a and not b)
    n = len(baseline)
    diffs = [float(b) - float(a) for a, b in zip(baseline, treatment, strict=True)]
    p = float(stats.binomtest(up, up + down, 0.5).pvalue) if up + down else 1.0
    low, high = bootstrap_interval(diffs, seed)
    return Effect(math.fsum(diffs) / n if n else math.nan, low, high, n, up + down, p, "exact McNemar")


def wilcoxon(baseline: Sequence[float], treatment: Sequence[float], *, seed: str = "") -> Effect:
    """Wilcoxon signed-rank on paired seconds (zero differences dropped: an identical pair says
    nothing either way); the effect is the mean difference (treatment − baseline) with a bootstrap interval."""
    from scipy import stats

    if len(baseline) != len(treatment):
        raise ValueError("wilcoxon: the two arms must be paired (same length)")
    diffs = [b - a for a, b in zip(baseline, treatment, strict=True)]
    nonzero = [d for d in diffs if abs(d) > 1e-9]
    p = float(stats.wilcoxon(nonzero).pvalue) if len(nonzero) >= 1 and any(nonzero) else 1.0
    low, high = bootstrap_interval(diffs, seed)
    n = len(diffs)
    return Effect(math.fsum(diffs) / n if n else math.nan, low, high, n, len(nonzero), p, "Wilcoxon signed-rank")


def required_pairs(*, discordant: float | None = None, difference: float | None = None,
                   sd: float | None = None, delta: float | None = None, alpha: float = 0.05 / 16,
                   power: float = 0.8) -> int | None:
    """Pairs needed for a two-sided test at ``alpha`` with ``power``.

    Binary (McNemar, Connor's approximation): ``discordant`` is the share of discordant pairs
    and ``difference`` the difference in proportions.  Seconds (paired, normal approximation):
    ``sd`` of the paired differences and the difference ``delta`` worth detecting.  None when
    the pilot gives nothing to size (no discordant pairs, no spread)."""
    from scipy import stats

    z = stats.norm.ppf(1 - alpha / 2) + stats.norm.ppf(power)
    if discordant is not None and difference is not None:
        if discordant <= 0 or difference == 0:
            return None
        return math.ceil(z ** 2 * discordant / difference ** 2)
    if sd is not None and delta is not None:
        if sd <= 0 or delta <= 0:
            return None
        return math.ceil((z * sd / delta) ** 2)
    raise ValueError("required_pairs: give discordant and difference, or sd and delta")
