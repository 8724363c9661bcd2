"""A pre-declared family of paired tests: scenario × contrast × outcome, Holm-adjusted together.

An experiment declares, before any run, which comparisons it makes (a :class:`Contrast`: one
factor of the strategy changed, every other held), on which outcomes (an :class:`Outcome`:
a binary one tested with the exact McNemar test, or seconds with the Wilcoxon signed-rank
test) and in which scenarios.  :func:`run_family` pairs the stored runs by seed — the same
randomised variant under the two strategies — and tests each (scenario, contrast, outcome)
once: the family has exactly the declared tests, whatever the data say, and Holm's
adjustment is over all of them (a test with too few informative pairs stays in the family
with the p-value it has, which only makes the others stricter).  :func:`pilot_sizes` reads a
pilot's variances and says how many pairs each test needs.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from experiments.analysis.paired_tests import MIN_PAIRS, Effect, mcnemar, required_pairs, wilcoxon
from experiments.analysis.stats import ALPHA, holm
from experiments.inputs.strategy import FACTORS, Strategy
from experiments.metrics.registry import Direction, direction, numeric_metrics
from experiments.metrics.store import RunRow, Status

BINARY, SECONDS = "binary", "seconds"


@dataclass(frozen=True)
class Outcome:
    """A primary outcome: the metric, how it is tested, and — for seconds — the smallest difference
    worth detecting (what a pilot sizes for)."""

    metric: str
    kind: str
    label: str
    delta: float | None = None

    def __post_init__(self) -> None:
        if self.kind not in (BINARY, SECONDS):
            raise ValueError(f"Outcome.kind: expected {BINARY!r} or {SECONDS!r}, got {self.kind!r}")


@dataclass(frozen=True)
class Contrast:
    """``factor`` at ``treatment`` against ``factor`` at ``baseline``, every other factor held."""

    factor: str
    baseline: str
    treatment: str

    def __post_init__(self) -> None:
        if self.factor not in FACTORS:
            raise ValueError(f"Contrast.factor: expected one of {list(FACTORS)}, got {self.factor!r}")

    @property
    def name(self) -> str:
        return f"{self.treatment} vs {self.baseline}"

    def partner(self, label: str) -> str | None:
        """The baseline strategy paired with the treatment strategy ``label`` (None if ``label`` is not
        at the treatment level)."""
        st = Strategy.parse(label)
        if _level(getattr(st, self.factor)) != self.treatment:
            return None
        values = dict(st.items())
        values[self.factor] = _parse_level(self.factor, self.baseline)
        return Strategy(**values).label


def _level(value: object) -> str:
    return ("on" if value else "off") if isinstance(value, bool) else str(value)


def _parse_level(factor: str, level: str) -> object:
    return level == "on" if factor == "hazard_waiting" else level


@dataclass(frozen=True)
class Test:
    """One test of the family: its effect (treatment − baseline), and the Holm-adjusted p."""

    scenario: str
    contrast: Contrast
    outcome: Outcome
    effect: Effect
    p_holm: float
    missing: int
    """Seeds with the treatment run but no usable baseline (or the metric absent from either)."""

    @property
    def verdict(self) -> str:
        """``no pairs`` (nothing to compare yet), ``identical``, ``too few pairs``, ``no significant
        difference``, or which arm the outcome's registered direction favours (``treatment better`` /
        ``baseline better``)."""
        if self.effect.n == 0:
            return "no pairs"
        if self.effect.informative == 0:
            return "identical"
        if not self.effect.enough:
            return "too few pairs"
        if self.p_holm >= ALPHA:
            return "no significant difference"
        better_higher = direction(self.outcome.metric) is Direction.HIGHER
        return "treatment better" if (self.effect.estimate > 0) == better_higher else "baseline better"


def _pairs(rows: Iterable[RunRow], scenario: str, contrast: Contrast,
           metric: str) -> tuple[list[float], list[float], int]:
    """(baseline values, treatment values, seeds missing a partner), paired by seed and by every other
    factor (a spec with several contexts gives one pair per seed and context)."""
    ok = {(r.seed, r.strategy): numeric_metrics(r.metrics) for r in rows
          if r.scenario == scenario and r.status is Status.OK}
    base: list[float] = []
    treat: list[float] = []
    missing = 0
    for (seed, label), m in sorted(ok.items()):
        partner = contrast.partner(label)
        if partner is None:
            continue
        b = ok.get((seed, partner))
        if b is None or metric not in m or metric not in b or not (math.isfinite(m[metric])
                                                                    and math.isfinite(b[metric])):
            missing += 1
            continue
        base.append(b[metric])
        treat.append(m[metric])
    return base, treat, missing


def _effect(outcome: Outcome, base: Sequence[float], treat: Sequence[float], seed: str) -> Effect:
    if outcome.kind == BINARY:
        return mcnemar([v > 0.5 for v in base], [v > 0.5 for v in treat], seed=seed)
    return wilcoxon(base, treat, seed=seed)


def run_family(rows: Sequence[RunRow], scenarios: Sequence[str], contrasts: Sequence[Contrast],
               outcomes: Sequence[Outcome]) -> list[Test]:
    """Every declared test (scenario-major, then contrast, then outcome), Holm-adjusted together."""
    raw: list[tuple[str, Contrast, Outcome, Effect, int]] = []
    for sc in scenarios:
        for c in contrasts:
            for o in outcomes:
                base, treat, missing = _pairs(rows, sc, c, o.metric)
                raw.append((sc, c, o, _effect(o, base, treat, f"{sc}|{c.name}|{o.metric}"), missing))
    adjusted = holm([e.p for *_, e, _ in raw]) if raw else []
    return [Test(sc, c, o, e, a, missing) for (sc, c, o, e, missing), a in zip(raw, adjusted, strict=True)]


@dataclass(frozen=True)
class Size:
    """What a pilot says one test needs: the pilot's pairs, what it measured, and the pairs required
    (None when the pilot gives nothing to size: no discordant pairs, no spread, no difference)."""

    scenario: str
    contrast: Contrast
    outcome: Outcome
    pairs: int
    discordant: float | None
    difference: float | None
    sd: float | None
    required: int | None


def pilot_sizes(rows: Sequence[RunRow], scenarios: Sequence[str], contrasts: Sequence[Contrast],
                outcomes: Sequence[Outcome], *, family_size: int | None = None, power: float = 0.8) -> list[Size]:
    """Pairs each declared test needs at the Bonferroni level of the family (α / m, the first
    step of Holm's procedure: the conservative size), from the pilot's runs: for a binary outcome
    its share of discordant pairs and its difference in proportions, for seconds the SD of the
    paired differences against the outcome's ``delta``."""
    m = family_size or len(scenarios) * len(contrasts) * len(outcomes)
    out = []
    for sc in scenarios:
        for c in contrasts:
            for o in outcomes:
                base, treat, _ = _pairs(rows, sc, c, o.metric)
                n = len(base)
                if o.kind == BINARY:
                    up = sum(1 for a, b in zip(base, treat, strict=True) if b > 0.5 >= a)
                    down = sum(1 for a, b in zip(base, treat, strict=True) if a > 0.5 >= b)
                    disc = (up + down) / n if n else None
                    diff = (up - down) / n if n else None
                    need = (required_pairs(discordant=disc, difference=diff, alpha=ALPHA / m, power=power)
                            if disc is not None and diff is not None else None)
                    out.append(Size(sc, c, o, n, disc, diff, None, need))
                else:
                    diffs = [b - a for a, b in zip(base, treat, strict=True)]
                    mean = math.fsum(diffs) / n if n else None
                    sd = (math.sqrt(math.fsum((d - mean) ** 2 for d in diffs) / (n - 1))
                          if n > 1 and mean is not None else None)
                    need = (required_pairs(sd=sd, delta=o.delta, alpha=ALPHA / m, power=power)
                            if sd is not None and o.delta is not None else None)
                    out.append(Size(sc, c, o, n, None, mean, sd, need))
    return out


__all__ = ["BINARY", "MIN_PAIRS", "SECONDS", "Contrast", "Outcome", "Size", "Test", "pilot_sizes", "run_family"]
