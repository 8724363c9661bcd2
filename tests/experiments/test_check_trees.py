"""``tasker check`` prints each task folder's tree report (``tree`` lines) and warns where a branch is not
complete or a ``when`` names a fact the world never has (:mod:`planners.treecheck`); the exit status
stays 0, as for any warning.  The worlds and scenarios checked in the same call count as worlds the
task may run in."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

from experiments.cli import main
from tests.planners.test_treecheck import COUNTER  # the counter tree the fixture's example breaks

ROOT = Path(__file__).resolve().parents[2]
HOT_POT = ROOT / "tests" / "planners" / "fixtures" / "hot_pot"
BRING_WATER = ROOT / "tests" / "domains" / "fixtures" / "bring_water"


def _counter_tree(tmp_path: Path) -> Path:
    folder = tmp_path / "hot_pot"
    shutil.copytree(HOT_POT, folder)
    toml = folder / "task.toml"
    text, n = re.subn(r"# BEGIN tree\n.*# END tree\n", lambda _: COUNTER, toml.read_text(), flags=re.S)
    assert n == 1
    toml.write_text(text)
    return folder


def test_a_branch_left_incomplete_is_printed_and_warned_not_failed(tmp_path: Path,
                                                                  capsys: pytest.CaptureFixture[str]) -> None:
    folder = _counter_tree(tmp_path)
    assert main(["check", str(folder)]) == 0
    out, err = capsys.readouterr()
    tree = [line for line in out.splitlines() if line.startswith(f"tree   {folder}: ")]
    assert any("suspension[0] 'pot held: put it on the counter': NOT complete at 2 of 2 point(s)" in t for t in tree)
    assert any("leaves on pot_held (holding robot pot)" in t for t in tree)
    assert any("suspension[1] 'save': complete at 2 point(s)" in t for t in tree)
    warned = [line for line in err.splitlines() if "is not complete on the [example]" in line]
    assert len(warned) == 1 and "task.toml:" in warned[0] and "suspension[0]" in warned[0]
    assert "pot_held" in warned[0] and "'pot held: put it on the counter'" in warned[0]
    assert main(["check", str(folder), "--quiet"]) == 0
    assert "tree   " not in capsys.readouterr().out


def test_a_complete_tree_gives_no_tree_warning(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", str(HOT_POT)]) == 0
    out, err = capsys.readouterr()
    assert "'pot held: put it back on the stove': complete at 2 point(s)" in out
    assert "not complete" not in err and "never has" not in err


@pytest.mark.slow
def test_a_scenario_checked_alongside_states_facts_the_tree_may_read(capsys: pytest.CaptureFixture[str]) -> None:
    # bring_water's `when` reads (table ?t): no world file states it, its scenario's glass does
    assert main(["check", str(BRING_WATER / "task.toml")]) == 0
    err = capsys.readouterr().err
    assert "`when` ['table', '?t'] names a fact the world never has" in err
    assert main(["check", str(BRING_WATER)]) == 0  # the folder: its scenario.toml is checked too
    assert "never has" not in capsys.readouterr().err


def test_a_report_that_fails_is_a_problem_of_its_folder(monkeypatch: pytest.MonkeyPatch,
                                                        capsys: pytest.CaptureFixture[str]) -> None:
    from planners import treecheck
    from planners.checks import DefinitionError

    def broken(task: object, **_: object) -> object:
        raise DefinitionError(HOT_POT / "task.py", "extra_facts gave 'x'")

    monkeypatch.setattr(treecheck, "report", broken)
    assert main(["check", str(HOT_POT)]) == 1
    out = capsys.readouterr().out
    assert f"error  {HOT_POT}: its suspension tree cannot be read: " in out and "extra_facts gave 'x'" in out


def test_the_report_docs_domains_md_shows_is_what_check_prints(monkeypatch: pytest.MonkeyPatch,
                                                               capsys: pytest.CaptureFixture[str]) -> None:
    doc = (ROOT / "docs" / "domains.md").read_text()
    marker = "<!-- pasted from `tasker check experiments/sweep/specs/tasks/water_plants` on commit "
    block = doc[doc.index(marker):].split("```")[1].strip("\n").splitlines()
    monkeypatch.chdir(ROOT)
    assert main(["check", "experiments/sweep/specs/tasks/water_plants"]) == 0
    out, err = capsys.readouterr()
    assert [line for line in block if line.startswith(("tree", "ok", "1 checks"))] == out.splitlines()
    assert [line for line in block if line.startswith("tasker check: warning:")] == err.splitlines()


def test_a_fact_another_folder_checked_with_it_makes_is_seen(tmp_path: Path,
                                                            capsys: pytest.CaptureFixture[str]) -> None:
    from tests.planners.test_treecheck import urgent_pair

    reader, maker = urgent_pair(tmp_path)
    assert main(["check", str(reader)]) == 0
    assert "`when` ['urgent', '$pot'] names a fact the world never has" in capsys.readouterr().err
    assert main(["check", str(reader), str(maker)]) == 0
    assert "never has" not in capsys.readouterr().err
