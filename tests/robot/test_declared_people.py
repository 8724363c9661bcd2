"""Who follows the robot or waits is declared by the task folder, never named by the world.

A user's ``escort`` folder is guide_human with every predicate and action renamed and the
same ``[[bindings]]`` (``follower``, ``waiting``): the simulation must move people for it
exactly as for guide_human.  Before, :mod:`robot.sim` looked for the predicates
``following`` and ``told_to_wait`` of the bundled domain when deciding whether people
could be fast-forwarded, so such a folder's follower was treated as standing still
(and their trail dropped) whenever the robot paused.
"""

from __future__ import annotations

import math
import re
import shutil
from pathlib import Path

import pytest

import domains
from robot.recording import read_trajectory
from robot.sim import Simulation
from tasker.meaning import Binding

RENAMES = [(r"\bguide_human\b", "escort"), (r"\bfollowing\b(?!\s*=)", "tagging_along"),
           (r"\btold_to_wait\b(?!\s*=)", "staying_put"), (r"\bask_to_follow\b", "invite_along"),
           (r"\bguide_through\b", "lead_through"), (r"\bguide\b", "lead"), (r"\bgreeted\b", "welcomed")]


def escort_folder(tmp_path: Path) -> Path:
    """guide_human copied and renamed (predicates and actions; the roles' keys are vocabulary)."""
    dst = tmp_path / "escort"
    shutil.copytree(domains.BUNDLED / "guide_human", dst, ignore=shutil.ignore_patterns("__pycache__"))
    for name in ("domain.pddl", "task.toml"):
        text = (dst / name).read_text()
        for old, new in RENAMES:
            text = re.sub(old, new, text)
        (dst / name).write_text(text)
    text = (dst / "task.toml").read_text()
    assert '"following"' not in text and "(following" not in (dst / "domain.pddl").read_text()
    assert 'fact = ["tagging_along", "?h"]' in text and 'fact = ["staying_put", "?h"]' in text
    return dst


SCENARIO = """kind = "robot"
name = "escort_check"
world = "paper"
seed = 1
[settings]
scheduler = "alg2"
mode = "IT"
update = "planned"
suspension = "planned"
horizon = 120.0
[[requests]]
t = 0.0
task = "{task}"
args = {{ person = "john", destination = "kitchen" }}
"""


def _run(tmp_path: Path, task: str, paths: tuple[str, ...]) -> Path:
    from experiments.run.runner import run_scenario

    scn = tmp_path / f"{task}.toml"
    scn.write_text(SCENARIO.format(task=task))
    out = tmp_path / f"out-{task}"
    run_scenario(scn, out=out, pictures=False, task_paths=paths)
    return out / "trajectory.jsonl"


@pytest.mark.slow
def test_an_escort_folder_with_its_own_predicates_moves_people_as_guide_human(tmp_path: Path) -> None:
    folder = escort_folder(tmp_path)
    _, escort, _ = read_trajectory(_run(tmp_path, "escort", (str(folder),)))
    _, guide, _ = read_trajectory(_run(tmp_path, "guide_human", ()))
    # when the task ends (say_goodbye done, ~59 s; the run goes on to the world file's falls at 60 and 90 s)
    ended = [s for s in escort if s.t <= 59.0][-1]
    john = next(p for p in ended.people if p.name == "john")
    # John walked with the robot into the kitchen (y > 4.5), where his script never takes him
    assert john.y > 4.5 and math.dist(ended.robot[:2], (john.x, john.y)) < 1.5
    assert [(s.t, s.robot, s.people) for s in escort] == [(s.t, s.robot, s.people) for s in guide]


def test_fast_forward_keeps_a_follower_of_any_predicate_following(paper: object) -> None:
    """A person bound as follower under another name keeps their trail while the robot
    stands still: the simulation skips nothing it would have stepped."""
    runs = []
    for skip in (True, False):
        sim = Simulation("paper", seed=1)
        if not skip:
            sim._fast_forward = lambda now: False  # type: ignore[method-assign]
        sim.bind([Binding("follower", ("tagging_along", "?h"), "?h", ("person",))])
        sim.apply(add=[["tagging_along", "alice"]])
        assert sim.people["alice"].following and ("tagging_along", "alice") in sim.snapshot().facts
        sim.advance(30.0)
        runs.append([(s.t, s.people) for s in sim.recording.samples])
    assert runs[0] == runs[1]
