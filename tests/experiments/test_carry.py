"""carry_object in MuJoCo: through a closed door, and a suspension that matters."""

from __future__ import annotations

from experiments.runner import run_scenario


def test_carry_opens_the_door_and_planned_suspension_closes_it() -> None:
    planned = run_scenario("carry", suspension="planned", pictures=False)
    static = run_scenario("carry", suspension="static", pictures=False)
    for r in (planned, static):
        assert [e["reason"] for e in r.trace.of("end")] == ["finished", "finished"]
        up = r.trace.of("plan", agent="d1", purpose="upTsk")[0]
        assert "open_door" in [s["action"] for s in up["stages"]]  # the door is closed at first
    susp = planned.trace.of("plan", agent="d1", purpose="genSusp")[0]
    assert susp["strategy"] == "planned" and "close_door" in [s["action"] for s in susp["stages"]]
    assert planned.metrics["safety"]["hazards"]["door_open"]["at_switch"] == 0
    assert static.metrics["safety"]["hazards"]["door_open"]["at_switch"] == 1  # eq. 47's tree only puts the vase down
