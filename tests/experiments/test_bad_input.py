"""Every input is checked before anything runs: each class of bad input is a clean error
(an :class:`~tasker.support.reader.InputError`) naming the file, the line, the field and what was
expected — never a traceback, never silently accepted.  Doubtful but valid inputs warn."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

from experiments.cli import main
from experiments.inputs import scenario as scenarios
from experiments.inputs import synthetic
from experiments.inputs.fields import ScenarioError
from experiments.sweep.spec import SpecError, load_spec
from robot.spec import WorldFileError, load_world
from tasker.support.reader import InputError, InputWarning
from tests.experiments import standin

ROBOT = """\
kind = "robot"
world = "paper"
seed = 1

[settings]
scheduler = "alg2"
horizon = 600.0

[[requests]]
t = 0.0
task = "guide_human"
args = { person = "john", destination = "bedroom" }

[[requests]]
t = 20.0
task = "human_fell"
args = { person = "peter" }

[[world_events]]
t = 19.0
posture = ["peter", "fallen"]
"""


def _write(tmp_path: Path, text: str | bytes, name: str = "s.toml") -> Path:
    p = tmp_path / name
    if isinstance(text, bytes):
        p.write_bytes(text)
    else:
        p.write_text(text, encoding="utf-8")
    return p


def _fails(path: Path, loader, field: str, fragment: str, cls: type[InputError] = InputError) -> InputError:  # type: ignore[no-untyped-def]
    with pytest.raises(cls) as info:
        loader(path)
    err = info.value
    text = str(err)
    assert text.startswith(str(path)) or str(path) in text, text
    assert field in text, f"field {field!r} not named in: {text}"
    assert fragment in text, f"{fragment!r} not in: {text}"
    return err


# ----------------------------------------------------------------------------------------- robot scenarios

ROBOT_CASES = [
    # unknown keys, with did-you-mean
    ('seed = 1', 'seed = 1\nrequsts = []', "requsts", "did you mean 'requests'"),
    ('horizon = 600.0', 'horizon = 600.0\nhorizn = 3', "settings.horizn", "did you mean 'horizon'"),
    ('t = 19.0', 't = 19.0\nnotes = "x"', "world_events[0].notes", "did you mean 'note'"),
    ('t = 20.0', 't = 20.0\nagent = "d1"', "requests[1].agent", "unknown key"),
    # wrong types
    ('t = 0.0', 't = "soon"', "requests[0].t", "expected a number"),
    ('seed = 1', 'seed = 1.5', "seed", "expected an integer"),
    ('seed = 1', 'seed = -1', "seed", ">= 0"),
    ('horizon = 600.0', 'horizon = "long"', "settings.horizon", "expected a number"),
    ('horizon = 600.0', 'horizon = true', "settings.horizon", "expected a number"),
    ('args = { person = "peter" }', 'args = ["peter"]', "requests[1].args", "expected a table"),
    ('task = "human_fell"', 'task = 3', "requests[1].task", "expected a string"),
    ('posture = ["peter", "fallen"]', 'posture = "fallen"', "world_events[0].posture", "expected an array"),
    # NaN and inf
    ('t = 0.0', 't = nan', "requests[0].t", "finite"),
    ('horizon = 600.0', 'horizon = inf', "settings.horizon", "finite"),
    ('scheduler = "alg2"', 'scheduler = "alg2"\nrep_rate = -inf', "settings.rep_rate", "finite"),
    ('t = 19.0', 't = nan', "world_events[0].t", "finite"),
    # negative times, out-of-range values, bad choices
    ('t = 20.0', 't = -2.0', "requests[1].t", ">= 0"),
    ('t = 19.0', 't = -0.5', "world_events[0].t", ">= 0"),
    ('horizon = 600.0', 'horizon = 0', "settings.horizon", "> 0"),
    ('scheduler = "alg2"', 'scheduler = "alg2"\ns_freq = -1', "settings.s_freq", "> 0"),
    ('scheduler = "alg2"', 'scheduler = "alg2"\nmode = "XT"', "settings.mode", "expected one of"),
    ('scheduler = "alg2"', 'scheduler = "alg2"\npolicy = "lenient"', "settings.policy", "expected one of"),
    ('scheduler = "alg2"', 'scheduler = "alg"', "settings.scheduler", "did you mean 'alg2'"),
    ('scheduler = "alg2"', 'scheduler = "alg2"\nscheduler_options = { hysteresis = -3 }',
     "settings.scheduler_options", "hysteresis"),
    ('scheduler = "alg2"', 'scheduler = "alg2"\nscheduler_options = { cclasses = [["human_fell"]] }',
     "settings.scheduler_options.cclasses", "scheduler 'alg2' has no option 'cclasses'; did you mean 'classes'?"),
    ('scheduler = "alg2"', 'scheduler = "fifo"\nscheduler_options = { hysteresis = 0.5 }',
     "settings.scheduler_options.hysteresis", "scheduler 'fifo' has no option 'hysteresis' (it takes no options)"),
    ('scheduler = "alg2"', 'scheduler = "alg2"\nscheduler_options = { classes = false }',
     "settings.scheduler_options", "alg2: classes must be a list of classes"),
    ('scheduler = "alg2"', 'scheduler = "alg2"\nscheduler_options = { classes = [[1]] }',
     "settings.scheduler_options", "alg2: classes[0] must be a list of task types (strings)"),
    ('scheduler = "alg2"', 'scheduler = "priority"\nscheduler_options = { priorities = { human_fell = "high" } }',
     "settings.scheduler_options", "priority: priorities['human_fell'] must be a number"),
    ('scheduler = "alg2"', 'scheduler = "priority"\nscheduler_options = { default = "low" }',
     "settings.scheduler_options", "priority: default must be a number"),
    ('scheduler = "alg2"', 'scheduler = "lookahead"\nscheduler_options = { budgets = 5 }',
     "settings.scheduler_options", "lookahead: budgets must be a table"),
    ('scheduler = "alg2"', 'scheduler = "lookahead"\nscheduler_options = { budgets = { human_fell = "soon" } }',
     "settings.scheduler_options", "lookahead: budgets['human_fell'] must be a finite number"),
    # cross-references: task types, people, places, doors, postures, agents
    ('task = "guide_human"', 'task = "guide_humans"', "requests[0].task", "did you mean 'guide_human'"),
    ('person = "peter"', 'person = "bob"', "requests[1].args.person", "no person 'bob'"),
    ('person = "john"', 'person = "jon"', "requests[0].args.person", "did you mean 'john'"),
    ('destination = "bedroom"', 'destination = "bedrom"', "requests[0].args.destination", "did you mean 'bedroom'"),
    ('destination = "bedroom"', 'destination = "alice"', "requests[0].args.destination",
     "'alice' is a person, expected a place"),
    ('person = "john"', 'person = "kitchen"', "requests[0].args.person", "'kitchen' is a place, expected a person"),
    ('person = "john"', 'person = 3', "requests[0].args.person", "expected"),
    ('person = "john", destination', 'persn = "john", destination', "requests[0].args.persn",
     "did you mean 'person'"),
    ('args = { person = "peter" }', 'args = {}', "requests[1].args", "missing required argument 'person'"),
    ('posture = ["peter", "fallen"]', 'posture = ["bob", "fallen"]', "world_events[0].posture",
     "no person of world 'paper' 'bob'"),
    ('posture = ["peter", "fallen"]', 'posture = ["peter", "falen"]', "world_events[0].posture",
     "did you mean 'fallen'"),
    ('posture = ["peter", "fallen"]', 'door = ["front_door", false]', "world_events[0].door", "no door"),
    ('posture = ["peter", "fallen"]', 'add = [["fallen", "bob"]]', "world_events[0].add", "'bob'"),
    ('posture = ["peter", "fallen"]', 'add = [["falen", "peter"]]', "world_events[0].add",
     "did you mean 'fallen'"),
    ('posture = ["peter", "fallen"]', 'add = [["fallen", "peter", "hall"]]', "world_events[0].add",
     "takes 1 argument"),
    ('posture = ["peter", "fallen"]', 'delete = [[]]', "world_events[0].delete", "non-empty"),
    ('posture = ["peter", "fallen"]', 'note = "only a note"', "world_events[0]", "exactly one of"),
    ('posture = ["peter", "fallen"]', 'walk = ["peter", 1.0]', "world_events[0].walk", "expected [person, x, y]"),
    ('posture = ["peter", "fallen"]', 'walk = ["peter", "x", 2.0]', "world_events[0].walk",
     "expected [person, x, y]"),
    ('posture = ["peter", "fallen"]', 'walk = ["bob", 1.0, 2.0]', "world_events[0].walk", "no person"),
    ('posture = ["peter", "fallen"]', 'walk = ["peter", 99.0, 2.0]', "world_events[0].walk", "outside the world"),
    ('posture = ["peter", "fallen"]', 'posture = ["peter", "standing"]\nafter = "d9"', "world_events[0].after",
     "no agent 'd9'"),
    ('posture = ["peter", "fallen"]', 'posture = ["peter", "standing"]\nafter = 1', "world_events[0].after",
     "expected a string"),
    ('world = "paper"', 'world = "papr"', "world", "did you mean 'paper'"),
    ('world = "paper"', 'world = "nowhere.toml"', "world", "no world file"),
    ('kind = "robot"', 'kind = "robott"', "kind", "expected one of"),
]

TAILS = [
    ('[[terminations]]\nt = 30.0\nagent = "d3"\n', "terminations[0].agent", "no agent 'd3'"),
    ('[[terminations]]\nt = 30.0\nagent = "john"\n', "terminations[0].agent", "agents are d1..d2"),
    ('[[terminations]]\nt = 5.0\nagent = "d2"\n', "terminations[0].agent", "requested only at t=20"),
    ('[[changes]]\nt = 30.0\nagent = "d1"\nargs = { destination = "peter" }\n', "changes[0].args.destination",
     "'peter' is a person, expected a place"),
    ('[[changes]]\nt = 30.0\nagent = "d1"\nargs = { destiny = "hall" }\n', "changes[0].args.destiny",
     "did you mean 'destination'"),
    ('[[changes]]\nt = 30.0\nagent = "d1"\n', "changes[0].args", "missing"),
    ('[[mode_changes]]\nt = 30.0\nmode = "ct"\n', "mode_changes[0].mode", "expected one of"),
    ('[people.bob]\npose = [1.0, 1.0, 0.0]\n', "people.bob", "no person of world 'paper' 'bob'"),
    ('[people.john]\npose = [0.05, 3.0, 0.0]\n', "people.john.pose", "inside wall"),
    ('[people.john]\npose = [30.0, 3.0, 0.0]\n', "people.john.pose", "outside the world's bounds"),
    ('[people.john]\npose = [1.0, 3.0]\n', "people.john.pose", "expected [x, y, yaw]"),
    ('[people.john]\npose = [1.0, nan, 0.0]\n', "people.john.pose", "finite"),
    ('[people.john]\nwalk = [[5.0, 1.0, 3.0], [2.0, 1.5, 3.0]]\n', "people.john.walk[1]", "times must increase"),
    ('[people.john]\nwalk = [[-1.0, 1.0, 3.0]]\n', "people.john.walk[0]", ">= 0"),
    ('[people.john]\nwalk = [[5.0, 1.0, 30.0]]\n', "people.john.walk[0]", "outside the world's bounds"),
    ('[people.john]\nwalk = [[5.0, 1.5, 0.5]]\n', "people.john.walk[0]", "inside furniture 'sofa'"),
    ('[people.john]\nspeed = 2\n', "people.john.speed", "unknown key"),
    ('[objects.cup]\ntype = "item"\nplace = "garden"\n', "objects.cup.place", "no place of world 'paper' 'garden'"),
    ('[objects.cup]\ntype = "iteem"\nplace = "kitchen"\n', "objects.cup.type", "did you mean 'item'"),
    ('[objects.cup]\ntype = "item"\n', "objects.cup.place", "missing"),
    ('[objects.cup]\ntype = "item"\nplace = "kitchen"\ncolour = "red"\n', "objects.cup.colour", "unknown key"),
    ('[objects.john]\ntype = "item"\nplace = "kitchen"\n', "objects.john", "already a person"),
    ('[objects."my cup"]\ntype = "item"\nplace = "kitchen"\n', "objects.my cup", "is not a PDDL name"),
    ('[objects.cup]\ntype = "item"\nplace = "kitchen"\nfacts = [["at", "cup", "gardn"]]\n', "objects.cup.facts[0]",
     "'gardn'"),
    ('[objects.cup]\ntype = "item"\nplace = "kitchen"\nfacts = ["at"]\n', "objects.cup.facts[0]",
     "expected a fact"),
    ('[settings.strategies.guide]\nsuspension = "static"\n', "settings.strategies.guide",
     "did you mean 'guide_human'"),
    ('[settings.strategies.guide_human]\nsuspension = "sometimes"\n', "settings.strategies.guide_human.suspension",
     "expected one of"),
]


@pytest.mark.parametrize(("old", "new", "field", "fragment"), ROBOT_CASES)
def test_bad_robot_scenario_field_is_named(tmp_path: Path, old: str, new: str, field: str, fragment: str) -> None:
    assert old in ROBOT
    path = _write(tmp_path, ROBOT.replace(old, new, 1))
    err = _fails(path, scenarios.load, field, fragment, ScenarioError)
    assert err.field and (err.field in field or field in err.field)


@pytest.mark.parametrize(("tail", "field", "fragment"), TAILS)
def test_bad_robot_scenario_tables_are_named(tmp_path: Path, tail: str, field: str, fragment: str) -> None:
    path = _write(tmp_path, ROBOT + "\n" + tail)
    err = _fails(path, scenarios.load, field, fragment, ScenarioError)
    assert err.line is not None, "a key written in the file has a line"


def test_scheduler_priority_classes_name_task_types(tmp_path: Path) -> None:
    text = ROBOT.replace('scheduler = "alg2"', 'scheduler = "alg2"\n'
                         'scheduler_options = { classes = [["human_fell"], ["guide"]] }')
    _fails(_write(tmp_path, text), scenarios.load, "settings.scheduler_options.classes",
           "no task type 'guide'; did you mean 'guide_human'?", ScenarioError)


def test_the_good_robot_scenario_loads_with_objects_and_policy(tmp_path: Path) -> None:
    text = ROBOT.replace('horizon = 600.0', 'horizon = 600.0\npolicy = "conditional"') + (
        '\n[objects.cup]\ntype = "item"\nplace = "kitchen"\nfacts = [["at", "cup", "kitchen"]]\n')
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        scn = scenarios.load(_write(tmp_path, text))
    assert scn.policy == "conditional" and scn.warnings == ()
    assert scn.objects == {"cup": {"type": "item", "place": "kitchen", "facts": [["at", "cup", "kitchen"]]}}
    assert scenarios.load(_write(tmp_path, ROBOT)).policy == "strict"


@pytest.mark.parametrize(("content", "fragment"), [
    (b"kind = \"robot\"\x00\x01\x02", "binary file"),
    (b"kind = \"robot\"\nworld = \"caf\xe9\"\n", "not UTF-8"),
    (b"kind = \"robot\"\n[[requests]\n", "not valid TOML"),
])
def test_unreadable_scenario_files(tmp_path: Path, content: bytes, fragment: str) -> None:
    path = _write(tmp_path, content)
    with pytest.raises(ScenarioError, match=fragment):
        scenarios.load(path)


def test_a_directory_or_a_missing_file_is_a_clean_error(tmp_path: Path) -> None:
    (tmp_path / "d.toml").mkdir()
    with pytest.raises(ScenarioError, match="is not a file"):
        scenarios.load(tmp_path / "d.toml")
    with pytest.raises(ScenarioError, match="no such scenario file"):
        scenarios.load(tmp_path / "none.toml")
    with pytest.raises(ScenarioError, match="did you mean 'paper'"):
        scenarios.load("papr")


# ----------------------------------------------------------------------------------------- warnings

def test_a_request_after_the_horizon_warns(tmp_path: Path) -> None:
    text = ROBOT.replace("t = 20.0", "t = 900.0")
    with pytest.warns(InputWarning, match=r"requests\[1\]\.t: t=900 is after the horizon"):
        scn = scenarios.load(_write(tmp_path, text))
    assert any("after the horizon" in w for w in scn.warnings)


def test_a_device_in_a_state_its_binding_does_not_name_warns(tmp_path: Path) -> None:
    """Before: a cooker written ``state = "On"`` loaded silently, and cook read it as off."""
    world = (ROOT / "robot" / "worlds" / "flat.toml").read_text().replace('state = "on"', 'state = "On"')
    _write(tmp_path, world, "w.toml")
    text = ('kind = "robot"\nworld = "w.toml"\n[objects.pan]\ntype = "pan"\nplace = "kitchen"\n'
            '[[requests]]\nt = 0.0\ntask = "cook"\nargs = { pan = "pan" }\n')
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        scn = scenarios.load(_write(tmp_path, text))
    hits = [w for w in scn.warnings if "device 'cooker'" in w]
    assert len(hits) == 1 and "starts in state 'On'" in hits[0] and "expected state = 'on' or 'off'" in hits[0]
    assert any(issubclass(w.category, InputWarning) for w in caught)


@pytest.mark.parametrize("field", ["deadline = -5.0", "deadline = 20.0", "death_at = 10.0"])
def test_a_deadline_not_after_its_request_warns(tmp_path: Path, field: str) -> None:
    """Before: ``deadline = -5`` or a deadline before the request (read as relative to it, say)
    loaded silently, and every scheduler saw a task late before it existed."""
    name = field.split(" ")[0]
    text = ROBOT.replace('args = { person = "peter" }', f'args = {{ person = "peter", {field} }}')
    with pytest.warns(InputWarning, match=rf"requests\[1\]\.args\.{name}: {name}=.* is not after the request "
                                          r"\(t=20\)"):
        scn = scenarios.load(_write(tmp_path, text))
    assert len(scn.warnings) == 1


@pytest.mark.parametrize("task, args", [
    ("guide_human", '{ person = "john", destination = "bedroom" }'),
    ("human_fell", '{ person = "peter" }'),
])
def test_two_identical_requests_that_overlap_warn(tmp_path: Path, task: str, args: str) -> None:
    text = ROBOT + f'\n[[requests]]\nt = 30.0\ntask = "{task}"\nargs = {args}\n'
    with pytest.warns(InputWarning, match=r"requests\[2\]\.task: the same request as d\d"):
        scn = scenarios.load(_write(tmp_path, text))
    assert len(scn.warnings) == 1


def test_identical_requests_after_a_termination_do_not_warn(tmp_path: Path) -> None:
    text = ROBOT + ('\n[[terminations]]\nt = 25.0\nagent = "d1"\n\n[[requests]]\nt = 30.0\n'
                    'task = "guide_human"\nargs = { person = "john", destination = "bedroom" }\n')
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert scenarios.load(_write(tmp_path, text)).warnings == ()


def test_a_robot_scenario_without_kind_says_to_add_it(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Before: read as a synthetic scenario (the default kind), it failed with "tasks: missing
    (required)", a key robot scenarios do not have."""
    path = _write(tmp_path, ROBOT.replace('kind = "robot"\n', ""))
    assert main(["run", str(path), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"tasker run: error: {path}: kind: missing: a scenario with a world is a robot scenario, "
                          'so write kind = "robot"'), err


ROOT = Path(__file__).parents[2]


@pytest.mark.parametrize(("argv", "expected"), [
    (["run", "robot/worlds/flat.toml"], "this is a world file (it has 'rooms'), not a scenario"),
    (["run", "experiments/sweep/specs/suspension.toml"], "this is a sweep spec (it has 'scenarios'), not a scenario"),
    (["run", "experiments/days/protocols/tabsa.toml"], "this is a day protocol (it has 'arrivals'), not a scenario"),
    (["world", "experiments/inputs/scenarios/paper.toml"],
     "paper.toml:6: kind: this is a scenario file, not a world file"),
])
def test_another_kind_of_file_is_named_for_what_it_is(argv: list[str], expected: str, tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    """Before: a world file or a sweep spec given to ``run`` failed with "tasks: missing (required)",
    a scenario given to ``world`` with "unknown key 'kind'"."""
    monkeypatch.chdir(ROOT)
    assert main([*argv, *(["--out", str(tmp_path / "o")] if argv[0] == "run" else [])]) == 2
    err = capsys.readouterr().err
    assert expected in err and "tasks: missing" not in err, err


@pytest.mark.slow
@pytest.mark.parametrize("text", [
    'kind = "robot"\nworld = "paper"\n[[world_events]]\nt = 3.0\nposture = ["peter", "fallen"]\n',
    'kind = "synthetic"\n[tasks.a]\nstages = [{ action = "x", duration = 2.0 }]\n',
])
def test_a_scenario_without_requests_warns_and_runs(tmp_path: Path, text: str,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    """A world and its events to watch, nothing requested: valid.  Before, refused ("a scenario
    needs at least one request")."""
    path = _write(tmp_path, text)
    assert main(["run", str(path), "--out", str(tmp_path / "o"), "--no-pictures"]) == 0
    captured = capsys.readouterr()
    assert "0 tasks, 0 ended" in captured.out
    assert f"warning: {path}: requests: no [[requests]]: no task runs" in captured.err
    assert (tmp_path / "o" / "trace.jsonl").read_text().startswith('{"t":0.0,"event":"run"')


def test_cli_reports_a_bad_cross_reference_without_a_traceback(tmp_path: Path,
                                                               capsys: pytest.CaptureFixture[str]) -> None:
    path = _write(tmp_path, ROBOT.replace('person = "peter"', 'person = "bob"'))
    assert main(["run", str(path), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "requests[1].args.person" in err and "Traceback" not in err


# ----------------------------------------------------------------------------------------- synthetic scenarios

SYN = standin.DEMO.read_text()


@pytest.mark.parametrize(("old", "new", "field", "fragment"), [
    ('jitter = 0.1', 'jitter = 2.0', "settings.jitter", "<= 1"),
    ('jitter = 0.1', 'jitter = nan', "settings.jitter", "finite"),
    ('jitter = 0.1', 'jiter = 0.1', "settings.jiter", "did you mean 'jitter'"),
    ('rep_rate = 2.0', 'rep_rate = 0.0', "settings.rep_rate", "> 0"),
    ('duration = 8.0', 'duration = -8.0', "tasks.guide_human.stages[0].duration", ">= 0"),
    ('duration = 8.0', 'duration = inf', "tasks.guide_human.stages[0].duration", "finite"),
    ('kind = "blocking" },', 'kind = "blockin" },', "tasks.guide_human.stages[1].kind", "did you mean 'blocking'"),
    ('weight = 4.0', 'weight = -4.0', "tasks.human_fell.weight", ">= 0"),
    ('site = [6.0, 2.0]\nstages', 'site = [6.0]\nstages', "tasks.guide_human.site", "expected [x, y]"),
    ('task = "guide_human"', 'task = "guide"', "requests[0].task", "did you mean 'guide_human'"),
    ('seed = 1', 'seed = "one"', "seed", "expected an integer"),
    ('weight = 1.5 }', 'wieght = 1.5 }', "requests[1].args.wieght", "did you mean 'weight'"),
    ('weight = 1.5 }', 'weight = "heavy" }', "requests[1].args.weight", "expected a number"),
    ('weight = 1.5 }', 'weight = nan }', "requests[1].args.weight", "finite"),
    ('args = { site = [6.0, 2.0] }', 'args = { site = "hall" }', "requests[0].args.site", "site"),
    ('guide = [{ action = "ask_to_wait"', 'guid = [{ action = "ask_to_wait"', "tasks.guide_human.suspension.guid",
     "did you mean 'guide'"),
    ('kind = "synthetic"', 'kind = "robot"', "world", "missing"),
])
def test_bad_synthetic_scenario_field_is_named(tmp_path: Path, old: str, new: str, field: str, fragment: str) -> None:
    assert old in SYN
    path = _write(tmp_path, SYN.replace(old, new, 1))
    loader = scenarios.load if 'kind = "robot"' in new else synthetic.load
    _fails(path, loader, field, fragment, ScenarioError)


def test_synthetic_json_with_nan_is_refused(tmp_path: Path) -> None:
    body = ('{"kind": "synthetic", "tasks": {"a": {"stages": [{"action": "x", "duration": NaN}]}},'
            ' "requests": [{"t": 0, "task": "a"}]}')
    _fails(_write(tmp_path, body, "s.json"), synthetic.load, "tasks.a.stages[0].duration", "finite", ScenarioError)


# ----------------------------------------------------------------------------------------- worlds

WORLD = 'bounds = [[0, 0], [6, 6]]\nwalls = [[0, 2.9, 2, 3.1]]\n[robot]\npose = [4, 4, 0]\n[places]\nhall = [1, 1, 0]\n'


@pytest.mark.parametrize(("text", "field", "fragment"), [
    (WORLD.replace("pose = [4, 4, 0]", "pose = [1, 3, 0]"), "robot.pose", "inside wall"),
    (WORLD.replace("pose = [4, 4, 0]", "pose = [0.1, 4, 0]"), "robot.pose", "overlaps a wall"),
    (WORLD.replace("hall = [1, 1, 0]", "hall = [9, 1, 0]"), "places.hall", "outside the world's bounds"),
    # before: accepted, and every task sent there failed with "no plan reaches the goal"
    (WORLD.replace("hall = [1, 1, 0]", "hall = [1, 2.7, 0]"), "places.hall", "a place is where the robot stands"),
    (WORLD + '[people.ann]\npose = [1, 3, 0]\n', "people.ann.pose", "inside wall"),
    (WORLD + '[people.ann]\npose = [1, 1, 0]\nwalk = [[1, 1, 1], [2, 7, 1]]\n', "people.ann.walk[1]", "outside"),
    (WORLD + '[people.ann]\npose = [1, 1, 0]\nwalk = [[3, 1, 1], [3, 1, 2]]\n', "people.ann.walk[1]", "increase"),
    (WORLD + '[people.ann]\npose = [1, 1, 0]\nevents = [[-1, "fallen"]]\n', "people.ann.events[0]", ">= 0"),
    (WORLD + '[people.ann]\npose = [1, 1, 0]\nposture = "lying"\n', "people.ann.posture", "expected one of"),
    (WORLD + '[people.ann]\npose = [1, 1, 0]\nspeed = nan\n', "people.ann.speed", "finite"),
    (WORLD.replace("[[0, 0], [6, 6]]", "[[0, 0], [6, nan]]"), "bounds", "finite"),
    (WORLD.replace("[[0, 0], [6, 6]]", "[[6, 0], [0, 6]]"), "bounds", "xmin < xmax"),
    # before: accepted, and growing the roadmap over 1e12 m² never ended (gigabytes and counting)
    (WORLD.replace("[[0, 0], [6, 6]]", "[[0, 0], [1e6, 1e6]]"), "bounds", "covers 1e+12 m², more than 10000 m²"),
    (WORLD + '[devices.cooker]\nplace = "hal"\n', "devices.cooker.place", "did you mean 'hall'"),
    (WORLD + '[doors.hall]\nbox = [1, 1, 2, 2]\n', "doors.hall", "used twice"),
    ('facts = [["at", "robot", "kitchen"]]\n' + WORLD, "facts[0]", "'kitchen'"),
    (WORLD.replace("bounds", "bound"), "bound", "did you mean 'bounds'"),
    (WORLD + '[furniture.sofa]\nbox = [1, 1, 2, 2]\nheigth = 1\n', "furniture.sofa.heigth", "did you mean 'height'"),
    (WORLD + '[furniture.sofa]\nbox = [1, 1, 2, 2]\nheight = -1\n', "furniture.sofa.height", "> 0"),
    (WORLD + '[furniture.sofa]\nbox = [5, 5, 7, 7]\n', "furniture.sofa.box", "outside the world's bounds"),
    (WORLD + '[rooms]\nhall = [-1, 0, 3, 3]\n', "rooms.hall", "outside the world's bounds"),
    (WORLD + '[doors.d]\nbox = [5, 5, 7, 6]\n', "doors.d.box", "outside the world's bounds"),
])
def test_bad_world_field_is_named(tmp_path: Path, text: str, field: str, fragment: str) -> None:
    _fails(_write(tmp_path, text, "w.toml"), load_world, field, fragment, WorldFileError)


def test_a_binary_world_file_is_a_clean_error(tmp_path: Path) -> None:
    with pytest.raises(WorldFileError, match="binary file"):
        load_world(_write(tmp_path, b"\x89PNG\x00\x00", "w.toml"))


def test_a_scenario_on_a_bad_world_names_the_world_file(tmp_path: Path) -> None:
    _write(tmp_path, WORLD.replace("hall = [1, 1, 0]", "hall = [9, 1, 0]"), "w.toml")
    text = ('kind = "robot"\nworld = "w.toml"\n[[requests]]\nt = 0.0\ntask = "human_fell"\n'
            'args = { person = "x" }\n')
    with pytest.raises(WorldFileError, match=r"w\.toml:6: places\.hall"):
        scenarios.load(_write(tmp_path, text))


# ----------------------------------------------------------------------------------------- sweep specs

@pytest.mark.parametrize(("body", "field", "fragment"), [
    ('scenarios = ["papr"]\nseeds = 2\nstrategies = ["default"]', "scenarios[0]", "did you mean 'paper'"),
    ('scenarios = ["paper"]\nseeds = 100000000\nstrategies = ["default"]', "seeds", "more than"),
    ('scenarios = ["paper", "carry"]\nseeds = 60000\nstrategies = ["default"]', "seeds", "jobs, more than"),
    ('scenarios = ["paper"]\nseeds = 2.5\nstrategies = ["default"]', "seeds", "expected a count"),
    ('scenarios = ["paper"]\nseeds = [1, -2]\nstrategies = ["default"]', "seeds[1]", ">= 0"),
    ('scenarios = ["paper"]\nseeds = 2\nseed_start = 4294967295\nstrategies = ["default"]', "seeds", "largest seed"),
    ('scenarios = ["paper"]\nseeds = [1, nan]\nstrategies = ["default"]', "seeds", "finite"),
    ('scenarios = ["paper"]\nseeds = 2\nseed_start = -inf\nstrategies = ["default"]', "seed_start", "finite"),
    ('scenarios = ["paper"]\nseeds = 2\nstrategies = [{scheduler = "alg"}]', "strategies[0]",
     "did you mean 'alg2'"),
    ('scenarios = ["paper", "paper"]\nseeds = 2\nstrategies = ["default"]', "scenarios[1]", "listed twice"),
    ('scenarios = ["paper"]\nseds = 2\nstrategies = ["default"]', "seeds", "missing"),
    ('scenario = ["paper"]\nseeds = 2\nstrategies = ["default"]', "scenarios",
     "missing (required); the file has 'scenario' (line 1), not a valid key: did you mean 'scenarios'?"),
    ('scenarios = "paper"\nseeds = 2\nstrategies = ["default"]', "scenarios", "expected an array"),
    ('scenarios = ["paper"]\nseeds = 2\nstrategies = ["default"]\n[variants.paper]\ninterrupt = "requests[9]"\n'
     'times = { start = 0.0, stop = 60.0, step = 20.0 }', "variants.paper.interrupt",
     "no requests[9] in 'paper': it has 4 requests, requests[0]..requests[3]"),
    (f'scenarios = ["{standin.DEMO.as_posix()}"]\nseeds = 2\nstrategies = ["default"]\n'
     f'[variants."{standin.DEMO.as_posix()}"]\ninterrupt = "requests[1]"\ntimes = {{ start = 0.0, stop = 60.0, '
     'step = 20.0 }', "variants.", "is a synthetic scenario: only robot scenarios are randomised"),
])
def test_bad_sweep_spec_field_is_named(tmp_path: Path, body: str, field: str, fragment: str) -> None:
    _fails(_write(tmp_path, body, "spec.toml"), load_spec, field, fragment, SpecError)


def test_strategies_a_synthetic_scenario_ignores_warn(tmp_path: Path) -> None:
    """A synthetic scenario swept over suspension=static/planned ran static twice, silently: the
    report then compared two identical strategies.  The scheduler alone, or a robot scenario, is quiet."""
    demo = standin.DEMO.as_posix()
    body = f'scenarios = ["{demo}", "paper"]\nseeds = 2\n[factors]\nsuspension = ["static", "planned"]\n'
    with pytest.warns(InputWarning, match=rf"spec\.toml:3: factors: '{demo}' is a synthetic scenario, whose timed "
                                          r"stages ignore suspension: its runs of strategies that differ only there "
                                          r"are alike") as caught:
        load_spec(_write(tmp_path, body, "spec.toml"))
    assert len(caught) == 1  # paper is a robot scenario
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        load_spec(_write(tmp_path, f'scenarios = ["{demo}"]\nseeds = 2\nstrategies = ["scheduler=fifo", '
                                   '"scheduler=alg2"]\n', "spec.toml"))
        load_spec(_write(tmp_path, body.replace(f'"{demo}", ', ""), "spec.toml"))
        # one setting compares nothing: a synthetic sweep that names its (only) strategy is quiet
        load_spec(_write(tmp_path, f'scenarios = ["{demo}"]\nseeds = 2\nstrategies = '
                                   '["update=static,suspension=static"]\n', "spec.toml"))


def test_a_non_utf8_spec_is_a_clean_error(tmp_path: Path) -> None:
    with pytest.raises(SpecError, match="not UTF-8"):
        load_spec(_write(tmp_path, b'name = "\xff"\n', "spec.toml"))


# ----------------------------------------------------------------------------------------- typed arguments, generally

def _typed_cases() -> list[tuple[str, str, str, str]]:
    """(world, task, argument, PDDL type) for each typed argument of each bundled task type, in
    each shipped world that has objects of every type the task's arguments need."""
    from experiments.inputs.crossref import _most_specific, arg_types, world_objects
    from planners.bundled import task_types

    out = []
    for world in ("paper", "flat"):
        objects = world_objects(load_world(world))
        for task in task_types():
            domain = task.domain  # type: ignore[attr-defined]
            typed = {a: _most_specific(domain, ts) for a, ts in arg_types(task).items()
                     if a in {s.name for s in task.arg_specs}}
            if all(any(all(domain.has_type(ty, w) for w in ts) for ty in objects.values()) for ts in typed.values()):
                out.extend((world, task.name, a, sorted(ts)[0]) for a, ts in sorted(typed.items()) if ts != {""})
    return out


@pytest.mark.parametrize(("world", "task", "arg", "pddl_type"), _typed_cases())
def test_every_typed_argument_must_name_a_world_object_of_its_type(tmp_path: Path, world: str, task: str, arg: str,
                                                                   pddl_type: str) -> None:
    """The general rule: an argument used as a PDDL object of type T names a world object of type T."""
    from experiments.inputs.crossref import arg_types, world_objects
    from planners.bundled import task_types

    tt = next(t for t in task_types() if t.name == task)
    objects = world_objects(load_world(world))
    domain = tt.domain  # type: ignore[attr-defined]
    args = {name: sorted(n for n, ty in objects.items() if all(domain.has_type(ty, w) for w in types))[0]
            for name, types in arg_types(tt).items() if name in {a.name for a in tt.arg_specs}}
    wrong = sorted(n for n, ty in objects.items() if not domain.has_type(ty, pddl_type))[0]

    def scenario(value: str) -> Path:
        given = {**args, arg: value}
        text = (f'kind = "robot"\nworld = "{world}"\n[[requests]]\nt = 0.0\ntask = "{task}"\nargs = {{ '
                + ", ".join(f'{k} = "{v}"' for k, v in given.items()) + " }\n")
        return _write(tmp_path, text)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", InputWarning)
        scenarios.load(scenario(args[arg]))  # the right type loads
    _fails(scenario(wrong), scenarios.load, f"requests[0].args.{arg}", f"expected a {pddl_type}", ScenarioError)
    _fails(scenario("nobody_here"), scenarios.load, f"requests[0].args.{arg}", "'nobody_here'", ScenarioError)


def test_typed_cases_cover_every_bundled_task_type() -> None:
    from planners.bundled import task_types

    assert {c[1] for c in _typed_cases()} == {t.name for t in task_types()}


SHIPPED = Path(__file__).resolve().parents[2] / "experiments"
_KIND_CASES = [  # (command, file of another kind, what the message must say)
    (["day", "--days", "1", "--protocol"], "inputs/scenarios/paper.toml",
     "this is a scenario (it has 'requests'), not a day protocol: run it with 'tasker run FILE'"),
    (["day", "--days", "1", "--protocol"], "sweep/specs/suspension.toml",
     "this is a sweep spec (it has 'scenarios'), not a day protocol"),
    (["day", "--days", "1", "--protocol"], "days/protocols/tabsa_apartment.toml",
     "this is a world file (it has 'rooms')"),
    (["run"], "days/protocols/tabsa.toml",
     "this is a day protocol (it has 'arrivals'), not a scenario: run it with 'tasker day --protocol FILE'"),
    (["run"], "sweep/specs/suspension.toml", "this is a sweep spec (it has 'scenarios'), not a scenario"),
    (["sweep", "--db", "{tmp}/r.db"], "days/protocols/tabsa.toml",
     "this is a day protocol (it has 'arrivals'), not a sweep spec"),
    (["sweep", "--db", "{tmp}/r.db"], "inputs/scenarios/synthetic_demo.toml",
     "this is a scenario (it has 'requests'), not a sweep spec"),
]


@pytest.mark.parametrize(("command", "file", "message"), _KIND_CASES, ids=[f"{c[0][0]} {c[1]}" for c in _KIND_CASES])
def test_a_file_of_another_kind_is_named_for_what_it_is(command: list[str], file: str, message: str, tmp_path: Path,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    """A protocol given to 'tasker run' was refused with 'tasks.transport.stages: missing (required)',
    a scenario given to 'tasker day' with 'day: missing (required)': each sent the user to fix a
    file that was fine."""
    argv = [a.format(tmp=tmp_path) for a in command] + [str(SHIPPED / file)]
    if command[0] == "sweep":  # the spec is positional
        argv = [argv[0], str(SHIPPED / file), *argv[1:-1]]
    if command[0] != "sweep":
        argv += ["--out", str(tmp_path / "out")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert f"{SHIPPED / file}: {message}" in err and "Traceback" not in err
