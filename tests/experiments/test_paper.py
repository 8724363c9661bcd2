"""End to end: ``tasker run paper`` writes its outputs, is reproducible, and reproduces the
steps of Appendix B that follow from the costs — with the paper's rule (hysteresis 1.0) and
the ROS code's 0.9 — plus the counterfactuals that show the causes (John stands still;
Peter stays down).  The 50-variant reproduction rate is ``python -m experiments.paper.report``
(``docs/paper.md``), not a test."""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from experiments.cli import main
from experiments.inputs import scenario as scenarios
from experiments.paper import appendix_b
from experiments.paper.report import run_one
from experiments.run.runner import run_scenario
from tasker.trace import read

COST_STEPS = (1, 4)  # indices of the steps Alg. 2 decides by comparing costs and that happen
HOLDING = (0, 1, 4, 5, 6)  # the steps that follow from the costs and the scenario's events
KNIFE_EDGE = 0.1  # a cost step must win by at least this fraction of c_wait beyond the hysteresis


@pytest.fixture(scope="module")
def paper_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("paper") / "paper"
    assert main(["run", "paper", "--out", str(out)]) == 0
    return out


@pytest.fixture(scope="module")
def checked(paper_run: Path) -> dict[float, list[dict[str, Any]]]:
    """Appendix B checked on the shipped run (hysteresis 0.9) and on a run with the paper's 1.0."""
    shipped = appendix_b.check(read(paper_run / "trace.jsonl"))
    as_dicts = [{"ok": s.ok, "t": s.t, "c_switch": s.c_switch, "c_wait": s.c_wait, "detail": s.detail,
                 "name": s.name} for s in shipped]
    return {0.9: as_dicts, 1.0: run_one((1.0, None, "paper"))["steps"]}


def _events(change: Callable[[scenarios.RobotScenario], scenarios.RobotScenario]) -> list[dict[str, Any]]:
    scn = change(scenarios.load(scenarios.resolve("paper")))
    return list(run_scenario(scn, seed=scn.seed, pictures=False).trace.events)


def test_paper_run_writes_its_outputs_and_is_reproducible(paper_run: Path, tmp_path: Path) -> None:
    for name in ("run.json", "metrics.json", "timeline.png", "gantt.png", "world.png"):
        assert (paper_run / name).stat().st_size > 0, name
    metrics = json.loads((paper_run / "metrics.json").read_text())
    assert metrics["switching"]["switches"] >= 3
    # the same scenario and seed give the same trace, byte for byte
    again = tmp_path / "again"
    assert main(["run", "paper", "--out", str(again), "--no-pictures"]) == 0
    assert (again / "trace.jsonl").read_bytes() == (paper_run / "trace.jsonl").read_bytes()


@pytest.mark.parametrize("hysteresis", [1.0, 0.9])
def test_the_steps_that_follow_from_the_costs_hold_by_clear_margins(
        checked: dict[float, list[dict[str, Any]]], hysteresis: float) -> None:
    steps = checked[hysteresis]
    failed = [f"{steps[k]['name']}: {steps[k]['detail']}" for k in HOLDING if not steps[k]["ok"]]
    assert not failed, failed
    for k in COST_STEPS:
        s = steps[k]
        assert s["c_switch"] < (hysteresis - KNIFE_EDGE) * s["c_wait"], f"knife-edge: {s['name']}: {s['detail']}"
    times = [steps[k]["t"] for k in HOLDING]
    assert times == sorted(times), "the steps must happen in the paper's order"


@pytest.mark.xfail(strict=True, reason=(
    "Step 3 does not follow from the costs with Fig. 10's two destinations: while guide Alice runs, "
    "guide John stays the longer task, so c_switch never falls below c_wait (docs/paper.md: the closest "
    "comparison and its margin); without step 3 John is being greeted again, not guided, when Peter "
    "falls, so step 4's 'while John is guided' fails too."))
@pytest.mark.parametrize("hysteresis", [1.0, 0.9])
def test_tasker_run_paper_reproduces_all_of_appendix_b(
        checked: dict[float, list[dict[str, Any]]], hysteresis: float) -> None:
    steps = checked[hysteresis]
    failed = [f"{s['name']}: {s['detail']}" for s in steps if not s["ok"]]
    assert not failed, failed


def test_counterfactual_john_stands_still_so_guide_john_does_not_take_back_over() -> None:
    """Without John's walk his task cannot get cheaper while it waits: no cost decision puts
    d1 back over d2 before Peter falls."""
    def still(scn: scenarios.RobotScenario) -> scenarios.RobotScenario:
        people = {**scn.people, "john": {**scn.people["john"], "walk": []}}  # [] also drops the world file's walk
        return dataclasses.replace(scn, people=people)

    events = _events(still)
    fell = min(e["t"] for e in events if e["event"] == "request" and e.get("agent") == "d3")
    back = [e for e in events if e["event"] == "decision" and e.get("dac") == "d1" and e.get("exeDA") == "d2"
            and e.get("switch") and e["t"] < fell]
    assert not back, back
    assert appendix_b.check(events)[1].ok  # guide Alice still takes over, by cost


def test_counterfactual_peter_stays_down_so_his_task_does_not_end_from_wait() -> None:
    """Step 6 is caused by Peter getting up: without it, d3 is resumed and runs to its end."""
    def down(scn: scenarios.RobotScenario) -> scenarios.RobotScenario:
        up = ["peter", "standing"]
        kept = tuple(a for a in scn.actions if not (a.kind == "world" and a.fields.get("value") == up))
        assert len(kept) == len(scn.actions) - 1, "the scenario lets Peter get up exactly once"
        return dataclasses.replace(scn, actions=kept)

    events = _events(down)
    ends = [e for e in events if e["event"] == "transition" and e.get("agent") == "d3" and e.get("to") == "end"]
    assert ends and ends[0]["from"] != "wait", ends
    end = next(e for e in events if e["event"] == "end" and e.get("agent") == "d3")
    assert end["cause"] == "finished", end
    assert not appendix_b.check(events)[5].ok


def test_the_checker_survives_inf_and_never_credits_a_non_finite_comparison(paper_run: Path) -> None:
    events = [dict(e) for e in read(paper_run / "trace.jsonl")]
    assert appendix_b.check(events)[1].ok
    # the deciding comparison of step 2, with an infinite side as the trace writes it
    d = next(e for e in events if e["event"] == "decision" and e.get("dac") == "d2" and e.get("switch"))
    d["c_wait"] = "inf"
    step = appendix_b.check(events)[1]
    assert not step.ok and step.margin is None and "inf" in step.detail
    # every number of the trace may be non-finite or missing: the checker still answers
    broken = [{**e, **{k: "inf" for k in ("c_switch", "c_wait", "cTime_dac", "cTime_exeDA") if k in e}}
              for e in events]
    assert len(appendix_b.check(broken)) == 7


def test_the_report_replaces_only_its_block() -> None:
    from experiments.paper.report import BEGIN, END, splice

    text = f"# title\n\nprose\n\n{BEGIN}\nold\n{END}\n\nmore prose\n"
    out = splice(text, f"{BEGIN}\nnew\n{END}\n")
    assert out == f"# title\n\nprose\n\n{BEGIN}\nnew\n{END}\n\nmore prose\n"
    assert splice("no markers\n", f"{BEGIN}\nx\n{END}\n").endswith(f"\n\n{BEGIN}\nx\n{END}\n")
