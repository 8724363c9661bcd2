"""What tasker run says of a run's safety (issue 36, item 5), and the hazard stretches the report draws."""

from __future__ import annotations

import pytest

from experiments.metrics import run as metrics
from experiments.metrics.exposure import Stretch, stretches
from experiments.report import summary
from experiments.trace.timeline import Timeline
from tests.experiments.test_metrics import Build


def _kettle_forgotten() -> Build:
    """d1 turns a kettle on at 5 and ends at 10 without turning it off; the run ends at 45."""
    b = Build().request(0, "d1", "kettle").go(0, "d1", "initComm", "compSP", "upTsk", "exeTsk")
    b.add(5, "hazard", agent="d1", hazard="kettle_on", args=["kettle"], fact=["kettle_on", "kettle"], status="on",
          budget_s=0.0)
    b.end(10, "d1")
    b.add(0, "hazard", agent=None, hazard="door_open", args=["d9"], fact=["open", "d9"], status="on", budget_s=60.0)
    return b.add(45, "mode", mode="IT")


def test_a_forgotten_hazard_is_said_with_its_budget_and_what_came_after_its_owner() -> None:
    b = _kettle_forgotten()
    b.events.sort(key=lambda e: e["t"])
    tl = Timeline.of(b.events)
    lines = summary.safety(tl, metrics.compute(tl))
    assert lines[0] == "  safety:"
    assert ("  hazard kettle_on(kettle) of d1 kettle: 35.0 s unattended against a budget of 0 s, OVER by 35.0 s "
            "(35.0 s of it after d1 ended); still on when the run ended") in lines
    assert any(line.startswith("  nobody owns 1 hazard episode") and "so in the world file" in line for line in lines)


def test_a_run_that_left_nothing_unsafe_says_so_in_one_line() -> None:
    b = Build().request(0, "d1").go(0, "d1", "initComm", "compSP", "upTsk", "exeTsk").end(5, "d1")
    tl = Timeline.of(b.events)
    assert summary.safety(tl, metrics.compute(tl)) == [
        "  safety: every suspension safe, no declared hazard left unattended"]
    assert summary.headline("x", tl, metrics.compute(tl), 1.0) == \
        "x: 1 tasks, 1 ended (1 finished), 0 suspensions (0 safe), 5.0 s simulated in 1.0 s"


def test_stretches_tell_attended_unattended_over_budget_and_nobodys_apart() -> None:
    b = Build().request(0, "d1").go(0, "d1", "initComm", "compSP", "upTsk", "exeTsk")
    b.add(2, "hazard", agent="d1", hazard="cooker_on", args=["cooker"], fact=["cooker_on", "cooker"], status="on",
          budget_s=10.0)
    b.go(6, "d1", "exeTsk", "genSusp", "exeSusp").go(8, "d1", "exeSusp", "wait")  # unattended from 8
    b.go(30, "d1", "wait", "upTsk", "exeTsk")  # 22 s unattended: 10 within budget, 12 over
    b.add(35, "hazard", agent="d1", hazard="cooker_on", args=["cooker"], fact=["cooker_on", "cooker"], status="off",
          budget_s=10.0)
    b.add(1, "hazard", agent=None, hazard="door_open", args=["d9"], fact=["open", "d9"], status="on", budget_s=60.0)
    b.events.sort(key=lambda e: e["t"])
    got = [(s.owner, s.start, s.end, s.kind) for s in stretches(Timeline.of(b.events))]
    assert got == [(None, 1, 35, "nobody's"), ("d1", 2, 8, "attended"), ("d1", 8, 18, "unattended"),
                   ("d1", 18, 30, "over budget"), ("d1", 30, 35, "attended")]


def test_a_stretch_checks_its_kind_and_its_ends() -> None:
    with pytest.raises(ValueError, match="kind"):
        Stretch("d1", "x", 0.0, 1.0, "ignored")
    with pytest.raises(ValueError, match="before start"):
        Stretch("d1", "x", 2.0, 1.0, "attended")
