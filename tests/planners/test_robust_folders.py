"""Task folders and PDDL that used to crash, or to be accepted and fail later (or never).

Each case names what happened before: an internal error (exit 3), tasker ending with a task.py's
exit status and no word, or a contradiction accepted without a warning.
"""

from __future__ import annotations

import json
import os
import warnings
from pathlib import Path
from typing import Any

import pytest

from experiments.cli import main as cli_main
from planners.checks import DefinitionError, PddlError, load_domain, load_problem
from planners.loader import HookExited, load_task
from planners.scaffold import scaffold
from tasker.errors import ConfigError
from tasker.support.reader import InputWarning

DOMAIN = """(define (domain d) (:requirements :strips :typing) (:types thing)
 (:predicates (p ?x - thing) (q ?x - thing))
 (:action act :parameters (?x - thing) :precondition (p ?x) :effect (q ?x)))
"""


def _problem(goal: str, domain: str = "d") -> str:
    return f"(define (problem x) (:domain {domain}) (:objects o - thing) (:init (p o)) (:goal {goal}))\n"


def _files(tmp_path: Path, domain: str, problem: str) -> tuple[Path, Path]:
    d, p = tmp_path / "domain.pddl", tmp_path / "problem.pddl"
    d.write_text(domain)
    p.write_text(problem)
    return d, p


@pytest.mark.parametrize(("types", "cycle"), [
    ("(:types thing a - b\n b - a)", "b - a - b"),
    ("(:types thing a - b b - c\n c - a)", "- a -"),
    ("(:types thing\n  a - B B - A)", "b - a - b"),
])
def test_a_cycle_of_types_is_refused(tmp_path: Path, types: str, cycle: str) -> None:
    """Before: unified-planning recursed up the cycle: RecursionError, exit 3."""
    d, _ = _files(tmp_path, DOMAIN.replace("(:types thing)", types), _problem("(q o)"))
    with pytest.raises(PddlError, match=f"the types form a cycle: .*{cycle}") as info:
        load_domain(d)
    assert info.value.line == 1


@pytest.mark.parametrize("depth", [40, 100, 5000])
def test_a_very_deep_goal_is_refused_with_its_line(tmp_path: Path, depth: int,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    d, p = _files(tmp_path, DOMAIN, "; a comment (((((\n" + _problem("(and " * depth + "(q o)" + ")" * depth))
    with pytest.raises(PddlError, match="parentheses nested more than 32 deep") as info:
        load_problem(d, p)
    assert info.value.line == 2
    assert cli_main(["plan", str(d), str(p)]) == 2
    err = capsys.readouterr().err
    assert "nested more than 32 deep" in err and "internal error" not in err


def test_a_goal_nested_within_the_limit_plans(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    d, p = _files(tmp_path, DOMAIN, _problem("(and " * 20 + "(q o)" + ")" * 20))
    assert load_problem(d, p)[2] is not None
    assert cli_main(["plan", str(d), str(p), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "solved" and out["plan"] == [["act", "o"]]


def test_a_deep_domain_is_refused(tmp_path: Path) -> None:
    deep = DOMAIN.replace(":effect (q ?x)", ":effect " + "(and " * 40 + "(q ?x)" + ")" * 40)
    d, _ = _files(tmp_path, deep, _problem("(q o)"))
    with pytest.raises(PddlError, match="nested more than 32 deep"):
        load_domain(d)


@pytest.mark.slow
def test_a_problem_of_another_domain_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Before: planned silently against the domain given."""
    d, p = _files(tmp_path, DOMAIN, "\n" + _problem("(q o)", domain="other"))
    assert cli_main(["plan", str(d), str(p)]) == 2
    err = capsys.readouterr().err
    assert f"{p}:2: the problem is for domain 'other', but the domain given is 'd'" in err
    p.write_text(_problem("(q o)", domain="D"))  # PDDL names ignore case
    assert cli_main(["plan", str(d), str(p)]) == 0


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    out = tmp_path / "fetch"
    scaffold("fetch", out)
    return out


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text, old
    path.write_text(text.replace(old, new, 1))


@pytest.mark.slow
def test_an_argument_declared_twice_is_refused(folder: Path) -> None:
    """Before: accepted; the request's value went to whichever declaration came first."""
    toml = folder / "task.toml"
    toml.write_text(toml.read_text() + '\n[[args]]\nname = "item"\ntype = "int"\n')
    with pytest.raises(DefinitionError, match=r"args\[2\].name: argument 'item' is declared twice \(first at line"):
        load_task(folder, use_cache=False)


@pytest.mark.slow
def test_choices_must_fit_the_type_and_duplicates_warn(folder: Path) -> None:
    toml = folder / "task.toml"
    _edit(toml, '# choices = ["living", "kitchen"]', 'choices = ["living", 5]')
    with pytest.raises(DefinitionError, match=r"choices\[1\]: expected a non-empty string, got 5"):
        load_task(folder, use_cache=False)
    _edit(toml, 'choices = ["living", 5]', 'choices = ["living", "kitchen", "living"]')
    with pytest.warns(InputWarning, match="'living' listed more than once"):
        load_task(folder, use_cache=False)


def test_a_binding_whose_state_equals_otherwise_is_refused(folder: Path) -> None:
    toml = folder / "task.toml"
    _edit(toml, 'kind = "held"                     # device | door | held | follower | waiting',
          'kind = "device"\nstate = "on"\notherwise = "on"')
    with pytest.raises(DefinitionError, match="bindings\\[0\\].otherwise: state and otherwise are both 'on'"):
        load_task(folder, use_cache=False)


def test_one_fact_bound_twice(folder: Path) -> None:
    toml = folder / "task.toml"
    text = toml.read_text()
    toml.write_text(text + '\n[[bindings]]\nkind = "follower"\nfact = ["holding", "?r", "?i"]\n')
    with pytest.raises(DefinitionError, match="'holding' is bound twice, differently: as held of \\?i \\(line"):
        load_task(folder, use_cache=False)
    toml.write_text(text + '\n[[bindings]]\nkind = "held"\nfact = ["holding", "?r", "?i"]\n')
    with pytest.warns(InputWarning, match="'holding' is bound twice .*the same way"):
        task = load_task(folder, use_cache=False)
    assert len(task.meaning.bindings) == 1


@pytest.mark.slow
def test_a_fact_bound_differently_by_two_folders_is_refused(folder: Path, tmp_path: Path) -> None:
    """The world reads a bound fact from the first binding that covers it: the other was silently ignored."""
    from planners.bundled import task_types

    other = tmp_path / "other"
    scaffold("other", other)
    _edit(other / "task.toml", 'kind = "held"                     # device | door | held | follower | waiting',
          'kind = "follower"')
    with pytest.raises(ConfigError, match=f"'holding' is bound as held of \\?[ik] by .* and as follower of \\?i "
                                          f"by {other / 'task.toml'}"):
        task_types([folder, other])
    assert {t.name for t in task_types([folder])} >= {"fetch", "carry_object"}  # alike: accepted


@pytest.mark.slow
@pytest.mark.parametrize(("key", "old", "new", "fragment"), [
    ("timeout", "timeout_s = 10.0", "timeout_s = 1e300", "task.timeout_s: expected a number <= 86400"),
    ("cps", "cps = 1.0", "cps = 1" + "0" * 400, "schedule.cps: expected a 64-bit integer"),
    ("budget", "budget_s = 60", "budget_s = 1e300", "hazards[0].budget_s: expected a number <= 604800"),
    ("pose", "robot = [5.0, 2.0, 3.1416]", "robot = [5" + "0" * 400 + ", 2.0, 3.1416]",
     "example.poses.robot[0]: expected a 64-bit integer"),
    ("deep", 'goal = [["at", "$item", "$destination"], ["hand_empty", "$robot"]]',
     "goal = [" + "[" * 3000 + "]" * 3000 + "]", "nested more than 64 deep"),
])
def test_numbers_and_nesting_out_of_range_are_refused_where_read(folder: Path, key: str, old: str, new: str,
                                                                  fragment: str) -> None:
    """Before: OverflowError or RecursionError, exit 3."""
    _edit(folder / "task.toml", old, new)
    with pytest.raises(DefinitionError) as info:
        load_task(folder, use_cache=False)
    assert fragment in str(info.value) and str(folder / "task.toml") in str(info.value)


@pytest.mark.slow
@pytest.mark.parametrize(("body", "fragment"), [
    ("import sys\nsys.exit(4)\n", "task.py:2: called sys.exit(4) on import"),
    ("import sys\nsys.exit()\n", "task.py:2: called sys.exit() on import"),
    ("raise SystemExit('bye')\n", "called sys.exit('bye') on import"),
])
def test_a_task_py_that_exits_on_import_is_named(folder: Path, body: str, fragment: str,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    """Before: tasker ended with the task.py's exit status and no message."""
    (folder / "task.py").write_text(body)
    assert cli_main(["domains", "--path", str(folder)]) == 2
    err = capsys.readouterr().err
    assert f"tasker domains: error: {folder / 'task.py'}" in err and fragment in err


@pytest.mark.slow
def test_a_hook_that_exits_is_an_error_of_its_task(folder: Path) -> None:
    """sys.exit() in a hook at run time ended tasker; now it is an exception the agent contains."""
    (folder / "task.py").write_text("import sys\n\ndef check_terminate(ctx, world):\n    sys.exit(3)\n")
    with pytest.warns(InputWarning, match="check_terminate called sys.exit\\(3\\)"):
        task = load_task(folder, use_cache=False)
    with pytest.raises(HookExited, match=f"{folder / 'task.py'}:4: check_terminate called sys.exit"):
        task.hooks["check_terminate"](None, None)
    assert issubclass(HookExited, Exception)


@pytest.mark.slow
def test_a_task_py_that_is_a_device_is_refused(folder: Path) -> None:
    os.symlink("/dev/zero", folder / "task.py")
    with pytest.raises(DefinitionError, match="task.py: is not a regular file"):
        load_task(folder, use_cache=False)


@pytest.mark.slow
def test_a_domain_that_is_a_device_is_refused(folder: Path) -> None:
    (folder / "domain.pddl").unlink()
    os.symlink("/dev/zero", folder / "domain.pddl")
    with pytest.raises(DefinitionError, match="domain.pddl: is not a regular file"):
        load_task(folder)


@pytest.mark.slow
def test_a_warning_is_given_every_time_not_only_before_the_check_is_cached(
        folder: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Before: the [example]'s warnings came from the checks a cached folder skips: shown once."""
    monkeypatch.setenv("TASKER_CACHE", str(tmp_path / "cache"))
    _edit(folder / "task.toml", 'facts = [["at", "robot", "living"], ["hand_empty", "robot"]',
          'facts = [["at", "robot", "living"]')  # the hand is never empty: no plan
    seen = []
    for _ in range(3):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("default")
            load_task(folder)
        seen.append([str(w.message) for w in caught if issubclass(w.category, InputWarning)])
    assert seen[0] and seen[0] == seen[1] == seen[2], seen
    assert "no plan reaches the goal" in seen[0][0] and seen[0][0].startswith(str(folder / "task.toml"))


def test_tasker_new_refuses_a_bundled_name(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Before: it wrote the folder, and every later command refused it ('defined twice')."""
    assert cli_main(["new", "cook", str(tmp_path / "cook")]) == 2
    err = capsys.readouterr().err
    assert "'cook' is the name of a bundled task type" in err and "my_cook" in err
    assert not (tmp_path / "cook").exists()


def hook_job(job: Any) -> tuple[dict[str, Any], dict[str, Any]]:
    """A sweep's run_fn: load the job's task folder (its source) and ask its check_args hook."""
    task = load_task(job.source, use_cache=False)
    task.hooks["check_args"]({})
    return {}, {}


@pytest.mark.slow
def test_a_hook_that_kills_its_process_is_named_in_the_sweep(folder: Path) -> None:
    """Before: 'worker process died (exit code 7) ... (a crash in native code, os._exit, or the OOM killer)'."""
    from experiments.inputs.strategy import Strategy
    from experiments.metrics.store import ResultStore
    from experiments.sweep.driver import run_sweep
    from experiments.sweep.spec import Job

    (folder / "task.py").write_text("import os\n\ndef check_args(args):\n    os._exit(7)\n")  # on load too
    db = folder.parent / "r.db"
    summary = run_sweep([Job("hooked", str(folder), 1, Strategy())], db, workers=1, run_fn=hook_job, progress=False)
    assert summary.errors == 1
    with ResultStore(db, readonly=True) as store:
        (row,) = store.rows()
    assert row.error is not None and "exit code 7" in row.error
    assert f"in the task.py hook check_args of {folder / 'task.py'}" in row.error


@pytest.mark.slow
@pytest.mark.parametrize("name", ["robot", "deadline", "priority", "death_at"])
def test_a_reserved_argument_name_is_refused(folder: Path, name: str) -> None:
    """Before: an argument named deadline was stripped from the folder's own arguments by the request
    fields every task type takes, so every request lacked it; robot shadowed $robot."""
    toml = folder / "task.toml"
    toml.write_text(toml.read_text() + f'\n[[args]]\nname = "{name}"\ntype = "float"\nrequired = false\n')
    with pytest.raises(DefinitionError, match=f"args\\[2\\].name: '{name}' is reserved"):
        load_task(folder, use_cache=False)


def test_the_reserved_names_cover_the_request_fields() -> None:
    from experiments.inputs.request_fields import FIELD_NAMES
    from planners.taskspec import RESERVED_ARGS

    assert set(FIELD_NAMES) <= set(RESERVED_ARGS)


@pytest.mark.slow
def test_one_condition_declared_as_two_hazards_is_refused(folder: Path) -> None:
    """Before: accepted; every hazard metric counted the held item twice."""
    toml = folder / "task.toml"
    toml.write_text(toml.read_text() + '\n[[hazards]]\nname = "again"\nfact = ["holding", "$robot", "$item"]\n'
                                       'budget_s = 30\n')
    with pytest.raises(DefinitionError, match=r"hazards\[1\]: hazard 'again' has the fact of hazard 'item_held'"):
        load_task(folder, use_cache=False)
