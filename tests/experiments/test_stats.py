"""The statistics of the sweep report: Student-t intervals, the paired t-test, Holm's correction."""

from __future__ import annotations

import math

import pytest
from scipy import stats

from experiments.analysis.stats import estimate, holm, paired_p


def test_estimate_is_the_student_t_interval() -> None:
    values = [1.0, 2.0, 4.0, 7.0]
    e = estimate(values)
    low, high = stats.t.interval(0.95, len(values) - 1, loc=sum(values) / 4, scale=stats.sem(values))
    assert (e.n, e.low, e.high) == (4, pytest.approx(low), pytest.approx(high))
    one = estimate([3.0])
    assert one.mean == 3.0 and math.isnan(one.half)
    assert estimate([]).n == 0


def test_holm_against_a_hand_computed_example() -> None:
    # sorted: 0.005*4 = 0.02, 0.01*3 = 0.03, 0.03*2 = 0.06, 0.04*1 = 0.04 -> kept monotone at 0.06
    adjusted = holm([0.01, 0.04, 0.03, 0.005, math.nan])
    assert adjusted[:4] == [pytest.approx(0.03), pytest.approx(0.06), pytest.approx(0.06), pytest.approx(0.02)]
    assert math.isnan(adjusted[4])  # no test, not in the family
    assert holm([0.5, 0.9]) == [pytest.approx(1.0), pytest.approx(1.0)]  # capped at 1


def test_paired_p_is_the_paired_t_test() -> None:
    d = [1.0, 2.0, 0.5, 3.0, -0.2]
    assert paired_p(d) == pytest.approx(stats.ttest_1samp(d, 0.0).pvalue)
    assert paired_p([1.0, 1.0]) == 0.0 and math.isnan(paired_p([0.0, 0.0]))
