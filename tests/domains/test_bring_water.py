"""A task folder written only from docs/domains.md (``fixtures/bring_water``), unlike the
bundled ones, runs in the shipped ``paper`` world with a scenario-declared glass; its
hazards and its person's waiting are in the trace and the metrics, with no change to any
file outside the folder."""

from __future__ import annotations

from pathlib import Path

import pytest

from experiments.run.runner import run_scenario
from planners.bundled import ENV_VAR

pytestmark = pytest.mark.slow  # its fixture runs the scenario in MuJoCo twice

FOLDER = Path(__file__).parent / "fixtures" / "bring_water"

@pytest.fixture(scope="module", params=["static", "planned"])
def run(request: pytest.FixtureRequest) -> object:
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv(ENV_VAR, str(FOLDER))
        return run_scenario(FOLDER / "scenario.toml", suspension=request.param, pictures=False)


def test_it_runs_to_the_end(run) -> None:  # type: ignore[no-untyped-def]
    assert [(e["task_type"], e["reason"]) for e in run.trace.of("end")] == [
        ("human_fell", "finished"), ("bring_water", "finished")]


def test_its_hazards_and_person_are_in_the_trace(run) -> None:  # type: ignore[no-untyped-def]
    held = run.trace.of("hazard", agent="d1", hazard="glass_held")
    assert [e["status"] for e in held][:2] == ["on", "off"] and held[0]["args"] == ["robot", "glass"]
    waiting = run.trace.of("role", agent="d1", role="waiting")
    assert waiting[0]["person"] == "sara" and waiting[0]["status"] == "on"
    susp = run.trace.of("plan", agent="d1", purpose="genSusp")[0]
    actions = [s["action"] for s in susp["stages"]]
    if run.trace.of("run")[0]["suspension"] == "static":  # the folder's rule: put it on a table
        assert actions == ["navigate", "put_on_table"]
    else:  # planned to the same goal (hand empty, glass not on the floor): a table, or Sara herself
        assert actions[0] == "navigate" and actions[-1] in ("put_on_table", "serve")
    assert not run.trace.of("hazard", hazard="glass_on_floor")


def test_its_hazards_and_person_are_in_the_metrics(run) -> None:  # type: ignore[no-untyped-def]
    safety, people = run.metrics["safety"], run.metrics["people"]
    assert safety["hazards"]["glass_held"]["episodes"] >= 1
    assert safety["hazards"]["glass_held"]["budget_s"] == 0.0
    assert people["people"]["d1"]["person"] == "sara" and people["people"]["d1"]["waiting_s"] > 0
    assert people["people"]["d2"]["time_to_help_s"] > 0  # the bundled human_fell, measured the same way
