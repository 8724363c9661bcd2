"""End to end: ``tasker run paper`` writes its outputs, is reproducible, and reproduces the
steps of Appendix B that follow from the costs — with the paper's rule (hysteresis 1.0) and
the ROS code's 0.9 — plus the counterfactuals that show the causes (John stands still;
Peter stays down); ``paper-2019`` is the reconstruction of ``experiments.paper.reconstruction``
and reproduces the steps its layout gives.  The 50-variant reproduction rates are
``tasker paper`` (``docs/paper.md``), not a test."""

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
from experiments.paper.report import Config, run_one
from experiments.run.runner import run_scenario
from tasker.trace import read

pytestmark = pytest.mark.slow  # every test reads whole runs of the paper scenarios

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
    return {0.9: as_dicts, 1.0: run_one(("paper", Config("seconds", 1.0), None))["steps"]}


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


# -- paper-2019: the layout reconstructed from the original verification's record -------------

def test_the_paper_2019_files_hold_the_reconstruction() -> None:
    """Every coordinate of the world and the scenario is reconstruction.derive()'s, shifted into the room."""
    import math

    from experiments.paper import reconstruction
    from robot.spec import load_world

    lay = reconstruction.derive()
    scn = scenarios.load(scenarios.resolve("paper-2019"))
    world = load_world(scn.world)
    shift = (2.5, 2.0)

    def at(p: tuple[float, float]) -> tuple[float, float]:
        return (round(p[0] + shift[0], 2), round(p[1] + shift[1], 2))

    def xy(pose: tuple[float, ...] | list[float]) -> tuple[float, float]:
        return (round(float(pose[0]), 2), round(float(pose[1]), 2))

    assert xy(world.places["alice_destination"]) == at(lay.alice_dest)
    assert xy(world.places["john_destination"]) == at(lay.john_dest)
    assert xy(world.people["alice"].pose) == at(lay.alice)
    assert xy(world.people["peter"].pose) == at(lay.peter)
    assert xy(world.robot.pose) == at(lay.robot)
    assert xy(world.people["john"].pose) == at(lay.john_walk[0][1])
    walk = [(round(t, 1), round(x, 2), round(y, 2)) for t, x, y in scn.people["john"]["walk"]]
    assert walk == [(round(t - 2507.6, 1), *at(p)) for t, p in lay.john_walk]
    assert xy(scn.people["sara"]["walk"][-1][1:]) == at(lay.sara)
    fastest = max(math.dist(a[1], b[1]) / (b[0] - a[0]) for a, b in zip(lay.john_walk, lay.john_walk[1:], strict=False))
    assert world.people["john"].speed == pytest.approx(fastest, abs=0.05)
    assert world.robot.max_speed == round(lay.robot_speed, 2)
    # the clock is the record's for the falls too: each at its recorded row, t = recorded t - CLOCK
    postures = {tuple(a.fields["value"]): round(a.t, 1) for a in scn.actions if a.kind == "world"}
    requests = {a.fields["args"]["person"]: round(a.t, 1) for a in scn.actions if a.kind == "request"}
    recorded = {e.what: round(e.t - reconstruction.CLOCK, 1) for e in reconstruction.EVENTS}
    assert postures[("peter", "fallen")] == requests["peter"] == recorded["Peter falls"]
    assert postures[("sara", "fallen")] == requests["sara"] == recorded["Sara falls"]
    assert postures[("peter", "standing")] == recorded["Peter gets up"]
    assert scn.people["sara"]["walk"][-1][0] <= recorded["Sara falls"]  # she is where she falls by then
    # the derivation reproduces the recorded distances it was made from
    assert all(abs(rec - got) < 1e-6 for _, what, rec, got in reconstruction.residuals(lay) if "guided" not in what)
    assert lay.fit_rms < 0.15


def test_the_robot_of_paper_2019_drives_at_the_fastest_recorded_fall_of_alices_path() -> None:
    """Step 7 of the reconstruction, by hand: Alice's recorded costs (f_stand 0.2) at 2519.0 and
    2521.1 were 1.312 and 1.236, her path 6.56 and 6.18 m: 0.38 m in 2.1 s, the fastest leg."""
    from experiments.paper import reconstruction

    legs = reconstruction.robot_legs()
    assert [(leg.t0, leg.t1) for leg in legs] == [(2508.6, 2512.7), (2512.7, 2514.8), (2514.8, 2516.8),
                                                 (2516.8, 2519.0), (2519.0, 2521.1)]
    assert reconstruction.derive().robot_speed == pytest.approx((1.312 - 1.236) / 0.2 / 2.1, abs=1e-3)
    assert max(legs, key=lambda leg: leg.speed).t0 == 2519.0
    assert reconstruction.CLOCK == 2508.6 - 1.0  # Alice's request at t = 1.0, her first comparison


@pytest.fixture(scope="module")
def paper_2019() -> list[dict[str, Any]]:
    return run_one(("paper-2019", Config("seconds", 0.9), None))["steps"]


def test_paper_2019_reproduces_steps_1_2_and_7_and_step_2_by_a_clear_margin(paper_2019: list[dict[str, Any]]) -> None:
    steps = paper_2019
    assert [steps[k]["ok"] for k in (0, 1, 6)] == [True, True, True], [steps[k]["detail"] for k in (0, 1, 6)]
    assert steps[1]["c_switch"] < (0.9 - KNIFE_EDGE) * steps[1]["c_wait"], steps[1]["detail"]


@pytest.mark.xfail(strict=True, reason=(
    "In paper-2019, with the robot at the record's speed, John's walk does not bring guide John's c_switch below "
    "0.9 of c_wait, as the shipped rule (the original code's) asks: docs/paper.md gives the closest comparison "
    "and its margin."))
def test_paper_2019_reproduces_step_3(paper_2019: list[dict[str, Any]]) -> None:
    assert paper_2019[2]["ok"], paper_2019[2]["detail"]


def test_the_original_model_is_chosen_per_request_with_each_persons_factors() -> None:
    from experiments.paper.report import scenario_for

    scn = scenario_for(("paper-2019", Config("taskER-2019", 0.9), None))
    args = {a.fields["args"]["person"]: a.fields["args"] for a in scn.actions if a.kind == "request"}
    assert args["john"] == {"person": "john", "destination": "john_destination", "cost_model": "taskER-2019",
                            "f_walk": 0.15, "f_stand": 0.15, "f_sit": 0.3}
    assert args["alice"]["f_walk"] == 0.2 and args["peter"] == {"person": "peter", "cost_model": "taskER-2019"}
    assert scn.scheduler_options["hysteresis"] == 0.9
    ours = scenario_for(("paper", Config("seconds", 1.0), 3))
    assert all("cost_model" not in a.fields["args"] for a in ours.actions if a.kind == "request")
    assert ours.scheduler_options["hysteresis"] == 1.0 and ours.seed == 3


def test_tasker_paper_writes_the_block_with_its_command_and_commit(tmp_path: Path,
                                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    from experiments.paper import report

    def fake(todo: list[report.Job], workers: int, done: Any = None) -> dict[report.Job, report.Run]:
        step = {"name": "s", "ok": True, "t": 1.0, "c_switch": 1.0, "c_wait": 2.0, "margin": 0.5, "detail": "d"}
        miss = {**step, "ok": False, "t": None, "c_switch": 3.0, "margin": -0.5}
        return {job: {"steps": [step, miss if job[2] == 1 else step],
                      "predictions": [{"agent": "d1", "t": 0.0, "predicted_s": 10.0, "realised_s": 11.0,
                                       "ended": True}]} for job in todo}

    monkeypatch.setattr(report, "run_all", fake)
    doc = tmp_path / "paper.md"
    doc.write_text(f"# prose\n\n{report.BEGIN}\nold\n{report.END}\n\nmore prose\n")
    assert main(["paper", "--variants", "2", "--out", str(doc), "--scenario", "paper-2019"]) == 0
    text = doc.read_text()
    assert text.startswith("# prose\n\n") and text.endswith("\n\nmore prose\n") and "\nold\n" not in text
    assert "`tasker paper --variants 2 --scenario paper-2019 --out " in text and "at commit `" in text
    assert "| 2 | s | yes +50.0 %; 1/2 |" in text  # the shipped run holds; variant 1 of 2 misses
    assert "taskER-2019, h = 0.9" in text and "`paper-2019`" in text and "`paper`:" not in text
    assert "| 2521.1 | taskER-2019 | 2.248 | 2.861 | +21.4 % | yes | yes | 2.248 | 2.861 |" in text
