"""The ``tasker`` command line as a user meets it: bad arguments, help, exit statuses, start-up cost.

Every subcommand is driven with bad arguments: the exit status is not 0, stderr holds
no traceback, and the message names the argument at fault (or the bad value for a
positional one).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from experiments.cli import build_parser, main
from tasker.errors import TaskerError

ROOT = Path(__file__).resolve().parents[2]
SYNTHETIC = str(ROOT / "experiments" / "inputs" / "scenarios" / "synthetic_demo.toml")


@pytest.fixture
def files(tmp_path: Path) -> dict[str, str]:
    """Files the bad-argument cases point at."""
    a_file = tmp_path / "a_file"
    a_file.write_text("not a folder")
    spec = tmp_path / "spec.toml"
    spec.write_text(f'scenarios = ["{SYNTHETIC}"]\nseeds = 2\nstrategies = ["update=planned,suspension=static"]\n')
    bad_seeds = tmp_path / "bad_seeds.toml"
    bad_seeds.write_text(f'scenarios = ["{SYNTHETIC}"]\nseeds = [1, -1]\n'
                         'strategies = ["update=planned,suspension=static"]\n')
    bad_scn = tmp_path / "bad_seed_scenario.toml"
    bad_scn.write_text(Path(SYNTHETIC).read_text().replace("seed = 1", "seed = -1"))
    domain = ROOT / "domains" / "cook" / "domain.pddl"
    return {"tmp": str(tmp_path), "file": str(a_file), "under_file": str(a_file / "x"), "spec": str(spec),
            "bad_seeds": str(bad_seeds), "bad_scn": str(bad_scn), "domain": str(domain),
            "db": str(tmp_path / "r.db"), "missing": str(tmp_path / "missing")}


# (argv with {placeholders}, what the message must name)
BAD: list[tuple[list[str], str]] = [
    (["rnu"], "did you mean 'run'"),
    (["run", SYNTHETIC, "--seed", "-1"], "--seed"),
    (["run", SYNTHETIC, "--seed", str(2**32)], "--seed"),
    (["run", SYNTHETIC, "--seed", "x"], "--seed"),
    (["run", SYNTHETIC, "--out", "{under_file}"], "--out"),
    (["run", SYNTHETIC, "--scheduler", "alg3"], "--scheduler"),
    (["run", SYNTHETIC, "--suspension", "plannd"], "did you mean 'planned'"),
    (["run", SYNTHETIC, "--path", "{missing}"], "--path"),
    (["run", "no_such_scenario"], "no_such_scenario"),
    (["run", "{bad_scn}"], "seed"),
    (["sweep", "{spec}"], "--db"),
    (["sweep", "{spec}", "--db", "{db}", "--workers", "0"], "--workers"),
    (["sweep", "{spec}", "--db", "{under_file}"], "--db"),
    (["sweep", "{spec}", "--db", "{db}", "--scheduler-address", "tcp://127.0.0.1:9"], "--scheduler-address"),
    (["sweep", "{spec}", "--db", "{db}", "--scheduler-address", "not an address"], "--scheduler-address"),
    (["sweep", "{spec}", "--db", "{db}", "--path", "{missing}"], "--path"),
    (["sweep", "{bad_seeds}", "--db", "{db}"], "seeds[1]"),
    (["report", "--db", "{missing}", "--out", "{tmp}"], "--db"),
    (["check"], "PATH"),
    (["check", "{tmp}", "--path", "{missing}"], "--path"),
    (["plan", "{domain}", "{missing}"], "PROBLEM"),
    (["plan", "{missing}", "{domain}"], "DOMAIN"),
    (["plan", "{domain}", "{domain}", "--timeout", "0"], "--timeout"),
    (["plan", "{domain}", "{domain}", "--timeout", "-3"], "--timeout"),
    (["plan", "{domain}", "{domain}", "--timeout", "inf"], "--timeout"),
    (["plan", "{domain}", "{domain}", "--timeout", "nan"], "--timeout"),
    (["plan", "{domain}", "{domain}", "--planner", "fast-downwrd"], "did you mean 'fast-downward'"),
    (["domains", "--path", "{missing}"], "--path"),
    (["paper", "--variants", "-1"], "--variants"),
    (["paper", "--variants", "0", "--out", "{missing}"], "--out"),
    (["paper", "--scenario", "papr"], "did you mean 'paper'"),
    (["fsm", "guide_humn"], "did you mean 'guide_human'"),
    (["fsm", "cook", "--purpose", "genSusp", "--after", "-1"], "--after"),
    (["fsm", "cook", "--purpose", "genSusp", "--after", "99"], "--after"),
    (["fsm", "cook", "--purpose", "gensusp"], "did you mean 'genSusp'"),
    (["new", "Not-A-Name", "{tmp}/n"], "TASK"),
    (["new", "fine", "{tmp}"], "DIR"),
    (["world", "papr"], "did you mean 'paper'"),
    (["world", "paper.toml"], "named without a suffix: paper"),
    (["run", "paper.toml"], "named without a suffix: paper"),
    (["world", "flat", "--out", "{under_file}"], "--out"),
    (["cost", "flat", "living"], "PLACE"),
    (["cost", "flat", "living", "kitchn"], "did you mean 'kitchen'"),
    (["cost", "flat", "living", "kitchen", "--seed", "-1"], "--seed"),
    (["explain", "{missing}", "--agent", "d1"], "no such run folder"),
    (["explain", "{tmp}"], "--agent"),
    (["day", "--protocol", "tabsaa", "--out", "{tmp}/day"], "did you mean 'tabsa'"),
    (["day", "--schedulers", "alg3", "--out", "{tmp}/day"], "did you mean 'alg2'"),
    (["day", "--days", "0", "--out", "{tmp}/day"], "--days"),
    (["docs", "--root", "{missing}"], "no docs/ folder"),
    (["results", "--replay", "nowhere", "1", "derived", "--out", "{tmp}"], "no scenario 'nowhere'"),
    (["serve", "papr"], "did you mean 'paper'"),
    (["serve", "{file}"], "a_file"),
    (["serve", SYNTHETIC], "a synthetic scenario has no robot to serve"),
    (["serve", "paper", "--speed", "0"], "--speed"),
    (["serve", "paper", "--port", "70000"], "--port"),
    (["serve", "paper", "--token", ""], "--token"),
    (["serve", "paper", "--out", "{under_file}"], "--out"),
]


def _ids(case: tuple[list[str], str]) -> str:
    return " ".join(case[0])[:60]


@pytest.mark.parametrize("argv, names", BAD, ids=[_ids(c) for c in BAD])
def test_bad_arguments_exit_nonzero_with_a_message_naming_them(
        argv: list[str], names: str, files: dict[str, str], capsys: pytest.CaptureFixture[str],
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    here = tmp_path / "cwd"
    here.mkdir()
    monkeypatch.chdir(here)  # default output folders land here, not in the checkout
    status = main([a.format(**files) for a in argv])
    err = capsys.readouterr().err
    assert status == 2, err
    assert "Traceback" not in err
    assert names in err
    last = err.strip().splitlines()[-1]
    assert last.startswith(("tasker: error:", f"tasker {argv[0]}: error:")), last
    assert not list((here / "out").rglob("*")), "bad input left an output folder behind"


def test_every_subcommand_has_a_bad_argument_case() -> None:
    parser = build_parser()
    commands = set(parser._subparsers._group_actions[0].choices)  # type: ignore[union-attr]
    assert commands <= {argv[0] for argv, _ in BAD}


@pytest.mark.parametrize("command", sorted(build_parser()._subparsers._group_actions[0].choices))  # type: ignore
def test_every_help_has_a_description_examples_and_exit_statuses(command: str,
                                                                 capsys: pytest.CaptureFixture[str]) -> None:
    assert main([command, "--help"]) == 0
    out = capsys.readouterr().out
    assert out.startswith(f"usage: tasker {command}")
    assert "examples:\n  tasker " + command in out
    assert "exit status:" in out and "130" in out
    assert "--verbose" in out and "--quiet" in out
    paragraphs = out.split("\n\n")
    assert len(paragraphs[1].split()) >= 5, "a description of at least a sentence"


def test_top_level_help_lists_exit_statuses(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    assert "exit status:" in out and "130" in out and "new" in out and "check" in out


def _fake_result(causes: list[str]) -> Any:
    from tasker import events as ev

    typed: list[ev.Event] = [ev.TaskRequested(0.0, f"a{k}", "t", {}, "test") for k in range(len(causes))]
    typed += [ev.TaskEnded(1.0, f"a{k}", "t", c, c) for k, c in enumerate(causes)]
    return SimpleNamespace(trace=SimpleNamespace(typed=typed), record=SimpleNamespace(wall_time_s=0.1), metrics={})


@pytest.mark.parametrize("strict, causes, status", [
    (False, ["failed"], 0), (True, ["failed"], 1), (True, ["finished", "self", "term"], 0),
])
def test_run_strict(strict: bool, causes: list[str], status: int, tmp_path: Path,
                    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    import experiments.run.runner

    monkeypatch.setattr(experiments.run.runner, "run_scenario", lambda *a, **k: _fake_result(causes))
    argv = ["run", SYNTHETIC, "--out", str(tmp_path / "o"), *(["--strict"] if strict else [])]
    assert main(argv) == status
    err = capsys.readouterr().err
    assert ("1 task(s) failed" in err) == (status == 1)


def test_out_is_checked_before_the_run(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import experiments.run.runner

    def never(*_: object, **__: object) -> None:
        raise AssertionError("the run started although --out cannot be written")

    monkeypatch.setattr(experiments.run.runner, "run_scenario", never)
    (tmp_path / "f").write_text("")
    assert main(["run", SYNTHETIC, "--out", str(tmp_path / "f")]) == 2


class RunAborted(TaskerError):
    """Stands for ``tasker.errors.RunAborted``: the CLI recognises it by name."""


@pytest.mark.parametrize("exc, status, text", [
    (RunAborted("the world crashed"), 1, "error: the world crashed"),
    (KeyboardInterrupt(), 130, "interrupted"),
    (RuntimeError("oops"), 3, "internal error: RuntimeError: oops"),
    (PermissionError(13, "Permission denied", "/x"), 2, "error: /x: Permission denied"),
])
def test_exit_statuses(exc: BaseException, status: int, text: str, monkeypatch: pytest.MonkeyPatch,
                       tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    import experiments.run.runner

    def boom(*_: object, **__: object) -> None:
        raise exc

    monkeypatch.setattr(experiments.run.runner, "run_scenario", boom)
    assert main(["run", SYNTHETIC, "--out", str(tmp_path)]) == status
    err = capsys.readouterr().err
    assert err.startswith("tasker run: ") and text in err and "Traceback" not in err


def test_verbose_shows_the_traceback_of_an_internal_error(monkeypatch: pytest.MonkeyPatch, tmp_path: Path,
                                                          capsys: pytest.CaptureFixture[str]) -> None:
    import experiments.run.runner

    def boom(*_: object, **__: object) -> None:
        raise RuntimeError("oops")

    monkeypatch.setattr(experiments.run.runner, "run_scenario", boom)
    assert main(["run", SYNTHETIC, "--out", str(tmp_path), "--verbose"]) == 3
    assert "Traceback" in capsys.readouterr().err


@pytest.mark.slow
@pytest.mark.parametrize("scenario", [SYNTHETIC, "paper"])
def test_a_run_stopped_by_ctrl_c_keeps_what_ran(scenario: str, monkeypatch: pytest.MonkeyPatch, tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    """Before: Ctrl-C during a run wrote nothing, so a long run's first hours were lost."""
    import experiments.run.runner

    def stopped(loop: Any, progress: bool) -> None:
        loop.run(until=10.0)
        raise KeyboardInterrupt

    monkeypatch.setattr(experiments.run.runner, "_run", stopped)
    out = tmp_path / "o"
    assert main(["run", scenario, "--out", str(out), "--no-pictures"]) == 130
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert f"tasker run: interrupted by the user at t=10 s; the trace so far, run.json and metrics.json are in {out}/" \
        in err
    events = [json.loads(line) for line in (out / "trace.jsonl").read_text().splitlines()]
    assert events[0]["event"] == "run" and events[-1]["event"] == "run"
    assert events[-1]["status"] == "interrupted" and events[-1]["t"] == 10.0 and events[-1]["active"]
    record = json.loads((out / "run.json").read_text())
    assert record["status"] == "interrupted" and record["error"] == "interrupted by the user at t=10 s"
    assert "tasks" in json.loads((out / "metrics.json").read_text())  # computed from the trace so far


def test_quiet_run_prints_the_summary_only(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", SYNTHETIC, "--out", str(tmp_path), "--no-pictures", "--quiet"]) == 0
    out, err = capsys.readouterr()
    assert len(out.strip().splitlines()) == 1 and err == ""


@pytest.mark.slow
def test_check_lists_every_problem(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["new", "one", str(tmp_path / "tasks" / "one")]) == 0
    assert main(["new", "two", str(tmp_path / "tasks" / "two")]) == 0
    toml = tmp_path / "tasks" / "two" / "task.toml"
    toml.write_text(toml.read_text().replace('skill = "manipulate"', 'skill = "teleport"', 1))
    (tmp_path / "tasks" / "one" / "domain.pddl").write_text("(define (domain one) (:action")
    scn = tmp_path / "s.toml"
    scn.write_text('kind = "robot"\nworld = "flat"\n[[requests]]\nt = 0\ntask = "fetch"\nargs = {}\n')
    scn2 = tmp_path / "s2.toml"  # one problem a file: a scenario's reading stops at its first fault
    scn2.write_text('kind = "robot"\nworld = "flat"\n[[requests]]\nt = 0\ntask = "human_fell"\n'
                    'args = { person = "anna" }\n[people.bob]\npose = [1, 1, 0]\n')
    capsys.readouterr()
    assert main(["check", str(tmp_path / "tasks"), str(scn), str(scn2), str(ROOT / "robot" / "worlds"),
                 str(ROOT / "experiments" / "sweep" / "specs"), str(tmp_path / "nothing")]) == 1
    out = capsys.readouterr().out
    problems = [line for line in out.splitlines() if line.startswith("error")]
    assert any("one/domain.pddl" in p for p in problems)
    assert any("teleport" in p for p in problems)
    assert any("people.bob" in p for p in problems)
    assert any("task type 'fetch'" in p and "--path DIR" in p for p in problems)
    assert any("nothing: no such file" in p for p in problems)
    assert "ok     " + str(ROOT / "robot" / "worlds" / "flat.toml") in out
    assert f"{len(problems)} problems" in out


@pytest.mark.slow
def test_check_passes_the_shipped_files(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", str(ROOT / "domains"), str(ROOT / "experiments" / "inputs" / "scenarios"),
                 str(ROOT / "robot" / "worlds"), str(ROOT / "experiments" / "sweep" / "specs"),
                 str(ROOT / "experiments" / "days" / "protocols"), "-q"]) == 0
    assert "0 problems" in capsys.readouterr().out


def _modules_after(code: str, tmp_path: Path) -> set[str]:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "TASKER_CACHE": str(tmp_path / "cache")}
    out = subprocess.run([sys.executable, "-c", code + "\nimport sys, json; print(json.dumps(sorted(sys.modules)))"],
                         capture_output=True, text=True, env=env, check=True, cwd=tmp_path)
    return set(json.loads(out.stdout.strip().splitlines()[-1]))


@pytest.mark.slow
def test_help_and_a_warm_plan_stay_clear_of_heavy_imports(tmp_path: Path) -> None:
    mods = _modules_after("import experiments.cli as c; c.build_parser().format_help()", tmp_path)
    assert not {m for m in mods if m.split(".")[0] in ("unified_planning", "ConfigSpace", "scipy", "mujoco",
                                                        "ompl", "pinocchio", "matplotlib", "dask")}
    domain, problem = tmp_path / "d.pddl", tmp_path / "p.pddl"
    from tests.planners.conftest import DOMAIN, problem_text

    domain.write_text(DOMAIN)
    problem.write_text(problem_text())
    plan = f"from experiments.cli import main; main(['plan', {str(domain)!r}, {str(problem)!r}, '-q'])"
    _modules_after(plan, tmp_path)  # cold: checked with UP's reader, recorded in the cache
    mods = _modules_after(plan, tmp_path)
    assert "planners.fd" in mods and "fast_downward.translate.main" in mods
    assert not {m for m in mods if m.split(".")[0] in ("unified_planning", "ConfigSpace", "up_fast_downward")}


def test_sweep_jobs_carry_absolute_task_paths(tmp_path: Path, files: dict[str, str],
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    import experiments.sweep.driver

    assert main(["new", "mine", str(tmp_path / "tasks" / "mine")]) == 0
    seen: list[Any] = []

    def fake(spec: Any, db: str, **_: object) -> Any:
        seen.append(spec)
        return SimpleNamespace(total=0, skipped=0, ran=0, ok=0, errors=0, not_run=0, wall=0.0, backend="local")

    monkeypatch.setattr(experiments.sweep.driver, "run_sweep", fake)
    monkeypatch.chdir(tmp_path)
    assert main(["sweep", files["spec"], "--db", files["db"], "--path", "tasks"]) == 0
    jobs = seen[0].jobs()
    assert jobs and all(j.task_paths == (str((tmp_path / "tasks").resolve()),) for j in jobs)


@pytest.mark.slow
def test_doubtful_input_is_one_warning_line_in_the_cli_format(tmp_path: Path,
                                                              capsys: pytest.CaptureFixture[str]) -> None:
    scn = tmp_path / "late.toml"
    scn.write_text('kind = "synthetic"\nname = "late"\n[settings]\nhorizon = 20.0\n'
                   '[tasks.t]\nstages = [{ action = "a", duration = 1.0 }]\n'
                   '[[requests]]\nt = 0.0\ntask = "t"\n[[requests]]\nt = 100.0\ntask = "t"\n')
    assert main(["run", str(scn), "--out", str(tmp_path / "out")]) == 0
    err = capsys.readouterr().err
    assert f"tasker run: warning: {scn}:" in err and "after the horizon" in err
    assert "InputWarning" not in err
    assert main(["run", str(scn), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    assert "warning" not in capsys.readouterr().err


def test_run_takes_the_policy_and_hazard_waiting_factors(tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert main(["run", "synthetic_demo", "--out", str(out), "--hazard-waiting", "--no-pictures", "--quiet"]) == 0
    assert json.loads((out / "run.json").read_text())["settings"]["hazard_waiting"] is True
    assert main(["run", "synthetic_demo", "--policy", "lenient", "--out", str(out)]) == 2


@pytest.mark.slow
def test_a_task_ended_by_an_exception_counts_as_failed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                       capsys: pytest.CaptureFixture[str]) -> None:
    """Cause ``error`` is a failure (``tasker.trace.FAILED``): ``--strict`` exits 1 and the
    metrics count it with its reason; the default output folder is named by the scenario's
    ``name``, not its file's (every ``tasker new`` folder has a ``scenario.toml``)."""
    monkeypatch.chdir(tmp_path)
    assert main(["new", "fetch", "mine/fetch"]) == 0
    (tmp_path / "mine" / "fetch" / "task.py").write_text(
        "def check_terminate(ctx, world):\n    raise ValueError('boom')\n")
    capsys.readouterr()
    assert main(["run", "mine/fetch/scenario.toml", "--path", "mine", "--strict", "--no-pictures"]) == 1
    assert "d1: check_terminate() raised ValueError: boom" in capsys.readouterr().err
    totals = json.loads((tmp_path / "out" / "fetch_demo" / "metrics.json").read_text())["totals"]
    assert totals["failed"] == 1 and totals["by_cause"] == {"error": 1}
    assert totals["failure_reasons"][0].startswith("d1: check_terminate() raised ValueError: boom")


def test_day_stopped_by_ctrl_c_says_how_to_go_on(monkeypatch: pytest.MonkeyPatch, tmp_path: Path,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    """Before: a bare "interrupted", though the days that ended were kept and --resume goes on."""
    import experiments.cli.day

    def stopped(args: Any) -> int:
        (Path(args.out) / "days.db").write_bytes(b"")
        raise KeyboardInterrupt

    monkeypatch.setattr(experiments.cli.day, "_days", stopped)
    out = tmp_path / "day"
    out.mkdir()
    assert main(["day", "--protocol", "tabsa", "--days", "1", "--out", str(out)]) == 130
    err = capsys.readouterr().err
    assert f"the days that ended are in {out / 'days.db'}: run the same command again to go on" in err


@pytest.mark.slow
def test_strategy_options_on_a_synthetic_scenario_warn(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Before: ``--suspension planned`` on a synthetic scenario ran static without a word."""
    assert main(["run", SYNTHETIC, "--out", str(tmp_path / "a"), "--no-pictures", "--suspension", "planned"]) == 0
    assert "a synthetic scenario's timed stages ignore --suspension: the run is the static one" in \
        capsys.readouterr().err
    assert main(["run", SYNTHETIC, "--out", str(tmp_path / "b"), "--no-pictures", "--scheduler", "fifo"]) == 0
    assert "warning" not in capsys.readouterr().err
