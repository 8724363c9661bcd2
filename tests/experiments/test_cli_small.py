"""Small things a new user hit on the command line, each as it was found.

Before: ``tasker cost --help``'s example named a place no world has; ``tasker report --help``
printed ``95 %%``; ``tasker plan`` labelled every stage of a domain no task folder declares
"suspendable, 0 s", and a plan whose action the folder does not know was ``internal error:
KeyError: 'item'``; ``tasker check FOLDER SCENARIO`` refused the scenario that ``tasker check
SCENARIO --path FOLDER`` passed; huge numbers in options were internal errors; ``--after`` was
ignored without ``--purpose genSusp``; a label with a newline broke the diagram's note.
"""

from __future__ import annotations

import argparse
import re
import shutil
from pathlib import Path

import pytest

from experiments.cli import build_parser, main
from robot.spec import load_world


def _subparsers() -> dict[str, argparse.ArgumentParser]:
    return dict(build_parser()._subparsers._group_actions[0].choices)  # type: ignore[union-attr]


@pytest.mark.parametrize("command", sorted(_subparsers()))
def test_no_help_shows_a_doubled_percent(command: str) -> None:
    assert "%%" not in _subparsers()[command].format_help()


def test_every_cost_and_world_example_names_places_its_world_has() -> None:
    for command in ("cost", "world"):
        for line in (_subparsers()[command].epilog or "").splitlines():
            words = line.split("#")[0].split()
            if words[:2] != ["tasker", command] or words[2].endswith(".toml"):  # a user's world file: not shipped
                continue
            world, names, skip = words[2], [], False
            for w in words[3:]:
                if skip or w.startswith("-"):  # an option, or an option's value
                    skip = w in ("--seed", "--out")
                    continue
                if not re.match(r"^-?[\d.]+,", w):  # x,y[,yaw] is a point, not a place
                    names.append(w)
            places = load_world(world).places
            assert all(n in places for n in names), (line, sorted(places))


@pytest.mark.slow
def test_plan_without_a_task_folder_shows_no_made_up_stages(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from planners.scaffold import scaffold

    folder = tmp_path / "fetch"
    scaffold("fetch", folder)
    alone = tmp_path / "alone"
    alone.mkdir()
    shutil.copy(folder / "domain.pddl", alone / "domain.pddl")
    capsys.readouterr()
    assert main(["plan", str(alone / "domain.pddl"), str(folder / "problem.pddl")]) == 0
    out = capsys.readouterr().out
    assert "stages: none shown: domain 'fetch' is no task folder's" in out and "suspendable, skill=-, 0 s" not in out
    # a domain of the same name with an action the folder does not know: was KeyError: 'item', exit 3
    text = (folder / "domain.pddl").read_text().replace("(:action pick", "(:action item")
    (alone / "domain.pddl").write_text(text.replace("(pick ", "(item "))
    assert main(["plan", str(alone / "domain.pddl"), str(folder / "problem.pddl"), "--path", str(folder)]) == 0
    captured = capsys.readouterr()
    assert "stages: none shown: the plan's action(s) item are not those of" in captured.out
    assert "internal error" not in captured.err
    assert main(["plan", str(folder / "domain.pddl"), str(folder / "problem.pddl")]) == 0
    assert "[blocking, skill=manipulate, 5 s]" in capsys.readouterr().out  # its own folder: its stages


@pytest.mark.slow
def test_check_folder_and_scenario_is_check_scenario_with_path(tmp_path: Path,
                                                               capsys: pytest.CaptureFixture[str]) -> None:
    from planners.scaffold import scaffold

    folder = tmp_path / "fetch"
    scaffold("fetch", folder)
    scenario = tmp_path / "elsewhere" / "scenario.toml"
    scenario.parent.mkdir()
    (folder / "scenario.toml").rename(scenario)
    capsys.readouterr()
    assert main(["check", str(scenario), "--path", str(folder)]) == 0
    assert main(["check", str(scenario), str(folder)]) == 0  # the scenario after the folder it requests: alike
    assert main(["check", str(folder), str(scenario)]) == 0
    toml = folder / "task.toml"
    toml.write_text(toml.read_text().replace('skill = "manipulate"', 'skill = "teleport"', 1))
    capsys.readouterr()
    assert main(["check", str(folder), str(scenario)]) == 1  # a broken folder is named once, not per scenario
    out = capsys.readouterr().out
    assert out.count("teleport") == 1 and "task type 'fetch'" in out


@pytest.mark.parametrize(("argv", "fragment"), [
    (["plan", "{d}", "{p}", "--timeout", "1e300"], "argument --timeout: expected at most 86400 s"),
    (["sweep", "{spec}", "--db", "{tmp}/r.db", "--workers", "1" + "0" * 30], "at most 1024 worker processes"),
    (["day", "--workers", "1" + "0" * 30, "--out", "{tmp}/d"], "at most 1024 worker processes"),
    (["day", "--days", "1" + "0" * 400, "--out", "{tmp}/d"], "argument --days"),
    (["run", "synthetic_demo", "--seed", "1" + "0" * 400], "got an integer of 401 digits"),
    (["fsm", "cook", "--after", "2"], "argument --after: applies to --purpose genSusp"),
    (["explain", "{tmp}", "--agent", "d1", "--at", "1e400"], "argument --at"),
])
def test_huge_or_misplaced_options_are_bad_input(argv: list[str], fragment: str, tmp_path: Path,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    from tests.experiments import standin

    d, p = tmp_path / "d.pddl", tmp_path / "p.pddl"
    d.write_text("(define (domain d) (:requirements :strips) (:predicates (q)) (:action a :parameters () "
                 ":precondition () :effect (q)))")
    p.write_text("(define (problem x) (:domain d) (:init) (:goal (q)))")
    spec = tmp_path / "s.toml"
    spec.write_text(f'scenarios = ["{standin.DEMO}"]\nseeds = 1\nstrategies = ["default"]\n')
    values = {"d": str(d), "p": str(p), "tmp": str(tmp_path), "spec": str(spec)}
    assert main([a.format(**values) for a in argv]) == 2
    err = capsys.readouterr().err
    last = err.strip().splitlines()[-1]
    assert fragment in last and "internal error" not in err and len(last) < 300, err


@pytest.mark.slow
def test_an_fsm_ends_with_one_newline_and_its_note_is_one_line(tmp_path: Path,
                                                               capsys: pytest.CaptureFixture[str]) -> None:
    from planners.scaffold import scaffold

    folder = tmp_path / "fetch"
    scaffold("fetch", folder)
    toml = folder / "task.toml"
    toml.write_text(toml.read_text().replace('label = "item held: put it down"', 'label = "item held:\\nput it down"'))
    for fmt, comment in (("mermaid", "%% note: "), ("dot", "// note: ")):
        capsys.readouterr()
        assert main(["fsm", "fetch", "--path", str(folder), "--purpose", "genSusp", "--strategy", "static",
                     "--after", "2", "--format", fmt]) == 0
        out = capsys.readouterr().out
        assert out.endswith("\n") and not out.endswith("\n\n")
        assert f"{comment}decision tree: item held: put it down\n" in out
    for purpose in ("upTsk", "genSusp"):
        assert main(["fsm", "cook", "--purpose", purpose]) == 0
        out = capsys.readouterr().out
        assert out.endswith("\n") and not out.endswith("\n\n")


def test_a_system_exit_inside_a_command_is_named(monkeypatch: pytest.MonkeyPatch,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    import experiments.cli.plan

    def exits(args: argparse.Namespace) -> int:
        raise SystemExit(4)

    monkeypatch.setattr(experiments.cli.plan, "domains_command", exits)
    parser = build_parser()
    args = parser.parse_args(["domains"])
    from experiments.cli.args import run_handler

    assert run_handler(exits, args) == 3
    assert "internal error: sys.exit(4) was called while the command ran" in capsys.readouterr().err
