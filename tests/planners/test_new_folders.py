"""Task folders as a new user writes them (from ``tasker new``'s template): each mistake is
refused at load naming the file, the line and what was expected, and each valid PDDL
feature the docs promise works; never a traceback, never a silently wrong problem."""

from __future__ import annotations

from pathlib import Path

import pytest

from planners.checks import DefinitionError
from planners.loader import load_task
from planners.scaffold import scaffold
from tasker.stage import Purpose
from tasker.support.reader import InputWarning


def _new(tmp_path: Path, name: str = "fetch") -> Path:
    folder = tmp_path / name
    scaffold(name, folder)
    return folder


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text, old
    path.write_text(text.replace(old, new, 1))


def _line_of(path: Path, fragment: str) -> int:
    return next(n for n, s in enumerate(path.read_text().splitlines(), 1) if fragment in s)


@pytest.mark.slow
def test_an_unsolvable_example_is_a_warning_naming_what_was_left_out(tmp_path: Path) -> None:
    """Before: `tasker check` said "the [example] solved".  A warning, not a refusal: the
    folder's requests may still be solvable in a run's world, and one that is not ends alone
    ("upTsk unsolvable") with the run going on."""
    folder = _new(tmp_path)
    toml = folder / "task.toml"
    _edit(toml, '["at", "vase", "kitchen"]', '["at", "vaze", "kitchen"]')  # a typo: the vase is nowhere
    with pytest.warns(InputWarning) as caught:
        load_task(folder, use_cache=False)
    text = next(str(w.message) for w in caught if issubclass(w.category, InputWarning))
    assert text.startswith(f"{toml}:{_line_of(toml, '[example]')}: example: no plan reaches the goal")
    assert "['at', 'vaze', 'kitchen']" in text


@pytest.mark.slow
def test_connected_without_travel_time_still_connects_the_places(tmp_path: Path) -> None:
    """A domain without action costs keeps ``connected``: the docs add it "when the domain declares" it."""
    from planners.examples import example_context

    folder = _new(tmp_path)
    domain = folder / "domain.pddl"
    _edit(domain, " :action-costs", "")
    _edit(domain, "  (:functions\n    (travel-time ?from ?to - place) - number\n    (total-cost) - number)\n", "")
    _edit(domain, "\n                 (increase (total-cost) (travel-time ?from ?to))", "")
    for _ in range(2):
        _edit(domain, "\n                 (increase (total-cost) 5)", "")
    task = load_task(folder, use_cache=False)  # before: the example was unsolvable (no place connected)
    plan = task.update_task(example_context(task))
    assert [s.action for s in plan.stages] == ["navigate", "pick", "navigate", "put_down"]


@pytest.mark.slow
def test_a_domain_constant_that_is_also_a_world_object(tmp_path: Path) -> None:
    """``(:constants kitchen - place)``: the world's kitchen is that constant, declared once,
    and facts over it are kept (before: UP's "Name kitchen already defined!")."""
    from planners.examples import example_context

    folder = _new(tmp_path)
    _edit(folder / "domain.pddl", "  (:predicates", "  (:constants kitchen - place)\n  (:predicates")
    task = load_task(folder, use_cache=False)
    ctx = example_context(task)
    text = task.planning_problem(ctx, Purpose.UP_TSK)
    objects = text.problem.split("(:objects")[1].split(")")[0]
    assert "kitchen" not in objects and "(at vase kitchen)" in text.problem
    assert [s.action for s in task.update_task(ctx).stages] == ["navigate", "pick", "navigate", "put_down"]


@pytest.mark.slow
@pytest.mark.parametrize(("old", "new"), [
    ('goal = [["at", "$item", "$destination"]', 'goal = [["at", "$item", "$destination", "$robot"]'),
    ('when = [["holding", "$robot", "$item"]]', 'when = [["holds", "$robot", "$item"]]'),
])
def test_a_bad_literal_names_its_line(tmp_path: Path, old: str, new: str) -> None:
    folder = _new(tmp_path)
    toml = folder / "task.toml"
    _edit(toml, old, new)
    with pytest.raises(DefinitionError) as info:
        load_task(folder, use_cache=False)
    assert info.value.file == str(toml) and info.value.line == _line_of(toml, new[:30])
    assert f"task.toml:{info.value.line}: " in str(info.value)


@pytest.mark.slow
@pytest.mark.parametrize(("old", "new", "at"), [
    ('goal = [["at", "$item", "$destination"]', 'goal = [["at", "$item", "$destinaton"]', "goal = "),
    ('args = ["$robot", "$item", "$at:item"] }', 'args = ["$robot", "$itm", "$at:item"] }', "update = ["),
])
def test_an_unknown_request_argument_is_refused_at_load(tmp_path: Path, old: str, new: str, at: str) -> None:
    """Before: the goal's failed with "$destinaton: no request argument" naming no file; the
    static template's was accepted and failed only when the static strategy ran."""
    folder = _new(tmp_path)
    toml = folder / "task.toml"
    _edit(toml, old, new)
    with pytest.raises(DefinitionError) as info:
        load_task(folder, use_cache=False)
    assert info.value.file == str(toml) and info.value.line == _line_of(toml, at)
    assert "unknown request argument" in str(info.value) and "did you mean" in str(info.value)


@pytest.mark.parametrize(("old", "new", "fragment"), [
    ('default = "living"', "default = 3", "expected a non-empty string, got 3"),
    ('default = "living"', 'default = "living"\nchoices = ["kitchen"]', "expected one of ['kitchen'], got 'living'"),
])
def test_an_argument_default_that_does_not_fit_is_refused(tmp_path: Path, old: str, new: str, fragment: str) -> None:
    """Before: accepted, then a request without the argument failed in the planner ("Undefined object 3")."""
    folder = _new(tmp_path)
    toml = folder / "task.toml"
    _edit(toml, old, new)
    with pytest.raises(DefinitionError) as info:
        load_task(folder, use_cache=False)
    assert info.value.line == _line_of(toml, new.split("\n")[0])
    assert "args[1].default: " in str(info.value) and fragment in str(info.value)


@pytest.mark.slow
@pytest.mark.parametrize(("hook", "fragment", "line"), [
    ("def extra_facts(ctx, world):\n    raise RuntimeError('boom')\n", "RuntimeError: boom", 2),
    ("def extra_facts(ctx, world):\n    return None\n", "TypeError: 'NoneType' object is not iterable", None),
    ("def check_terminate(ctx, world):\n    return {}['x']\n", "KeyError: 'x'", 2),
    ("def check_args(args):\n    raise ValueError('no vases')\n", "ValueError: no vases", 2),
    ("\ndef extra_facts(world):\n    return []\n", "extra_facts(world): a hook extra_facts takes (ctx, world)", 2),
])
def test_a_failing_task_py_hook_is_named_before_any_run(tmp_path: Path, hook: str, fragment: str,
                                                        line: int | None) -> None:
    """Before: `tasker check` passed (the hooks never ran on the [example]) or ended in
    "internal error".  A hook that fails on the [example] is a warning naming task.py and the
    line: its tasks will end alone with cause error and the run goes on.  A wrong signature
    is an error."""
    folder = _new(tmp_path)
    (folder / "task.py").write_text(hook)
    if "takes (ctx, world)" in fragment:
        with pytest.raises(DefinitionError) as info:
            load_task(folder, use_cache=False)
        assert info.value.file == str(folder / "task.py") and fragment in str(info.value)
        assert info.value.line == line
        return
    with pytest.warns(InputWarning) as caught:
        load_task(folder, use_cache=False)
    text = next(str(w.message) for w in caught if issubclass(w.category, InputWarning))
    where = f"{folder / 'task.py'}:{line}" if line else f"{folder / 'task.py'}: "
    assert text.startswith(where) and fragment in text and "will end with cause error" in text


@pytest.mark.slow
def test_check_args_raising_anything_but_bad_request_names_task_py(tmp_path: Path) -> None:
    from tasker.errors import BadRequest

    folder = _new(tmp_path)
    (folder / "task.py").write_text("def check_args(args):\n    if args['item'] == 'cup':\n"
                                    "        raise ValueError('no cups')\n")
    task = load_task(folder, use_cache=False)
    with pytest.raises(DefinitionError, match="task.py:3: check_args raised ValueError: no cups"):
        task.validate_args({"item": "cup"})
    (folder / "task.py").write_text("from tasker.errors import BadRequest\n\ndef check_args(args):\n"
                                    "    raise BadRequest('no cups')\n")
    with pytest.raises(DefinitionError, match=r"task.toml:\d+: example: args: no cups"):
        load_task(folder, use_cache=False)
    assert issubclass(BadRequest, ValueError)


@pytest.mark.slow
def test_extra_facts_that_are_not_tuples_of_strings_are_refused(tmp_path: Path) -> None:
    """Before: ``"hand_empty robot"`` became a tuple of letters, silently left out of the problem."""
    folder = _new(tmp_path)
    (folder / "task.py").write_text("def extra_facts(ctx, world):\n    return ['hand_empty robot']\n")
    with pytest.warns(InputWarning, match="extra_facts gave 'hand_empty robot'; expected facts as tuples of strings"):
        task = load_task(folder, use_cache=False)
    from planners.examples import example_context

    with pytest.raises(DefinitionError) as info:  # at run time: the task ends with this reason
        task.update_task(example_context(task))
    assert info.value.file == str(folder / "task.py")


@pytest.mark.slow
def test_a_task_toml_with_a_byte_order_mark_is_checked_like_any(tmp_path: Path,
                                                               capsys: pytest.CaptureFixture[str]) -> None:
    from experiments.cli import main

    folder = _new(tmp_path)
    toml = folder / "task.toml"
    toml.write_bytes(b"\xef\xbb\xbf" + toml.read_bytes())
    assert main(["check", str(folder)]) == 0, capsys.readouterr()


@pytest.mark.slow
def test_an_example_object_of_an_undeclared_type_is_named(tmp_path: Path) -> None:
    """Before: "task.toml [example] problem:27:19: unknown object or invalid expression: vase",
    a line of the generated problem, not of task.toml."""
    folder = _new(tmp_path)
    toml = folder / "task.toml"
    _edit(toml, 'vase = "item"', 'vase = "itme"')
    with pytest.raises(DefinitionError) as info:
        load_task(folder, use_cache=False)
    assert info.value.file == str(toml) and info.value.line == _line_of(toml, "[example]")
    assert "objects.vase: 'itme' is not a type of domain.pddl; did you mean 'item'?" in str(info.value)


@pytest.mark.slow
@pytest.mark.parametrize(("old", "new", "fragment"), [
    ("(increase (total-cost) (travel-time ?from ?to))",
     "(increase (total-cost) (travel-time ?from ?to)) (decrease (battery ?r) 1)",
     "an effect on the numeric fluent battery"),
    ("(and (at ?r ?from) (connected ?from ?to))", "(and (at ?r ?from) (connected ?from ?to) (> (battery ?r) 0))",
     "a condition on the numeric fluent battery"),
])
def test_a_numeric_fluent_other_than_the_cost_is_refused_clearly(tmp_path: Path, old: str, new: str,
                                                                 fragment: str) -> None:
    """Before: "Fast Downward's parser refuses the domain: ... Undefined predicate Got: decrease"."""
    domain, err = _refused_domain(tmp_path, ("(total-cost) - number)",
                                             "(total-cost) - number\n    (battery ?r - robot) - number)"), old, new)
    assert err.file == str(domain)
    assert (f"action navigate: {fragment}: unsupported PDDL features (numeric fluents are supported only as "
            "action costs") in str(err)
    assert err.line == _line_of(domain, new[-25:])


def _refused_domain(tmp_path: Path, prepare: tuple[str, str], old: str, new: str) -> tuple[Path, DefinitionError]:
    """The template's domain edited by ``prepare`` then ``old -> new``, and the error its loading raises."""
    folder = _new(tmp_path)
    domain = folder / "domain.pddl"
    _edit(domain, *prepare)
    _edit(domain, old, new)
    with pytest.raises(DefinitionError) as info:
        load_task(folder, use_cache=False)
    return domain, info.value


@pytest.mark.parametrize(("old", "new", "at", "fragment"), [
    ("(holding ?r - robot ?i - item)", "(holding ?r - robot ?i - (either item robot))", "(either",
     "(either ...) types: unified-planning's PDDL reader cannot read them, so a task folder cannot use them"),
    ("  (:action navigate", "  (:derived (busy ?r - robot) (not (hand_empty ?r)))\n  (:action navigate", "(:derived",
     ":derived predicates: unified-planning's PDDL reader cannot read them, so a task folder cannot use them"),
    (":action-costs)", ":action-costs :derived-predicates)", ":derived-predicates",
     ":derived predicates: unified-planning's PDDL reader cannot read them, so a task folder cannot use them"),
])
def test_either_types_and_derived_predicates_are_refused_plainly(tmp_path: Path, old: str, new: str, at: str,
                                                                 fragment: str) -> None:
    """Before: unified-planning's "syntax error: Expected ')'" at a misleading place."""
    busy = ("(hand_empty ?r - robot))", "(hand_empty ?r - robot)\n    (busy ?r - robot))")
    domain, err = _refused_domain(tmp_path, busy, old, new)
    line = _line_of(domain, at)
    assert err.file == str(domain) and err.line == line
    assert err.col == domain.read_text().splitlines()[line - 1].index(at) + 1
    assert fragment in str(err) and "Expected" not in str(err)


@pytest.mark.slow
def test_pddl_names_in_task_toml_ignore_case_as_in_pddl(tmp_path: Path) -> None:
    """Before: ``[actions.Put_Down]`` gave "no entry for domain action(s) ['put_down']" and
    ``["HAND_EMPTY", ...]`` "unknown predicate": the domain's names are read in lower case."""
    folder = _new(tmp_path)
    for path in (folder / "domain.pddl", folder / "task.toml"):
        path.write_text(path.read_text().replace("put_down", "Put_Down").replace("hand_empty", "HAND_EMPTY"))
    toml = folder / "task.toml"
    _edit(toml, 'fact = ["holding", "$robot", "$item"]', 'fact = ["Holding", "$robot", "$item"]')
    _edit(toml, 'to = "?to"', 'to = "?To"')
    _edit(toml, 'when = [["holding", "$robot", "$item"]]', 'when = [["NOT", "HOLDING", "$robot", "$item"]]')
    task = load_task(folder, use_cache=False)
    assert "put_down" in task.spec.actions and task.spec.actions["navigate"].to == "?to"
    assert task.spec.goal[1] == ("hand_empty", "$robot") and task.spec.hazards[0].fact[0] == "holding"
    assert task.spec.suspension[0].when == (("not", "holding", "$robot", "$item"),)
    assert [t.action for t in task.spec.static_update][-1] == "put_down"
    # object names too (a world's are lower case); a request's $argument keeps its case
    _edit(toml, 'goal = [["HAND_EMPTY", "$robot"]]', 'goal = [["HAND_EMPTY", "$robot"], ["at", "$item", "Kitchen"]]')
    _edit(toml, 'args = ["$robot", "$item", "$at:robot"]', 'args = ["$robot", "$item", "$at:Robot"]')
    from planners.taskspec import read_task_toml

    spec = read_task_toml(toml)
    assert spec.suspension[0].goal == (("hand_empty", "$robot"), ("at", "$item", "kitchen"))
    assert spec.suspension[0].stages[0].args == ("$robot", "$item", "$at:robot")
    _edit(toml, "[actions.pick]", "[actions.PUT_DOWN]\nskill = \"manipulate\"\n\n[actions.pick]")
    with pytest.raises(DefinitionError, match="a second entry for action 'put_down'"):
        load_task(folder, use_cache=False)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["domain.pddl", "task.py"])
def test_a_file_that_is_not_utf8_is_named_with_the_line_of_the_byte(tmp_path: Path, name: str) -> None:
    """Before: Python's "'utf-8' codec can't decode byte 0xe9 in position 183" (domain.pddl: no
    line; task.py: a syntax error whose column is a byte offset)."""
    folder = _new(tmp_path)
    path = folder / name
    if name == "task.py":
        path.write_text("def extra_facts(ctx, world):\n    return []\n")
    lines = path.read_bytes().split(b"\n")
    lines[1] += b" ; caf\xe9"  # Latin-1, as an editor on Windows may write it
    path.write_bytes(b"\n".join(lines))
    with pytest.raises(DefinitionError) as info:
        load_task(folder, use_cache=False)
    assert str(info.value) == f"{path}:2: is not UTF-8 text (byte 0xe9)"


def test_tasker_plan_names_the_line_of_a_non_utf8_byte(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from experiments.cli import main

    folder = _new(tmp_path)
    problem = folder / "problem.pddl"
    problem.write_bytes(problem.read_bytes().replace(b"\n", b" ; caf\xe9\n", 1))
    assert main(["plan", str(folder / "domain.pddl"), str(problem)]) == 2
    assert f"argument PROBLEM: {problem}:1: is not UTF-8 text (byte 0xe9)" in capsys.readouterr().err


@pytest.mark.slow
@pytest.mark.parametrize(("text", "fragment"), [
    ("Here is {itme}", "unknown placeholder {itme}; did you mean '{item}'? (placeholders name a parameter of "
                       "put_down (r, i, p) or a request argument (item, destination)"),
    ("{nowhere}", "unknown placeholder {nowhere}"),
    ("a { brace", "expected '}' before end of string"),
    ("{i:d}", "{i:d}: Unknown format code 'd'"),
])
def test_a_say_text_placeholder_is_checked_at_load(tmp_path: Path, text: str, fragment: str) -> None:
    """Before: an unknown placeholder was said as written ("{nowhere}"), a malformed one failed at run time."""
    folder = _new(tmp_path)
    toml = folder / "task.toml"
    _edit(toml, '# text = "..."', f'text = "{text}"')
    with pytest.raises(DefinitionError) as info:
        load_task(folder, use_cache=False)
    assert info.value.line == _line_of(toml, f'text = "{text}"')
    assert "actions.put_down.text: " in str(info.value) and fragment in str(info.value)
    _edit(toml, f'text = "{text}"', 'text = "{{Put}} {i!r} at {destination:>8}"')
    load_task(folder, use_cache=False)


@pytest.mark.slow
def test_a_folder_reached_twice_is_one_task_type_and_a_real_clash_names_both(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Before: $TASKER_TASKS and --path naming the same folder (or a folder and its parent) gave
    "task type name(s) defined twice: ['fetch']", and a real clash named neither file."""
    from domains import BUNDLED
    from planners.bundled import ENV_VAR, task_types
    from tasker.errors import ConfigError

    folder = _new(tmp_path)
    monkeypatch.setenv(ENV_VAR, str(folder))
    assert [t.name for t in task_types([tmp_path, f"{folder}/"])].count("fetch") == 1
    other = _new(tmp_path / "more", "guide_humans")  # tasker new refuses a bundled name: made by hand
    toml = other / "task.toml"
    toml.write_text(toml.read_text().replace('name = "guide_humans"', 'name = "guide_human"'))
    with pytest.raises(ConfigError) as info:
        task_types([other])
    bundled = (BUNDLED / "guide_human" / "task.toml").resolve()
    assert f"'guide_human' by {bundled} and {(other / 'task.toml').resolve()}" in str(info.value)


@pytest.mark.slow
def test_a_suspension_branch_without_when_before_the_last_is_refused(tmp_path: Path) -> None:
    """Before: accepted, and the branches after it were silently never chosen (the held item was never put down)."""
    folder = _new(tmp_path)
    toml = folder / "task.toml"
    _edit(toml, '[[suspension]]\nlabel = "item held: put it down"',
          '[[suspension]]\nlabel = "first"\ngoal = []\n\n[[suspension]]\nlabel = "item held: put it down"')
    with pytest.raises(DefinitionError) as info:
        load_task(folder, use_cache=False)
    assert info.value.line == _line_of(toml, "[[suspension]]")
    assert "suspension[0]: no 'when': it always holds, so the branches after it ('item held: put it down', " \
           "'nothing to make safe') are never chosen" in str(info.value)
    _edit(toml, 'label = "first"', 'label = "first"\npolicy = "conditional"\nmax_interruption_s = 5')
    load_task(folder, use_cache=False)  # a conditional branch is not always eligible: the others are reachable


@pytest.mark.slow
def test_a_suspension_when_that_contradicts_itself_is_refused(tmp_path: Path) -> None:
    """Before: accepted, and the branch was silently never chosen (no state has a fact and its negation)."""
    folder = _new(tmp_path)
    toml = folder / "task.toml"
    _edit(toml, 'when = [["holding", "$robot", "$item"]]',
          'when = [["holding", "$robot", "$item"], ["not", "holding", "$robot", "$item"]]')
    with pytest.raises(DefinitionError) as info:
        load_task(folder, use_cache=False)
    assert info.value.line == _line_of(toml, "[[suspension]]")
    assert "suspension[0]: `when` asks for ['holding', '$robot', '$item'] and for its negation" in str(info.value)


@pytest.mark.slow
def test_an_upper_case_scenario_object_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Before: [objects.Cup] ran, but the plan moved "cup": the robot never held Cup and its hazard never fired."""
    from experiments.cli import main

    folder = _new(tmp_path)
    scenario = folder / "scenario.toml"
    _edit(scenario, 'item = "vase"', 'item = "Cup"')
    scenario.write_text(scenario.read_text() + '\n[objects.Cup]\ntype = "item"\nplace = "kitchen"\n')
    assert main(["check", str(scenario), "--path", str(folder)]) == 1
    assert f"{scenario}:{_line_of(scenario, '[objects.Cup]')}: objects.Cup: PDDL names ignore case and plans give " \
           "them in lower case: write 'cup'" in capsys.readouterr().out


@pytest.mark.slow
def test_a_binding_of_the_wrong_kind_for_the_world_is_a_warning(tmp_path: Path) -> None:
    """Before: kind = "device" for the held item ran silently: the robot "held" the vase only symbolically."""
    from experiments.inputs import scenario as scenarios
    from tasker.support.reader import InputWarning

    folder = _new(tmp_path)
    for name in ("task.toml", "domain.pddl"):  # a predicate of its own: 'holding' is bound as held by bundled
        (folder / name).write_text((folder / name).read_text().replace("holding", "carrying"))  # folders too
    _edit(folder / "task.toml", 'kind = "held"', 'kind = "device"')
    with pytest.warns(InputWarning) as caught:
        scn = scenarios.load(folder / "scenario.toml", task_paths=[str(folder)])
    message = "task type 'fetch': its device binding of ['carrying', '?r', '?i'] covers vase here, and none is " \
              "a device thing of world 'flat', so the fact stays symbolic (kind = 'held'?)"
    assert any(message in str(w.message) for w in caught) and any(message in w for w in scn.warnings)
    _edit(folder / "task.toml", 'kind = "device"', 'kind = "held"')
    assert scenarios.load(folder / "scenario.toml", task_paths=[str(folder)]).warnings == ()


def test_check_says_when_the_example_was_not_solved(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """`tasker check` no longer claims "the [example] solved" when a hook failed on it: it
    passes (a task whose hook fails ends alone at run time) and points at the warning."""
    from experiments.cli import main

    folder = _new(tmp_path)
    (folder / "task.py").write_text("def check_terminate(ctx, world):\n    raise ValueError('boom')\n")
    assert main(["check", str(folder)]) == 0
    out = capsys.readouterr()
    assert "task folder: PDDL and task.toml (its [example]: see the warning)" in out.out
    assert "[example] solved" not in out.out
    assert f"{folder / 'task.py'}:2: a hook fails on the [example]: ValueError: boom" in out.err


@pytest.mark.slow
def test_an_example_the_planner_does_not_finish_in_time_is_a_warning(tmp_path: Path) -> None:
    """Before: a timeout on the [example] passed silently and `tasker check` said "solved"."""
    folder = _new(tmp_path)
    toml = folder / "task.toml"
    _edit(toml, "timeout_s = 10.0", "timeout_s = 0.000001")
    load_task(folder, use_cache=False).planner.clear_cache()  # the scaffold solved it: forget that plan
    with pytest.warns(InputWarning) as caught:
        load_task(folder, use_cache=False)
    text = next(str(w.message) for w in caught if issubclass(w.category, InputWarning))
    assert text.startswith(f"{toml}:{_line_of(toml, 'timeout_s =')}: task.timeout_s: the planner did not finish "
                           "the [example] within timeout_s = 1e-06 s")
    assert "falls back to the [static] template" in text
