"""The look-ahead with a rolling horizon (``horizon``): each decision orders the executing task and at most
``horizon`` waiting ones — the most urgent half, then Smith's order — and leaves the rest beyond it."""

from __future__ import annotations

import random
from dataclasses import replace

import pytest

from tasker import schedulers
from tasker.errors import ConfigError
from tasker.schedulers.base import UnattendedHazard
from tasker.schedulers.lookahead import LookAhead
from tests.tasker.test_lookahead_incremental import cand, queue, view


@pytest.mark.parametrize("bad", [-1, 1.5, True, "4", None])
def test_horizon_must_be_a_whole_number_of_jobs(bad: object) -> None:
    with pytest.raises(ConfigError, match="horizon"):
        schedulers.create("lookahead", horizon=bad)


@pytest.mark.parametrize("seed", range(8))
def test_a_horizon_as_long_as_the_queue_changes_nothing(seed: int) -> None:
    rng = random.Random(seed)
    waiting = queue(rng, rng.randint(1, 7))
    whole, wide = LookAhead(), LookAhead(horizon=len(waiting))
    for t in range(5):
        exe = cand("d1", 0, 100.0 - 5 * t) if seed % 2 else None
        a, b = whole.schedule(view(5.0 * t, exe, waiting)), wide.schedule(view(5.0 * t, exe, waiting))
        assert a == b and a.record is not None and "beyond" not in a.record


def test_the_window_holds_the_urgent_half_then_smiths_order_and_says_how_many_wait_beyond() -> None:
    # Smith's order (c_time / cps) is d2 < d3 < d4 < d5 < d6 < d7; d7's deadline is the nearest, d6's the next
    waiting = [cand(f"d{k}", k, float(k), cps=1.0) for k in range(2, 6)]
    waiting += [cand("d6", 6, 60.0, deadline=500.0), cand("d7", 7, 70.0, deadline=100.0)]
    s = LookAhead(horizon=4)
    kept, beyond = s.window(view(0.0, None, waiting))
    assert [c.id for c in kept.candidates] == ["d2", "d3", "d6", "d7"] and beyond == 2
    d = s.schedule(view(0.0, None, waiting))
    assert d.record is not None and d.record["beyond"] == 2 and sorted(d.record["order"]) == ["d2", "d3", "d6", "d7"]
    # a hazard whose budget runs out soon is urgent too, deadline or not
    left_on = [UnattendedHazard("d5", "cooker", 30.0, 0.0)]
    kept, _ = s.window(replace(view(0.0, cand("d1", 0, 50.0), waiting), hazards=left_on))
    assert [c.id for c in kept.candidates] == ["d2", "d3", "d5", "d7"]  # d5 (due at 30 s) and d7 (100 s) first


def test_an_odd_horizon_gives_the_urgent_half_rounded_up_and_no_more_than_have_a_deadline() -> None:
    waiting = [cand(f"d{k}", k, float(k)) for k in range(2, 9)] + [cand("d9", 9, 90.0, deadline=50.0)]
    kept, beyond = LookAhead(horizon=3).window(view(0.0, None, waiting))
    assert [c.id for c in kept.candidates] == ["d2", "d3", "d9"] and beyond == 5  # one urgent, two by Smith


def test_a_horizon_day_repeats_and_orders_at_most_the_horizon() -> None:
    rng = random.Random(11)
    waiting = queue(rng, 12)
    records = []
    for _ in range(2):
        s = LookAhead(horizon=5)
        out = [s.schedule(view(10.0 * t, cand("d1", 0, 200.0 - 10 * t), waiting[: 6 + t])) for t in range(6)]
        records.append(out)
        assert all(d.record is not None and len(d.record["order"]) <= 6 for d in out)
        assert all(d.record["beyond"] == 1 + t for t, d in enumerate(out) if d.record is not None)
    assert records[0] == records[1]
