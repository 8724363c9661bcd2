"""The statistics of a sweep report: means with Student-t intervals, paired t-tests, Holm's correction.

Numbers in, numbers out: nothing here knows about runs, metrics or strategies
(:mod:`experiments.analysis.compare` applies these to the rows of a results database).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

ALPHA = 0.05
"""The family-wise error rate Holm's correction controls over one report."""


@dataclass(frozen=True)
class Estimate:
    """A sample mean with its 95 % Student-t confidence interval (``half`` is NaN when n < 2)."""

    n: int
    mean: float
    std: float
    half: float

    @property
    def low(self) -> float:
        return self.mean - self.half

    @property
    def high(self) -> float:
        return self.mean + self.half


def estimate(values: Sequence[float], confidence: float = 0.95) -> Estimate:
    """Mean and Student-t confidence interval of ``values`` (finite numbers)."""
    from scipy import stats

    n = len(values)
    if n == 0:
        return Estimate(0, math.nan, math.nan, math.nan)
    mean = math.fsum(values) / n
    if n < 2:
        return Estimate(1, mean, math.nan, math.nan)
    std = math.sqrt(math.fsum((v - mean) ** 2 for v in values) / (n - 1))
    half = float(stats.t.ppf(0.5 + confidence / 2, n - 1)) * std / math.sqrt(n)
    return Estimate(n, mean, std, half)


def paired_p(diffs: Sequence[float]) -> float:
    """Two-sided p-value of the paired t-test (H0: mean difference 0); NaN when it does not apply.

    Differences that are all equal and non-zero give 0 (no variance, a sure effect); all zero, NaN."""
    from scipy import stats

    e = estimate(diffs)
    if e.n < 2:
        return math.nan
    if e.std == 0:
        return math.nan if e.mean == 0 else 0.0
    t = e.mean / (e.std / math.sqrt(e.n))
    return float(2 * stats.t.sf(abs(t), e.n - 1))


def holm(pvalues: Sequence[float]) -> list[float]:
    """Holm's step-down adjusted p-values (NaN stays NaN and is not counted in the family).

    Sorted ascending, ``p_(i)`` becomes ``max_{j<=i} min(1, (m - j + 1) p_(j))`` with ``m`` the
    number of tests; reject where the adjusted value is below :data:`ALPHA`."""
    idx = sorted((i for i, p in enumerate(pvalues) if not math.isnan(p)), key=lambda i: (pvalues[i], i))
    m = len(idx)
    out = [math.nan] * len(pvalues)
    running = 0.0
    for rank, i in enumerate(idx):
        running = max(running, min(1.0, (m - rank) * pvalues[i]))
        out[i] = running
    return out
