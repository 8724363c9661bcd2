"""Day protocols: strict reading, reproducible days, every scheduler on every task type, metrics by hand."""

from __future__ import annotations

from pathlib import Path

import pytest

from experiments.analysis import stats
from experiments.days import draw as day_draw
from experiments.days import pipeline as day_pipeline
from experiments.days import protocol
from experiments.days import runner as day_runner
from experiments.days import table as day_table
from experiments.metrics import day as day_metrics_mod
from tasker import schedulers
from tasker.support.reader import InputError
from tests.experiments.events import complete

TABSA = Path(__file__).resolve().parents[2] / "experiments" / "days" / "protocols" / "tabsa.toml"


@pytest.fixture(scope="module")
def tabsa() -> protocol.Protocol:
    return protocol.load(TABSA)


def test_the_shipped_protocol_reads(tabsa: protocol.Protocol) -> None:
    assert set(tabsa.tasks) == {"transport", "fall", "pick_place"}
    assert tabsa.robot_speed == 0.5 and tabsa.step_s == 5.0 and tabsa.length_s == 4 * 3600
    assert all(s.count == 12 for s in tabsa.tasks.values())
    assert tabsa.death_after_s == 900.0


def test_a_day_is_reproducible_per_seed(tabsa: protocol.Protocol) -> None:
    a, b, c = day_draw.generate(tabsa, 7), day_draw.generate(tabsa, 7), day_draw.generate(tabsa, 8)
    assert a.actions == b.actions and a.actions != c.actions
    assert len(a.actions) == 36
    falls = [x.fields["args"] for x in a.actions if x.fields["task"] == "fall"]
    assert all(f["death_at"] == pytest.approx(f["deadline"] + 900.0) for f in falls)
    assert all(60.0 <= f["work"] <= 300.0 for f in falls)
    t1 = day_pipeline.build_day(tabsa, 7, "lookahead").run().dumps()
    t2 = day_pipeline.build_day(tabsa, 7, "lookahead").run().dumps()
    assert t1 == t2  # byte for byte


@pytest.mark.parametrize("name", schedulers.names())
def test_every_scheduler_runs_every_task_type(tabsa: protocol.Protocol, name: str) -> None:
    trace = day_pipeline.build_day(tabsa, 2, name, day_runner.scheduler_options(tabsa, name)).run()
    finished = {e["task_type"] for e in trace.of("end", cause="finished")}
    assert finished == {"transport", "fall", "pick_place"}
    assert not trace.of("end", cause="failed")


def test_a_transport_interrupted_while_escorting_asks_to_wait_and_goes_back(tabsa: protocol.Protocol) -> None:
    trace = day_pipeline.build_day(tabsa, 2, "alg2", day_runner.scheduler_options(tabsa, "alg2")).run()
    susp = [e for e in trace.of("plan", purpose="genSusp") if e["stages"]]
    assert susp, "day 2 under alg2 interrupts a task mid-motion"
    agent = susp[0]["agent"]
    resumed = [e for e in trace.of("plan", purpose="upTsk", agent=agent)][1]
    assert resumed["stages"][0]["action"] == "go_back"


def write(tmp_path: Path, text: str) -> Path:
    p = tmp_path / "p.toml"
    p.write_text(text, encoding="utf-8")
    return p


def test_bad_protocols_name_file_line_and_field(tmp_path: Path) -> None:
    text = TABSA.read_text(encoding="utf-8")
    with pytest.raises(InputError, match=r"p\.toml:\d+: tasks\.fal: unknown task type 'fal'; did you mean 'fall'"):
        protocol.load(write(tmp_path, text.replace("[tasks.fall]", "[tasks.fal]")))
    with pytest.raises(InputError, match=r"tasks\.fall\.work_s: expected low <= high"):
        protocol.load(write(tmp_path, text.replace("work_s = [60.0, 300.0]", "work_s = [300.0, 60.0]")))
    with pytest.raises(InputError, match=r"robot\.start_site: no site 'hal'; did you mean 'hall'"):
        protocol.load(write(tmp_path, text.replace('start_site = "hall"', 'start_site = "hal"')))
    with pytest.raises(InputError, match=r"robot\.planing_time_s: unknown key .*did you mean 'planning_time_s'"):
        protocol.load(write(tmp_path, text.replace("planning_time_s =", "planing_time_s =")))
    with pytest.raises(InputError, match=r"day\.step_s: expected at most the day's length_s \(14400 s\), got 20000"):
        protocol.load(write(tmp_path, text.replace("step_s = 5.0", "step_s = 20000.0")))
    with pytest.raises(InputError, match=r"tasks\.fall\.count: the day's counts add up to 1200024 requests, more than"):
        protocol.load(write(tmp_path, text.replace("count = 12\npriority = 3", "count = 1200000\npriority = 3")))
    with pytest.raises(InputError, match=r"robot_backnd: unknown key .*did you mean 'robot_backend'.*"
                                         r"\(valid keys: .*robot_backend"):  # optional, yet named
        protocol.load(write(tmp_path, text.replace("[robot_backend", "[robot_backnd")))
    for bad, why in (("0.0", "expected a number > 0"), ('"soon"', "expected a number")):
        with pytest.raises(InputError, match=rf"p\.toml:\d+: robot_backend\.tasks\.fall\.renew_after_s: {why}"):
            protocol.load(write(tmp_path, text.replace("renew_after_s = 30.0", f"renew_after_s = {bad}").replace(
                'world = "tabsa_apartment.toml"', f'world = "{TABSA.parent / "tabsa_apartment.toml"}"')))


def test_a_day_of_no_requests_is_refused_and_a_day_of_one_type_runs(tmp_path: Path) -> None:
    """Counts that were all 0 gave every scheduler an empty day: 'completed 0', 'all done', exit 0."""
    text = TABSA.read_text(encoding="utf-8").split("\n[robot_backend]")[0]
    with pytest.raises(InputError, match=r"p\.toml: tasks: the day's counts add up to 0 requests: expected a "
                                         r"count > 0 for at least one of transport, fall, pick_place"):
        protocol.load(write(tmp_path, text.replace("count = 12", "count = 0")))
    falls = protocol.load(write(tmp_path, text.replace("count = 12", "count = 0").replace(
        "count = 0\npriority = 3", "count = 1\npriority = 3")))
    assert [r.kind for r in day_draw.draw(falls, 1)] == ["fall"]


def test_a_failed_fall_is_requested_again_until_its_death_at(tabsa: protocol.Protocol) -> None:
    """The fall's request carries its renewal (every 30 s after a failure, until death_at);
    the other types' failures stand."""
    from experiments.days import pipeline as days

    assert tabsa.robot is not None and tabsa.robot.tasks["fall"].renew_after_s == 30.0
    assert tabsa.robot.tasks["transport"].renew_after_s is None
    scn = days.make(tabsa, 3, backend="robot").scenario
    requests = [a.fields for a in scn.actions if a.kind == "request"]
    falls = [f for f in requests if f["task"] == "human_fell"]
    assert falls and all(f["renew"] == {"after_s": 30.0, "until": f["args"]["death_at"]} for f in falls)
    assert all("renew" not in f for f in requests if f["task"] != "human_fell")



def test_a_robot_backend_names_its_world_and_its_spots_stand_in_it(tmp_path: Path) -> None:
    """Sites' places are the world's, and each spot lies in a room, clear of walls and furniture."""
    text = TABSA.read_text(encoding="utf-8")
    world = 'world = "tabsa_apartment.toml"'
    assert world in text
    text = text.replace(world, f'world = "{(TABSA.parent / "tabsa_apartment.toml").as_posix()}"')
    protocol.load(write(tmp_path, text))
    hall = next(line for line in text.splitlines() if line.startswith("hall = { place"))
    cases = [
        (hall.replace('place = "hall"', 'place = "hal"'),
         r"robot_backend\.sites\.hall\.place: no place 'hal'; did you mean 'hall'"),
        (hall.replace("spots = [[", "spots = [[60.0, 4.0], ["),
         r"robot_backend\.sites\.hall\.spots: spot 1 \[60\.0, 4\.0\] is in no room"),
        (hall.replace("spots = [[", "spots = [[5.0, 4.0], ["),
         r"robot_backend\.sites\.hall\.spots: spot 1 \[5\.0, 4\.0\] is inside wall"),
    ]
    for bad, message in cases:
        with pytest.raises(InputError, match=r"p\.toml:\d+: " + message):
            protocol.load(write(tmp_path, text.replace(hall, bad)))
    with pytest.raises(InputError, match=r"robot_backend\.world: no world file"):
        protocol.load(write(tmp_path, text.replace((TABSA.parent / "tabsa_apartment.toml").as_posix(), "nope.toml")))

def test_a_robot_backends_tasks_are_checked_against_the_task_types(tmp_path: Path) -> None:
    """Each robot task names a task type, gives its arguments (each variable standing for an
    object of its type) and an object type of its domain: refused at load, not in every day run."""
    text = TABSA.read_text(encoding="utf-8")
    text = text.replace('world = "tabsa_apartment.toml"',
                        f'world = "{(TABSA.parent / "tabsa_apartment.toml").as_posix()}"')
    guide = 'args = { person = "$person", destination = "$dest" }'
    assert guide in text and 'task = "guide_human"' in text and 'object_type = "item"' in text
    cases = [
        ('task = "guide_human"', 'task = "guide_humn"',
         r"robot_backend\.tasks\.transport\.task: no task type 'guide_humn'; did you mean 'guide_human'"),
        (guide, 'args = { destination = "$dest" }',
         r"robot_backend\.tasks\.transport\.args.*missing required argument 'person'"),
        (guide, 'args = { person = "$person", destinaton = "$dest" }',
         r"robot_backend\.tasks\.transport\.args\.destinaton: .*did you mean 'destination'"),
        (guide, 'args = { person = "$person", destination = "$person" }',
         r"robot_backend\.tasks\.transport\.args\.destination: '\$person' is a person, expected a place"),
        (guide, 'args = { person = "$person", destination = "kitchn" }',
         r"robot_backend\.tasks\.transport\.args\.destination: no place 'kitchn'.*did you mean 'kitchen'"),
        ('object_type = "item"', 'object_type = "itme"',
         r"robot_backend\.tasks\.pick_place\.object_type: no object type 'itme'; did you mean 'item'"),
    ]
    for old, new, message in cases:
        with pytest.raises(InputError, match=r"p\.toml:\d+: " + message):
            protocol.load(write(tmp_path, text.replace(old, new)))
    protocol.load(write(tmp_path, text.replace(guide, 'args = { person = "$person", destination = "kitchen" }')))


# -- metrics on a hand-made day -----------------------------------------------------------------------

def ev(t: float, event: str, **f: object) -> dict[str, object]:
    return complete({"t": t, "event": event, **f})


HAND = [
    ev(0, "request", agent="d1", task_type="transport", args={"deadline": 100.0}),
    ev(0, "command", agent="d1", flag="start"),
    ev(10, "request", agent="d2", task_type="fall", args={"deadline": 50.0, "death_at": 950.0}),
    ev(10, "command", agent="d1", flag="susp"),
    ev(10, "transition", agent="d1", **{"from": "exeTsk", "to": "genSusp"}),
    ev(11, "plan", agent="d1", purpose="genSusp", stages=[{"action": "ask_to_stay"}]),
    ev(11, "transition", agent="d1", **{"from": "genSusp", "to": "exeSusp"}),
    ev(15, "transition", agent="d1", **{"from": "exeSusp", "to": "wait"}),
    ev(15, "command", agent="d2", flag="start"),
    ev(80, "end", agent="d2", task_type="fall", cause="finished"),         # 30 s late
    ev(80, "command", agent="d1", flag="start"),
    ev(90, "request", agent="d3", task_type="fall", args={"deadline": 100.0, "death_at": 1000.0}),
    ev(90, "transition", agent="d1", **{"from": "exeTsk", "to": "genSusp"}),
    ev(90, "plan", agent="d1", purpose="genSusp", stages=[]),
    ev(90, "transition", agent="d1", **{"from": "genSusp", "to": "exeSusp"}),
    ev(90, "transition", agent="d1", **{"from": "exeSusp", "to": "wait"}),
    ev(90, "command", agent="d3", flag="start"),
    ev(95, "command", agent="d1", flag="start"),                               # third start of d1 within 95 s
    ev(120, "end", agent="d1", task_type="transport", cause="finished"),     # 20 s late
]


def test_metrics_agree_with_hand_computed_values() -> None:
    m = day_metrics_mod.day_metrics(HAND, day_end=2000.0)
    assert m["requested"] == 3 and m["completed"] == 2
    assert m["dead_falls"] == 1 and m["first_death_t"] == 1000.0  # d3 never finished
    # every entry into genSusp is a suspension (docs/metrics.md), one of which ran stages
    assert m["interruptions"] == 2 and m["suspensions"] == 2 and m["suspensions_with_stages"] == 1
    assert m["suspension_time_s"] == pytest.approx(5.0)  # 10 -> 15, then 90 -> 90
    assert m["switches"] == 5
    assert m["oscillation_t"] == 95.0 and m["ending"] == "oscillation"  # before the death at 1000
    assert m["completion_minus_deadline_s"] == pytest.approx((30 + 20) / 2)
    assert m["lateness_s"] == pytest.approx(50.0)
    t = m["per_type"]["transport"]
    assert t["completed"] == 1 and t["interruptions"] == 2 and t["interruptions_per_task"] == 2.0
    f = m["per_type"]["fall"]
    assert f["requested"] == 2 and f["completed"] == 1 and f["completion_minus_deadline_s"] == pytest.approx(30.0)


def test_endings() -> None:
    before_death = day_metrics_mod.day_metrics(HAND[:11], day_end=500.0)  # d3 not requested, d1 unfinished
    assert before_death["ending"] == "time ran out" and before_death["dead_falls"] == 0
    done = [e for e in HAND if e.get("agent") != "d3" and not (e["t"] == 95)]
    assert day_metrics_mod.day_metrics(done, day_end=2000.0)["ending"] == "all done"
    no_osc = [e for e in HAND if e["t"] != 95]
    assert day_metrics_mod.day_metrics(no_osc, day_end=2000.0)["ending"] == "a fall died"


def test_holm_adjustment() -> None:
    assert stats.holm([0.01, 0.04, 0.03]) == pytest.approx([0.03, 0.06, 0.06])


@pytest.mark.slow
def test_table_has_every_scheduler_and_the_paired_tests(tabsa: protocol.Protocol) -> None:
    results = day_runner.run_days(TABSA, 3, ["lookahead", "simple2"], workers=1)
    text = day_table.table(results)
    assert "| metric | lookahead | simple2 (ours) |" in text  # our priority-first reading of TaBSA's agent
    assert "| dead falls | simple2 (ours) | 3 |" in text and "Holm" in text
    assert "too few days (< 8)" in text  # 8 tests: 2^(1-n) * 8 < 0.05 needs n >= 8


def test_a_failed_tasks_own_safe_suspension_is_not_an_interruption() -> None:
    """Departure 11: a failed stage leads to genSusp; the task was not interrupted, it failed
    (and its safe suspension is still a suspension, with its time)."""
    events = [
        ev(0, "request", agent="d1", task_type="pick_place", args={"deadline": 100.0}),
        ev(0, "command", agent="d1", flag="start"),
        ev(5, "transition", agent="d1", trigger="stage_failed", **{"from": "exeTsk", "to": "genSusp"}),
        ev(5, "plan", agent="d1", purpose="genSusp", stages=[{"action": "place"}]),
        ev(5, "transition", agent="d1", trigger="planned", **{"from": "genSusp", "to": "exeSusp"}),
        ev(9, "transition", agent="d1", trigger="finished", **{"from": "exeSusp", "to": "end"}),
        ev(9, "end", agent="d1", task_type="pick_place", cause="failed"),
    ]
    m = day_metrics_mod.day_metrics(events, day_end=100.0)
    assert m["interruptions"] == 0 and m["suspensions"] == 1 and m["suspension_time_s"] == pytest.approx(4.0)
    assert m["failed"] == 1 and m["completed"] == 0


def _renewed(second: str) -> list[dict[str, object]]:
    """A fall whose help fails at 100 s and is asked again (d2 renews d1), then d3 renews d2."""
    args = {"deadline": 300.0, "death_at": 1200.0}
    return [
        ev(0, "request", agent="d1", task_type="fall", args=args),
        ev(0, "command", agent="d1", flag="start"),
        ev(100, "end", agent="d1", task_type="fall", cause="failed"),
        ev(130, "request", agent="d2", task_type="fall", args=args, renews="d1"),
        ev(130, "command", agent="d2", flag="start"),
        ev(200, "end", agent="d2", task_type="fall", cause="failed"),
        ev(230, "request", agent="d3", task_type="fall", args=args, renews="d2"),
        ev(230, "command", agent="d3", flag="start"),
        ev(400, "end", agent="d3", task_type="fall", cause=second),
    ]


def test_a_fall_requested_again_is_one_need() -> None:
    """A renewed request is the same need: served when any of its tasks finishes, dead only
    if none did by death_at, and counted once among the requests."""
    served = day_metrics_mod.day_metrics(_renewed("finished"), day_end=2000.0)
    assert (served["requested"], served["completed"], served["failed"], served["renewals"]) == (1, 1, 0, 2)
    assert served["dead_falls"] == 0 and served["ending"] == "all done"
    assert served["completion_minus_deadline_s"] == pytest.approx(100.0)  # served at 400, deadline 300
    f = served["per_type"]["fall"]
    assert (f["requested"], f["completed"], f["failed"], f["renewals"]) == (1, 1, 0, 2)
    never = day_metrics_mod.day_metrics(_renewed("failed"), day_end=2000.0)
    assert (never["requested"], never["completed"], never["failed"], never["renewals"]) == (1, 0, 1, 2)
    assert never["dead_falls"] == 1 and never["first_death_t"] == 1200.0 and never["ending"] == "a fall died"


def test_needs_follow_chains_of_renewals() -> None:
    from tasker.trace import needs

    assert needs(_renewed("finished")) == {"d1": "d1", "d2": "d1", "d3": "d1"}
    assert needs(HAND) == {"d1": "d1", "d2": "d2", "d3": "d3"}


def test_a_misspelt_table_or_key_is_named_with_the_one_it_should_be(tmp_path: Path) -> None:
    """A misspelt [arivals] or lenght_s was reported only as the missing one it should have been."""
    text = TABSA.read_text(encoding="utf-8")
    for old, new, message in (("[arrivals]", "[arivals]", r"arrivals: missing \(required\); the file has 'arivals' "
                                                          r"\(line \d+\), not a valid key: did you mean 'arrivals'\?"),
                              ("length_s =", "lenght_s =", r"day\.length_s: missing \(required\); the file has "
                                                           r"'lenght_s' \(line \d+\)")):
        with pytest.raises(InputError, match=r"p\.toml(:\d+)?: " + message):
            protocol.load(write(tmp_path, text.replace(old, new)))


def test_the_days_start_is_a_wall_clock_time(tmp_path: Path) -> None:
    """day.start took any string ('banana', '8 o'clock') and kept it as the day's label."""
    text = TABSA.read_text(encoding="utf-8").split("\n[robot_backend]")[0]
    assert 'start = "08:00"' in text
    for bad in ("banana", "8:00", "24:00", "08:60"):
        with pytest.raises(InputError, match=rf"p\.toml:\d+: day\.start: expected a wall-clock time HH:MM "
                                             rf"\(00:00 to 23:59\), got '{bad}'"):
            protocol.load(write(tmp_path, text.replace('start = "08:00"', f'start = "{bad}"')))
    assert protocol.load(write(tmp_path, text.replace('start = "08:00"', 'start = "23:59"'))).start == "23:59"


def test_a_day_of_too_many_steps_is_refused(tmp_path: Path) -> None:
    """length_s = 1e9 (or a step_s of a millisecond) was accepted, and the day never ended."""
    text = TABSA.read_text(encoding="utf-8").split("\n[robot_backend]")[0]
    for old, new in (("length_s = 14400.0", "length_s = 1e9"), ("step_s = 5.0", "step_s = 0.001")):
        assert old in text
        with pytest.raises(InputError, match=rf"p\.toml:\d+: day\.length_s: .* steps, more than the "
                                             rf"{protocol.MAX_STEPS} a day may have"):
            protocol.load(write(tmp_path, text.replace(old, new)))
    protocol.load(write(tmp_path, text.replace("step_s = 5.0", "step_s = 0.0144")))  # exactly MAX_STEPS
