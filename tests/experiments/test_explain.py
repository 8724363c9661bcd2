"""``tasker explain``: a run's problems/ folder, PDDL a default PDDLReader reads, and the explanation."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from unified_planning.io import PDDLReader

from experiments.cli import main as cli_main
from experiments.report import explain
from experiments.run.runner import run_scenario
from planners.bundled import task_types
from planners.examples import StraightLineMotion, example_context
from planners.pddl_task import PddlTaskType, planning_journal
from planners.planner import PddlText, Planner
from planners.problem import portable
from planners.results import PlanStatus
from tasker.events import parse
from tasker.stage import Purpose
from tasker.task import Strategy
from tests.experiments.events import complete

UNSOLVABLE = """
kind = "robot"
name = "unsolvable"
world = "flat"
seed = 1

[settings]
scheduler = "alg2"
update = "planned"
suspension = "planned"
horizon = 60.0

# Anna stands in the flat's storage room, walled off (no door): the robot cannot reach her
[people.anna]
pose = [0.7, 5.2, 0.0]

[[requests]]
t = 1.0
task = "guide_human"
args = { person = "anna", destination = "living" }
"""


@pytest.fixture(scope="module")
def unsolvable_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("unsolvable")
    (folder / "unsolvable.toml").write_text(UNSOLVABLE, encoding="utf-8")
    out = folder / "run"
    run_scenario(folder / "unsolvable.toml", out=out, pictures=False)
    return out


def _read(domain: str, problem: str):  # noqa: ANN202 - a UP Problem
    return PDDLReader().parse_problem_string(domain, problem)  # default settings, as any user would


@pytest.mark.slow
@pytest.mark.parametrize("task", [t for t in task_types() if isinstance(t, PddlTaskType)], ids=lambda t: t.name)
def test_portable_pddl_is_read_by_a_default_reader_and_plans_map_back(task: PddlTaskType) -> None:
    ctx = example_context(task, strategy=Strategy("planned", "planned"), motion=StraightLineMotion())
    text = task.planning_problem(ctx, Purpose.UP_TSK)
    with pytest.raises(Exception, match="already defined"):  # what this fixes: robot - robot, action place
        _read(text.domain, text.problem)
    p = portable(task.domain, text.domain, text.problem)
    problem = _read(p.domain, p.problem)
    assert {o.name for o in problem.all_objects} >= {p.renamed.get(n, n) for n in ctx.world.objects
                                                      if ctx.world.objects[n] in task.domain.types}
    planner = Planner(cache_size=0)
    original, written = planner.solve(text), planner.solve(PddlText(p.domain, p.problem))
    assert original.solved and written.solved and original.cost == written.cost
    assert tuple(p.original(s) for s in written.plan or ()) == original.plan
    assert all(p.original(p.written(s)) == s for s in original.plan or ())


def test_journal_records_only_inside_the_block() -> None:
    task = next(t for t in task_types() if isinstance(t, PddlTaskType))
    ctx = example_context(task, strategy=Strategy("planned", "planned"), motion=StraightLineMotion())
    task.update_task(ctx)  # outside: nothing kept anywhere
    with planning_journal() as journal:
        task.update_task(ctx)
    task.update_task(ctx)
    assert [(r.agent, r.purpose, r.status) for r in journal] == [(ctx.agent, "upTsk", "solved")]


@pytest.mark.slow
def test_unsolvable_uptsk_is_explained_with_pddl_a_planner_confirms(unsolvable_run: Path, tmp_path: Path) -> None:
    index = json.loads((unsolvable_run / "problems" / "index.json").read_text())
    assert [(e["agent"], e["purpose"], e["status"]) for e in index] == [("d1", "upTsk", "unsolvable")]
    trace = (unsolvable_run / "trace.jsonl").read_text()
    assert "(define" not in trace  # the PDDL stays out of the trace

    assert cli_main(["explain", str(unsolvable_run), "--agent", "d1", "--out", str(tmp_path)]) == 0
    domain, problem = (tmp_path / "domain.pddl").read_text(), (tmp_path / "problem.pddl").read_text()
    assert not (tmp_path / "plan").exists()
    model = _read(domain, problem)  # a default PDDLReader takes it
    result = Planner(cache_size=0).solve(model)
    assert result.status is PlanStatus.UNSOLVABLE
    text = (tmp_path / "explain.txt").read_text()
    assert "upTsk at t=1.002 s, unsolvable" in text and "no plan: unsolvable" in text
    assert "transition upTsk -> end" in text and "end (failed): upTsk unsolvable" in text


def _problems(run: Path, task_type: str, calls: list[tuple[float, str]]) -> Path:
    """A run folder's ``problems/``: one solved call of d1 per ``(t, purpose)``, file ``N.pddl`` holding
    ``; problem N``."""
    (run / "problems").mkdir(parents=True)
    entries = []
    for n, (t, purpose) in enumerate(calls, start=1):
        (run / "problems" / f"{n}.pddl").write_text(f"; problem {n}\n")
        entries.append({"n": n, "t": t, "agent": "d1", "task_type": task_type, "purpose": purpose, "label": "",
                        "status": "solved", "domain": f"{task_type}.domain.pddl", "problem": f"{n}.pddl",
                        "message": ""})
    (run / "problems" / f"{task_type}.domain.pddl").write_text("; domain\n")
    (run / "problems" / "index.json").write_text(json.dumps(entries))
    return run


def test_explain_picks_the_problem_in_force(tmp_path: Path) -> None:
    run = _problems(tmp_path / "run", "cook", [(0.5, "upTsk"), (40.0, "genSusp"), (80.0, "upTsk")])
    assert explain.explain(run, "d1").entry.n == 3
    assert explain.explain(run, "d1", at=45.0).entry.n == 2
    assert explain.explain(run, "d1", at=0.5).problem == "; problem 1\n"
    with pytest.raises(explain.ExplainError, match="had not planned yet at t=0.1 s; it planned at t = 0.5, 40, 80"):
        explain.explain(run, "d1", at=0.1)
    with pytest.raises(explain.ExplainError, match="agent 'd11' planned nothing.*did you mean 'd1'"):
        explain.explain(run, "d11")


def _instant_run(folder: Path) -> Path:
    """A run folder as ``tasker run carry`` writes one, cut down: d1 plans at 0.002; a fall is requested
    at 40.0, Alg. 2 sends ``susp`` at 40.001, d1 plans its suspension at 40.002 and runs it from 40.052;
    d1 plans again at 80.1 (the loop's float: 80.10000000000001)."""
    run = _problems(folder / "run", "carry_object", [(0.002, "upTsk"), (40.002, "genSusp"),
                                                     (80.10000000000001, "upTsk")])
    events = [{"t": 0.0, "event": "run"},
              {"t": 0.001, "event": "command", "agent": "d1", "flag": "start"},
              {"t": 0.002, "event": "transition", "agent": "d1", "from": "compSP", "to": "upTsk"},
              {"t": 0.502, "event": "transition", "agent": "d1", "from": "upTsk", "to": "exeTsk"},
              {"t": 40.0, "event": "request", "agent": "d2", "task_type": "human_fell"},
              {"t": 40.001, "event": "decision", "algorithm": "alg2", "dac": "d2", "exeDA": "d1", "switch": True},
              {"t": 40.001, "event": "command", "agent": "d1", "flag": "susp"},
              {"t": 40.002, "event": "transition", "agent": "d1", "from": "exeTsk", "to": "genSusp"},
              {"t": 40.052, "event": "transition", "agent": "d1", "from": "genSusp", "to": "exeSusp"},
              {"t": 80.1, "event": "transition", "agent": "d1", "from": "compSP", "to": "upTsk"}]
    (run / "trace.jsonl").write_text("".join(json.dumps(complete(e)) + "\n" for e in events))
    return run


def test_at_a_time_is_the_instant_the_trace_shows_there(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Issue 39: ``--at 40`` gave the upTsk of t = 0.002, not the genSusp the trace shows at 40: the
    answer to what happened at T comes a tick or two later (40.001, 40.002), and is part of T."""
    run = _instant_run(tmp_path)
    at40 = explain.explain(run, "d1", at=40.0)
    assert (at40.entry.purpose, at40.entry.t, at40.until) == ("genSusp", 40.002, 40.002)
    assert [type(e).__name__ for e in at40.events][-3:] == ["Decision", "CommandSent", "Transition"]
    assert at40.events[-1].t == 40.002  # not the exeSusp of 40.052: the planning time is a pause
    assert explain.explain(run, "d1", at=40.001).entry.purpose == "genSusp"
    before = explain.explain(run, "d1", at=39.999)
    assert (before.entry.purpose, before.until) == ("upTsk", 39.999)
    assert explain.explain(run, "d1", at=60.0).entry.purpose == "genSusp"
    assert explain.explain(run, "d1", at=80.1).entry.n == 3  # 80.10000000000001 is 80.1 in the trace
    assert cli_main(["explain", str(run), "--agent", "d1", "--at", "40"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("; d1 (carry_object): genSusp at t=40.002 s, solved\n")
    assert "; at t=40 s: with what the loop did at once in answer, up to t=40.002 s" in out
    assert "t=    40.002 transition exeTsk -> genSusp" in out and "40.052" not in out


@pytest.mark.slow
def test_at_the_interruption_of_a_real_run_explains_its_suspension(tmp_path: Path,
                                                                    capsys: pytest.CaptureFixture[str]) -> None:
    """The carry scenario asks for help at t = 40 while d1 carries the vase (issue 39's example)."""
    out = tmp_path / "carry"
    run_scenario("carry", out=out, pictures=False)
    assert cli_main(["explain", str(out), "--agent", "d1", "--at", "40"]) == 0
    text = capsys.readouterr().out
    assert re.match(r"; d1 \(carry_object\): genSusp at t=40\.00\d s, solved", text), text[:200]
    assert "transition exeTsk -> genSusp" in text


@pytest.mark.slow
def test_explain_without_an_agent_names_the_agents_of_the_run(unsolvable_run: Path,
                                                              capsys: pytest.CaptureFixture[str]) -> None:
    """Before: argparse's bare "the following arguments are required: --agent", whatever the folder held."""
    assert cli_main(["explain", str(unsolvable_run)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("tasker explain: error: argument --agent: which agent? an id such as d1; agents that "
                          f"planned in {unsolvable_run}: d1") and "Traceback" not in err


def test_explain_errors_are_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert cli_main(["explain", str(tmp_path / "nope"), "--agent", "d1"]) == 2
    assert "no such run folder" in capsys.readouterr().err
    assert cli_main(["explain", str(tmp_path), "--agent", "d1"]) == 2
    err = capsys.readouterr().err
    assert "problems/index.json: no planning record" in err and "Traceback" not in err
    (tmp_path / "problems").mkdir()
    (tmp_path / "problems" / "index.json").write_text("[{")
    assert cli_main(["explain", str(tmp_path), "--agent", "d1"]) == 2
    assert "index.json:1: not valid JSON" in capsys.readouterr().err


GOOD_RECORD = {"n": 1, "t": 1.0, "agent": "d1", "task_type": "cook", "purpose": "upTsk", "label": "",
               "status": "solved", "domain": "cook.domain.pddl", "problem": "1.pddl", "message": ""}


@pytest.mark.parametrize(("record", "message"), [
    (None, r"record \[1\]: expected a planning record \(an object\), got null"),
    ({k: v for k, v in GOOD_RECORD.items() if k != "agent"}, r"record \[1\]: agent: expected a string, got nothing"),
    ({**GOOD_RECORD, "t": "x"}, r"record \[1\]: t: expected a finite number, got \"x\""),
    ({**GOOD_RECORD, "plan_file": 5}, r"record \[1\]: plan_file: expected a string, got 5"),
])
def test_a_damaged_index_or_trace_is_a_clean_error(tmp_path: Path, record: object, message: str,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    """A damaged problems/index.json names the file and the record; a damaged trace its line;
    --at is a finite time >= 0.  Each is one line and exit status 2, never an internal error."""
    (tmp_path / "problems").mkdir()
    (tmp_path / "problems" / "cook.domain.pddl").write_text("; domain\n")
    (tmp_path / "problems" / "1.pddl").write_text("; problem\n")
    (tmp_path / "problems" / "index.json").write_text(json.dumps([GOOD_RECORD, record]))
    assert cli_main(["explain", str(tmp_path), "--agent", "d1"]) == 2
    err = capsys.readouterr().err
    assert re.search(r"problems/index\.json: " + message, err), err
    (tmp_path / "problems" / "index.json").write_text(json.dumps([GOOD_RECORD]))
    run = json.dumps(complete({"t": 0.0, "event": "run"}))
    (tmp_path / "trace.jsonl").write_text(run + '\n[1, 2]\n')
    assert cli_main(["explain", str(tmp_path), "--agent", "d1"]) == 2
    assert "trace.jsonl:2: not a JSON object: [1, 2]" in capsys.readouterr().err
    for at in ("nan", "inf", "-1"):
        assert cli_main(["explain", str(tmp_path), "--agent", "d1", "--at", at]) == 2
        assert "argument --at: expected a finite number of seconds >= 0" in capsys.readouterr().err


def test_repeated_decisions_are_folded() -> None:
    decision = {"event": "decision", "algorithm": "alg2", "dac": "d2", "exeDA": "d1", "rule": "cost", "switch": False}
    events = [{"t": float(t), **decision} for t in range(5)] + [{"t": 5.0, "event": "command", "agent": "d1",
                                                                  "flag": "susp"}]
    lines = explain._event_lines([parse(complete(e)) for e in events])
    assert len(lines) == 4 and "3 more decisions like it" in lines[1] and "command susp" in lines[3]
