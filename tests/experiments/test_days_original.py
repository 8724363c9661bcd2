"""TaBSA's own day (tabsa-original, tabsa-anywhere): drawn as its code draws it, run as its tasks run,
read as it reads a day; scheduler specs; verdicts; the day's pictures."""

from __future__ import annotations

import math
import random
from pathlib import Path

import pytest

from experiments.days import draw as day_draw
from experiments.days import pipeline as days
from experiments.days import protocol, specs
from experiments.days import table as day_table
from experiments.days.daytask import DayTask
from experiments.metrics import day as day_metrics_mod
from tasker.errors import ConfigError
from tasker.stage import StageKind
from tasker.support.reader import InputError
from tasker.task import TaskType
from tests.experiments.events import complete

PROTOCOLS = Path(__file__).resolve().parents[2] / "experiments" / "days" / "protocols"
ORIGINAL = PROTOCOLS / "tabsa_original.toml"


@pytest.fixture(scope="module")
def original() -> protocol.Protocol:
    return days.load("tabsa-original")


def write(tmp_path: Path, text: str, name: str = "p.toml") -> Path:
    p = tmp_path / name
    p.write_text(text.replace('world = "tabsa_apartment.toml"', f'world = "{PROTOCOLS / "tabsa_apartment.toml"}"'),
                 encoding="utf-8")
    return p


# -- the draw -----------------------------------------------------------------------------------------

def test_the_draw_is_tabsas(original: protocol.Protocol) -> None:
    """Deadlines over the day, calls before them (at least 5 s), TaBSA's priorities, speeds and works."""
    assert original.process == "before_deadline" and original.non_preemptive == ("fall", "pick_place")
    for seed in (1, 2, 3):
        for r in day_draw.draw(original, seed):
            assert 0.0 <= r.t and r.deadline <= original.length_s
            assert r.t <= max(0.0, r.deadline - 5.0) + 0.1  # rounded to 0.1 s
            if r.kind == "fall":
                assert r.priority == 4 and 60.0 <= (r.work or 0) <= 300.0 and r.death_at == r.deadline + 900.0
            else:
                assert r.priority in (1, 2, 3)
            if r.kind == "transport":
                assert r.walk_speed is not None and 0.01 <= r.walk_speed <= 0.1
            if r.kind == "pick_place":
                assert 60.0 <= (r.pick_s or 0) <= 300.0 and 60.0 <= (r.place_s or 0) <= 300.0
                assert r.carry_speed is not None and 0.01 <= r.carry_speed <= 0.1


def test_a_pick_and_place_takes_the_latest_of_three_deadlines(original: protocol.Protocol) -> None:
    """TaBSA's pick-and-place is three drawn tasks: its deadline is the latest, its call the earliest."""
    rng = random.Random("x")
    spec = original.tasks["pick_place"]
    call, deadline = day_draw._times(original, spec, rng)
    rng = random.Random("x")
    pairs = []
    for _ in range(3):
        d = rng.uniform(0.0, original.length_s)
        pairs.append((max(0.0, rng.uniform(-5.0, d - 5.0)), d))
    assert (call, deadline) == (round(min(c for c, _ in pairs), 1), round(max(d for _, d in pairs), 1))


@pytest.mark.slow
def test_the_work_of_a_day_is_tabsas_share_of_it(original: protocol.Protocol) -> None:
    """TaBSA's day asks about 0.7 of its four hours in work before travel; ours (tabsa) about 0.2."""
    def share(proto: protocol.Protocol) -> float:
        total = 0.0
        for seed in range(1, 21):
            for r in day_draw.draw(proto, seed):
                d = math.dist(proto.sites[r.site], proto.sites[r.dest])
                spec = proto.tasks[r.kind]
                if r.kind == "transport":
                    total += d / (r.walk_speed or 1.0) + spec.greet_s + spec.goodbye_s
                elif r.kind == "fall":
                    total += r.work or 0.0
                else:
                    total += day_draw_seconds(r.pick_s, spec.pick_s) + day_draw_seconds(r.place_s, spec.place_s) \
                        + d / (r.carry_speed or proto.robot_speed)
        return total / (20 * proto.length_s)

    assert 0.6 < share(original) < 0.8
    assert share(days.load("tabsa")) < 0.3


def day_draw_seconds(drawn: float | None, fixed: float | tuple[float, float]) -> float:
    return float(drawn) if drawn is not None else float(fixed)  # type: ignore[arg-type]


def test_protocols_without_the_new_fields_keep_their_digest(tmp_path: Path) -> None:
    """A protocol stored before TaBSA's fields existed resumes: writing their defaults changes nothing."""
    text = (PROTOCOLS / "tabsa.toml").read_text(encoding="utf-8")
    plain = protocol.load(write(tmp_path, text))
    anchor = "death_after_s = 900.0"
    assert anchor in text
    explicit = protocol.load(write(tmp_path, text.replace(anchor, anchor + "\npreemptive = true"), "q.toml"))
    assert plain.digest() == explicit.digest()
    assert protocol.load(write(tmp_path, text.replace(anchor, anchor + "\npreemptive = false"),
                               "r.toml")).digest() != plain.digest()


def test_bad_tabsa_fields_name_file_line_and_field(tmp_path: Path) -> None:
    text = ORIGINAL.read_text(encoding="utf-8")
    cases = [
        ("[tasks.fall]\n", "[tasks.fall]\ndeadline_s = [1.0, 2.0]\n",
         r"tasks\.fall\.deadline_s: not used with arrivals\.process = 'before_deadline'"),
        ("call_lead_s = 5.0", "call_lead_s = 5.0\nlast_call_s = 100.0", r"arrivals\.last_call_s: not used with"),
        ("priority = [1, 2, 3]     # random", "priority = [1, true]     # random",
         r"tasks\.transport\.priority: expected an integer or a non-empty list of integers"),
        ('process = "before_deadline"', 'process = "befor_deadline"', r"arrivals\.process: .*did you mean"),
        ('durations = { call_help = "$work" }', 'durations = { call_hlp = "$work" }',
         r"robot_backend\.tasks\.fall\.durations\.call_hlp: no action 'call_hlp'; did you mean 'call_help'"),
        ('durations = { call_help = "$work" }', 'durations = { call_help = "$pick" }',
         r"robot_backend\.tasks\.fall\.durations\.call_help: expected a value the fall requests draw \(one of "
         r"\$work\), got '\$pick'"),
        ("preemptive = false\nsuspend_s", "preemptive = 0\nsuspend_s",
         r"tasks\.pick_place\.preemptive: expected true or false"),
    ]
    for old, new, message in cases:
        assert old in text, old
        with pytest.raises(InputError, match=r"p\.toml:\d+: " + message):
            protocol.load(write(tmp_path, text.replace(old, new, 1)))


# -- the synthetic day's tasks -------------------------------------------------------------------------

def test_a_type_that_is_not_preemptive_runs_blocking_from_its_first_stage(original: protocol.Protocol) -> None:
    fall = DayTask(original.tasks["fall"], 0.5, 1.0)
    stages = fall._template({"site": (0.0, 0.0), "dest": None, "work": 100.0})
    assert [s.kind for s in stages] == [StageKind.BLOCKING, StageKind.BLOCKING]
    carry = DayTask(original.tasks["pick_place"], 0.5, 1.0)
    stages = carry._template({"site": (0.0, 0.0), "dest": (3.0, 4.0), "pick_s": 70.0, "place_s": 80.0,
                              "carry_speed": 0.05})
    assert all(s.kind is StageKind.BLOCKING for s in stages)
    assert [s.duration for s in stages if s.action in ("pick_up", "place")] == [70.0, 80.0]
    transport = DayTask(original.tasks["transport"], 0.5, 1.0)
    assert transport._template({"site": (0.0, 0.0), "dest": (1.0, 0.0), "walk_speed": 0.05})[2].kind \
        is StageKind.SUSPENDABLE


@pytest.mark.slow
def test_no_scheduler_interrupts_a_fall_or_a_pick_and_place_of_tabsas_day() -> None:
    """The type's own property, whatever the scheduler asks: srtf asks falls and pick-and-places to
    suspend for any shorter task; they run on, and only transports suspend."""
    run = days.make("tabsa-original", 3, scheduler="srtf").run()
    kinds = {e["agent"]: e["task_type"] for e in run.events if e["event"] == "request"}
    asked = {kinds[e["agent"]] for e in run.events if e["event"] == "command" and e["flag"] == "susp"}
    suspended = {kinds[e["agent"]] for e in run.events if e["event"] == "transition" and e["to"] == "genSusp"}
    assert asked == {"fall", "pick_place", "transport"} and suspended == {"transport"}


def test_an_escort_stopped_halfway_goes_on_from_where_it_stopped() -> None:
    """The person waits where the escort stopped: on resumption the escort covers what was left."""
    proto = days.load("tabsa")
    run = days.make(proto, 2, scheduler="alg2").run()
    plans = [e for e in run.events if e["event"] == "plan"]
    stopped = next(e for e in plans if e["purpose"] == "genSusp" and e["stages"])
    agent = stopped["agent"]
    stages = [e for e in run.events if e["event"] == "stage" and e.get("agent") == agent and e["action"] == "escort"]
    begins = [e["t"] for e in stages if e["status"] == "begin"]
    ends = {e["status"]: e["t"] for e in stages if e["status"] != "begin"}
    first_leg, second_leg = ends["stopped"] - begins[0], ends["done"] - begins[1]
    request = next(e for e in run.events if e["event"] == "request" and e["agent"] == agent)
    whole = math.dist(request["args"]["site"], request["args"]["dest"]) / request["args"]["walk_speed"]
    assert first_leg > 5.0 and second_leg <= max(0.0, whole - first_leg) + 5.0  # what was left (to the 5 s
    # step of the stages' polling), not the whole escort again


# -- positions anywhere -------------------------------------------------------------------------------

def test_anywhere_draws_people_in_free_space_of_the_sites_rooms() -> None:
    from robot.spec import disc_clear, load_world, room_of

    proto = days.load("tabsa-anywhere")
    assert proto.robot is not None
    world = load_world(proto.robot.world)
    boxes = [o.box for o in world.obstacles]
    rooms = {room_of(world, *world.places[p][:2]) for p in proto.robot.places.values()}
    drawn = [r for r in day_draw.draw(proto, 4) if r.kind in ("fall", "transport")]
    assert len(drawn) == 24 and all(r.xy is not None for r in drawn)
    for r in drawn:
        assert r.xy is not None
        assert room_of(world, *r.xy) in rooms and disc_clear(boxes, world.bounds, 0.3, *r.xy)
    assert len({r.xy for r in drawn}) == 24  # not three spots a site
    assert day_draw.draw(proto, 4) == day_draw.draw(proto, 4)
    scn = days.make(proto, 4, backend="robot").scenario
    spots = {tuple(p["walk"][-1][1:]) for p in scn.people.values()}
    assert {r.xy for r in drawn} <= spots


def test_positions_in_rooms_need_a_world(tmp_path: Path) -> None:
    text = (PROTOCOLS / "tabsa_anywhere.toml").read_text(encoding="utf-8").split("\n[robot_backend]")[0]
    with pytest.raises(InputError, match=r"apartment\.positions: 'rooms' draws positions in the rooms of the "
                                         r"\[robot_backend\]'s world"):
        protocol.load(write(tmp_path, text))


# -- schedulers of a day ------------------------------------------------------------------------------

def test_scheduler_specs_are_canonical_checked_and_swept() -> None:
    assert specs.parse("tabsa-simple:hesitance=0.50").label == "tabsa-simple:hesitance=0.5"
    assert specs.parse("tabsa-distance:ratio=1:estimates=reports").as_dict() == {"estimates": "reports", "ratio": 1}
    assert [s.label for s in specs.expand(["tabsa-distance:ratio=*"])] == [
        f"tabsa-distance:ratio={v}" for v in ("0", "0.25", "0.5", "0.75", "1")]
    for bad, why in (("tabsa-simpel", "did you mean 'tabsa-simple'"),
                     ("tabsa-simple:hesitanse=0.5", "has no option 'hesitanse'.*did you mean 'hesitance'"),
                     ("tabsa-simple:hesitance=1.5", r"hesitance must be a number in \[0, 1\], got 1.5"),
                     ("tabsa-simple:hesitance", "expected NAME:OPTION=VALUE"),
                     ("edf:foo=*", "does not sweep 'foo'")):
        with pytest.raises(ConfigError, match=why):
            specs.expand([bad])
    with pytest.raises(ConfigError, match="'tabsa-simple:hesitance=0.5' is given twice"):
        specs.expand(["tabsa-simple:hesitance=0.5", "tabsa-simple:hesitance=0.50"])


def test_the_day_gives_tabsas_agents_its_seed_and_the_non_preemptive_types(original: protocol.Protocol) -> None:
    assert days.scheduler_options(original, "tabsa-simple", seed=7) == {
        "non_preemptive": ["fall", "pick_place"], "seed": 7}
    assert days.scheduler_options(original, "tabsa-scheduler", backend="robot") == {
        "non_preemptive": ["human_fell", "carry_object"]}
    day = days.make(original, 7, scheduler="tabsa-simple:hesitance=0.25")
    assert day.scheduler == "tabsa-simple:hesitance=0.25"
    assert day.scenario.scheduler == "tabsa-simple"
    assert day.scenario.scheduler_options == {"non_preemptive": ["fall", "pick_place"], "seed": 7, "hesitance": 0.25}


# -- TaBSA's reading of a day -------------------------------------------------------------------------

def ev(t: float, event: str, **f: object) -> dict[str, object]:
    return complete({"t": t, "event": event, **f})


def _runs(pattern: str, step: float = 5.0) -> list[dict[str, object]]:
    """A day whose exeDA at step k is pattern[k] ('a', 'b' or '.' for none)."""
    out = [ev(0, "request", agent="a", task_type="t", args={"deadline": 1e4}),
           ev(0, "request", agent="b", task_type="t", args={"deadline": 1e4})]
    last = None
    for k, c in enumerate(pattern):
        who = None if c == "." else c
        if who != last:
            out.append(ev(k * step, "roles", exeDA=who))
            last = who
    return out


def test_tabsas_oscillation_is_more_than_two_gaps_in_three_minutes() -> None:
    from experiments.trace.timeline import Timeline

    def when(pattern: str) -> float | None:
        return day_metrics_mod.tabsa_oscillation(Timeline.of(_runs(pattern)), 5.0 * len(pattern))

    assert when("ab" * 3) is None               # a runs in 3 stretches: 2 gaps
    assert when("ab" * 3 + "a") == 30.0          # the 4th stretch of a: 3 gaps within 37 steps
    assert when("a." * 3 + "a") == 30.0          # idle steps make gaps too, as in TaBSA
    assert when("a" + "b" * 36 + "aba" + "ba") is None  # the first stretch has left the 37-step window


def test_tabsas_stop_is_the_first_of_all_done_a_death_and_oscillation() -> None:
    assert day_metrics_mod.tabsa_stop({"a": 100.0, "b": 50.0}, 2, None, None, 1000.0) == (100.0, "all done")
    assert day_metrics_mod.tabsa_stop({"a": 100.0}, 2, 400.0, 300.0, 1000.0) == (300.0, "oscillation")
    assert day_metrics_mod.tabsa_stop({"a": 100.0}, 2, None, None, 1000.0) == (1000.0, "time ran out")
    events = [ev(0, "request", agent="f", task_type="fall", args={"deadline": 100.0, "death_at": 1000.0}),
              ev(0, "request", agent="g", task_type="fall", args={"deadline": 200.0, "death_at": 1100.0}),
              ev(0, "roles", exeDA="f"), ev(300, "end", agent="f", task_type="fall", cause="finished"),
              ev(300, "roles", exeDA=None)]
    m = day_metrics_mod.day_metrics(events, day_end=2000.0)
    assert m["completion_minus_death_s"] == pytest.approx(300.0 - 1000.0)
    assert (m["tabsa_ending"], m["tabsa_stop_t"], m["tabsa_completed"]) == ("a fall died", 1100.0, 1)


# -- the table's verdicts -----------------------------------------------------------------------------

def test_the_minimum_of_days_is_where_a_test_could_reject_after_holm() -> None:
    for m in (1, 8, 56, 96):
        n = day_table.min_days(m)
        assert 2.0 ** (1 - n) * m < 0.05 <= 2.0 ** (2 - n) * m


def _day(name: str, seed: int, dead: int) -> dict[str, object]:
    return {"scheduler": name, "seed": seed, "backend": "synthetic", "completed": 3, "failed": 0,
            "completion_minus_deadline_s": 0.0,
            "lateness_s": 0.0, "dead_falls": dead, "interruptions": 0, "suspensions": 0, "suspension_time_s": 0.0,
            "switches": 0, "longest_order": 0, "anytime_decisions": 0, "ending": "all done", "per_type": {}}


@pytest.mark.slow
def test_verdicts_come_from_the_registered_direction_and_need_enough_days() -> None:
    many = [_day("lookahead", s, 0) for s in range(1, 13)] + [_day("edf", s, 1) for s in range(1, 13)]
    text = day_table.table(many)
    assert "| dead falls | edf | 12 | -1.00 ± 0.00 | 12 / 0 / 0 |" in text
    line = next(x for x in text.splitlines() if x.startswith("| dead falls | edf"))
    assert line.endswith("| better |")  # fewer dead falls: the registry says lower is better
    few = [_day("lookahead", s, 0) for s in range(1, 4)] + [_day("edf", s, 1) for s in range(1, 4)]
    assert "too few days (< 8)" in day_table.table(few)  # 6 tests: 2^(1 - 8) * 6 < 0.05


# -- the pictures -------------------------------------------------------------------------------------

@pytest.mark.slow
def test_a_day_run_writes_its_pictures_and_a_page_that_shares_plotly(tmp_path: Path) -> None:
    from experiments.days import pictures
    from experiments.days.runner import run_days

    results = run_days("tabsa-original", 1, ["edf", "tabsa-simple"], workers=1)
    text = day_table.report(results, title="t")
    files = pictures.write(tmp_path, text, results)
    names = sorted(p.name for p in files)
    assert names == ["completion_minus_deadline.png", "completions_per_type.png", "endings_ours.png",
                     "endings_tabsa.png", "report.html"]
    page = (tmp_path / "report.html").read_text(encoding="utf-8")
    assert '<script type="text/javascript" src="plotly.min.js"></script>' in page and len(page) < 500_000
    assert (tmp_path / "plotly.min.js").stat().st_size > 1_000_000
    assert "tabsa-simple" in page and "completions" in page


# -- the robot backend's drawn work -------------------------------------------------------------------

class _Folder(TaskType):
    """A stand-in for a task folder's type: one declared 18 s 'help' and a 5 s 'approach'."""

    class spec:  # noqa: N801 - the attribute a folder's type has
        actions = {"help": type("A", (), {"duration": 18.0})(), "approach": type("A", (), {"duration": 5.0})()}

    name = "fell"
    description = ""
    arg_specs = ()

    def __init__(self) -> None:
        from tasker.meaning import NO_MEANING

        self.meaning = NO_MEANING

    def compute_params(self, ctx: object) -> object:
        from tasker.messages import CostParams

        return CostParams("fell", cost=10.0 * 23.0, cps=10.0, c_time=23.0)

    def update_task(self, ctx: object) -> object:
        from tasker.stage import Purpose, Stage, StagePlan

        return StagePlan((Stage("approach", duration=5.0), Stage("help", kind=StageKind.BLOCKING, duration=18.0)),
                         Purpose.UP_TSK)


def test_drawn_work_sets_the_stage_and_the_estimate_and_blocks_a_non_preemptive_type() -> None:
    import random as _random

    from experiments.days.robot_work import DrawnWork, wrapper_for
    from tasker.task import TaskContext

    task = wrapper_for({"fell": (("help",), False)})(_Folder())  # type: ignore[arg-type]
    assert isinstance(task, DrawnWork)
    args = task.validate_args({"help_s": 200.0})
    ctx = TaskContext("d1", "fell", args, 0.0, _random.Random(0))
    params = task.compute_params(ctx)
    assert params.c_time == pytest.approx(23.0 + 200.0 - 18.0) and params.cost == pytest.approx(10.0 * 205.0)
    plan = task.update_task(ctx)
    assert [(s.action, s.duration, s.kind) for s in plan.stages] == [
        ("approach", 5.0, StageKind.BLOCKING), ("help", 200.0, StageKind.BLOCKING)]
    ctx.done.append(plan.stages[1])  # once the help is done, nothing is added
    assert task.compute_params(ctx).c_time == pytest.approx(23.0)
    assert wrapper_for({"other": ((), True)})(_Folder()).__class__ is _Folder  # type: ignore[arg-type]


@pytest.mark.slow
def test_a_robot_day_of_tabsas_protocol_takes_the_drawn_work(tmp_path: Path) -> None:
    """A 25-minute robot day, one request of each type: the help, the pick and the place last what
    was drawn, and a fall or a pick-and-place runs blocking from its first stage."""
    from experiments.days.runner import run_day
    from experiments.trace.timeline import Timeline

    text = ORIGINAL.read_text(encoding="utf-8").replace('name = "tabsa-original"', 'name = "tiny-original"')
    text = text.replace("length_s = 14400.0", "length_s = 1500.0").replace("count = 12", "count = 1")
    path = write(tmp_path, text)
    proto = protocol.load(path)
    drawn = {r.kind: r for r in day_draw.draw(proto, 1)}
    run_day(str(path), 1, "edf", backend="robot", keep=str(tmp_path / "run"))
    tl = Timeline.read(tmp_path / "run" / "trace.jsonl")
    by_type = {x.task_type: x for x in tl.agents.values()}
    assert {t: x.cause for t, x in by_type.items()} == {"human_fell": "finished", "carry_object": "finished",
                                                         "guide_human": "finished"}
    took = {(t, s.action): s.end - s.begin for t, x in by_type.items() for s in x.stages if s.end is not None}
    assert took["human_fell", "call_help"] == pytest.approx(drawn["fall"].work, abs=0.2)
    assert took["carry_object", "pick"] == pytest.approx(drawn["pick_place"].pick_s, abs=0.2)
    assert took["carry_object", "place"] == pytest.approx(drawn["pick_place"].place_s, abs=0.2)
    for t in ("human_fell", "carry_object"):
        assert {s.kind for s in by_type[t].stages} == {"blocking"}
    assert "suspendable" in {s.kind for s in by_type["guide_human"].stages}
