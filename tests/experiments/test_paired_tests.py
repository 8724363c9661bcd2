"""The experiment's paired tests: exact McNemar, Wilcoxon, bootstrap intervals, pairs needed."""

from __future__ import annotations

import math

import pytest

from experiments.analysis.paired_tests import MIN_PAIRS, mcnemar, required_pairs, wilcoxon


def test_mcnemar_counts_only_discordant_pairs() -> None:
    base = [False] * 12 + [True] * 20 + [True] * 2
    treat = [True] * 12 + [True] * 20 + [False] * 2
    e = mcnemar(base, treat, seed="x")
    assert e.informative == 14 and e.n == 34 and e.enough
    assert e.estimate == pytest.approx(10 / 34)
    assert e.p == pytest.approx(2 * sum(math.comb(14, k) for k in range(0, 3)) / 2 ** 14)
    assert e.low < e.estimate < e.high


def test_no_discordant_pair_is_no_evidence() -> None:
    e = mcnemar([True] * 40, [True] * 40)
    assert (e.p, e.informative, e.enough, e.estimate) == (1.0, 0, False, 0.0)


def test_wilcoxon_drops_identical_pairs_and_reports_the_mean_difference() -> None:
    base = [10.0] * 30 + [float(k) for k in range(15)]
    treat = [10.0] * 30 + [float(k) - 3.0 for k in range(15)]
    e = wilcoxon(base, treat, seed="y")
    assert e.informative == 15 and e.n == 45
    assert e.estimate == pytest.approx(-1.0) and e.high <= 0.0 and e.p < 0.001


def test_too_few_pairs_has_no_verdict_however_large_the_effect() -> None:
    e = wilcoxon([0.0] * (MIN_PAIRS - 1), [100.0] * (MIN_PAIRS - 1))
    assert not e.enough


def test_the_same_pairs_give_the_same_interval() -> None:
    base, treat = [float(k % 7) for k in range(50)], [float(k % 5) for k in range(50)]
    assert wilcoxon(base, treat, seed="s") == wilcoxon(base, treat, seed="s")


def test_pairs_needed_grow_as_the_effect_shrinks() -> None:
    small = required_pairs(discordant=0.2, difference=0.05)
    large = required_pairs(discordant=0.2, difference=0.15)
    assert small is not None and large is not None and small > large
    from scipy.stats import norm

    z = norm.ppf(1 - 0.05 / 32) + norm.ppf(0.8)  # Holm's first step in a family of 16, power 0.8
    assert required_pairs(sd=60.0, delta=30.0) == math.ceil((z * 2) ** 2)
    assert required_pairs(discordant=0.0, difference=0.1) is None
