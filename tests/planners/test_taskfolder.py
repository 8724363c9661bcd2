"""Malformed task folders are refused at load time, naming the file and what is wrong."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

import domains
from planners.bundled import task_types
from planners.checks import DefinitionError
from planners.loader import load_task, load_task_folder, store_loader


def _copy(tmp_path: Path, name: str = "guide_human") -> Path:
    dst = tmp_path / name
    shutil.copytree(domains.BUNDLED / name, dst, ignore=shutil.ignore_patterns("__pycache__"))
    return dst


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text, old
    path.write_text(text.replace(old, new, 1))


TOML_CASES = [
    ('skill = "say"\nkind = "blocking"\ntext = "Hello {h}', 'skill = "talk"\nkind = "blocking"\ntext = "Hello {h}',
     "actions.greet.skill: expected one of ['navigate', 'say', 'manipulate', 'wait'], got 'talk'"),
    ('[actions.say_goodbye]\nskill = "say"\n', '[actions.say_goodbye]\nskill = "say"\nkind = "sometimes"\n',
     "actions.say_goodbye.kind: expected one of"),
    ('["not", "told_to_wait", "$person"]]', '["not", "told_to", "$person"]]', "unknown predicate 'told_to'"),
    ('goal = [["at", "$person", "$destination"]', 'goal = [["at", "$person"]', "takes 2 argument(s)"),
    ('{ action = "say_goodbye", args = ["$robot", "$person", "$destination"] }',
     '{ action = "wave", args = ["$robot"] }', "unknown action 'wave'"),
    ('{ action = "say_goodbye", args = ["$robot", "$person", "$destination"] }',
     '{ action = "say_goodbye", args = ["$robot"] }', "takes 3 argument(s)"),
    ('[actions.ask_to_wait]\nskill = "say"\nkind = "blocking"\ntext = "Sorry {h}, I have an urgent task. '
     'Please wait here, I will come back."\n', "", "no entry for domain action(s) ['ask_to_wait']"),
    ('travel = ["?from", "?to"]', 'travel = ["?from", "?nowhere"]', "?nowhere is not a parameter"),
    ('[[suspension]]\nlabel = "save"\ngoal = []', '[[suspension]]\nlabel = "save"\nwhen = [["greeted", "$person"]]\n'
     'goal = []', "the last branch must have no 'when'"),
    ('when = [["greeted", "$person"]]\ngoal = [["told_to_wait", "$person"]]',
     'when = [["greeted", "$person"]]\ngoal = [["told_to_wait", "?who"]]', "suspension[1]: ?who is not bound"),
    ('name = "guide_human"', 'name = "guide human"', "'name' must be an identifier"),
    # the strict reader: unknown keys and tables are errors with the line and a did-you-mean
    ('[actions.say_goodbye]\nskill = "say"\n', '[actions.say_goodbye]\nskill = "say"\nkindd = "blocking"\n',
     "actions.say_goodbye.kindd: unknown key 'kindd'; did you mean 'kind'?"),
    ('[schedule]', '[shedule]', "shedule: unknown key 'shedule'; did you mean 'schedule'?"),
    # static and planned pursue the same goal: the branch's stages must reach it
    ('stages = [{ action = "ask_to_wait", args = ["$robot", "$person", "$at:robot"] }]', 'stages = []',
     "suspension[0]: static and planned must pursue the same goal"),
    ('label = "save"\ngoal = []', 'label = "save"\npolicy = "conditional"\ngoal = []',
     "suspension[3].policy: a branch"),
    ('[static]', '[[static.suspension]]\nstages = []\n\n[static]', "[[static.suspension]] is gone"),
    ('budget_s = 0', 'budget = 0', "hazards[0].budget_s: missing (required)"),
    ('fact = ["following", "$person"]\nbudget_s', 'fact = ["folowing", "$person"]\nbudget_s',
     "hazards[0].fact: unknown predicate 'folowing'; did you mean 'following'?"),
    ('fact = ["following", "$person"]\nbudget_s', 'fact = ["following", "$person", "$robot"]\nbudget_s',
     "hazards[0].fact: 'following' takes 1 argument(s), got 2"),
    ('fact = ["following", "$person"]\nbudget_s', 'fact = ["following", "$persn"]\nbudget_s',
     "hazards[0].fact: unknown request argument '$persn'; did you mean '$person'?"),
    ('person = "person"     #', 'person = "who"     #', "people.person: no request argument 'who'"),
    ('told_to_wait = [["told_to_wait", "$person"]]', 'told_to_wait = [["told", "$person"]]',
     "people.told_to_wait: unknown predicate 'told'"),
    ('kind = "waiting"', 'kind = "sleeping"', "bindings[1].kind: expected one of"),
    ('fact = ["told_to_wait", "?h"]', 'fact = ["told_to_wait", "$person"]', "bindings[1].fact: a binding is a fact"),
    ('[task]', '[task', "not valid TOML"),
]


@pytest.mark.slow
@pytest.mark.parametrize(("old", "new", "fragment"), TOML_CASES)
def test_bad_task_toml(old: str, new: str, fragment: str, tmp_path: Path) -> None:
    folder = _copy(tmp_path)
    _edit(folder / "task.toml", old, new)
    with pytest.raises(DefinitionError) as info:
        load_task(folder)
    assert info.value.file.endswith("task.toml") and fragment in str(info.value)


def test_strict_reader_names_the_line(tmp_path: Path) -> None:
    folder = _copy(tmp_path)
    _edit(folder / "task.toml", '[actions.say_goodbye]\nskill = "say"\n',
          '[actions.say_goodbye]\nskill = "say"\nkindd = "blocking"\n')
    line = folder.joinpath("task.toml").read_text().splitlines().index('kindd = "blocking"') + 1
    with pytest.raises(DefinitionError) as info:
        load_task(folder)
    assert info.value.line == line and f"task.toml:{line}: " in str(info.value)
    assert "valid keys: duration, kind, skill, text, to, travel" in str(info.value)


def test_a_bad_task_toml_is_one_line_and_exit_2_from_the_cli(tmp_path: Path,
                                                             capsys: pytest.CaptureFixture[str]) -> None:
    from experiments.cli import main

    folder = _copy(tmp_path)
    _edit(folder / "task.toml", '[schedule]', '[shedule]')
    assert main(["domains", "--path", str(folder)]) == 2
    err = capsys.readouterr().err
    assert "did you mean 'schedule'?" in err and "Traceback" not in err


def test_bad_domain_in_folder_names_domain(tmp_path: Path) -> None:
    folder = _copy(tmp_path)
    _edit(folder / "domain.pddl", "(apology_due ?h - person))", "(apology_due ?h - person)")
    with pytest.raises(DefinitionError) as info:
        load_task(folder)
    assert info.value.file.endswith("domain.pddl") and info.value.line is not None


@pytest.mark.slow
def test_axioms_fall_back_to_an_optimal_search_that_handles_them(tmp_path: Path) -> None:
    folder = _copy(tmp_path)
    _edit(folder / "domain.pddl", "(not (following ?h)))\n    :effect (and (not (at ?r ?from))",
          "(forall (?x - person) (not (following ?x))))\n    :effect (and (not (at ?r ?from))")
    _edit(folder / "domain.pddl", ":negative-preconditions", ":negative-preconditions :universal-preconditions")
    task = load_task(folder)  # LM-cut refuses axioms (exit 34); A* + blind search takes over
    from planners.examples import example_context

    plan = task.update_task(example_context(task))
    assert [s.action for s in plan.stages][:2] == ["approach", "greet"]


@pytest.mark.slow
def test_bad_task_py(tmp_path: Path) -> None:
    folder = _copy(tmp_path, "carry_object")
    (folder / "task.py").write_text("def extra_facts(ctx, world)\n    return []\n")
    with pytest.raises(DefinitionError, match="syntax error") as info:
        load_task(folder)
    assert info.value.file.endswith("task.py") and info.value.line == 1
    (folder / "task.py").write_text("def extra_fact(ctx, world):\n    return []\n")
    with pytest.raises(DefinitionError, match="unknown hook"):
        load_task(folder)


def test_folder_of_folders_and_store_loader(tmp_path: Path) -> None:
    _copy(tmp_path, "cook")
    _copy(tmp_path, "human_fell")
    assert [t.name for t in load_task_folder(tmp_path)] == ["cook", "human_fell"]
    assert [t.name for t in store_loader(tmp_path)] == ["cook", "human_fell"]
    empty = tmp_path / "empty"
    empty.mkdir()
    assert store_loader(empty) == []
    with pytest.raises(DefinitionError, match="no task folder"):
        load_task_folder(empty)


@pytest.mark.slow
def test_task_types_with_user_folder(tmp_path: Path) -> None:
    folder = _copy(tmp_path, "cook")
    _edit(folder / "task.toml", 'name = "cook"', 'name = "cook_pasta"')
    names = [t.name for t in task_types([folder])]
    assert names[-1] == "cook_pasta" and "cook" in names
