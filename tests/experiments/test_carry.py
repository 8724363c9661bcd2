"""carry_object in MuJoCo: through a closed door, and a suspension that matters."""

from __future__ import annotations

from experiments.run.runner import run_scenario


def test_carry_opens_the_door_and_both_suspensions_close_it() -> None:
    planned = run_scenario("carry", suspension="planned", pictures=False)
    static = run_scenario("carry", suspension="static", pictures=False)
    for r in (planned, static):
        assert [e["reason"] for e in r.trace.of("end")] == ["finished", "finished"]
        up = r.trace.of("plan", agent="d1", purpose="upTsk")[0]
        assert "open_door" in [s["action"] for s in up["stages"]]  # the door is closed at first
    for r, strategy in ((planned, "planned"), (static, "static")):
        # strategies differ only in method: both pursue "hands free, the door closed"
        susp = r.trace.of("plan", agent="d1", purpose="genSusp")[0]
        assert susp["strategy"] == strategy and "close_door" in [s["action"] for s in susp["stages"]]
        assert r.metrics["safety"]["hazards"]["door_open"]["at_switch"] == 0
        assert r.metrics["safety"]["hazards"]["object_held"]["at_switch"] == 0
