"""``tasker check``'s tree report (:mod:`planners.treecheck`): per branch, at each ``exeTsk`` stage of the
``[example]``, does the chosen branch reach its goal and leave every declared hazard off; which ``when``
conditions name a fact the world never has.

The task folder is ``fixtures/hot_pot`` (a hot pot may only go down on a clear, heat-proof spot; the
counter is occupied in its ``[example]``), with its tree swapped for others an author could write.
Expected points, branches and hazards are read off the fixture by hand: its plan is navigate(hall,
stove), pick_pot, navigate(stove, table), put_pot(table), so the pot is held before stages 3 and 4."""

from __future__ import annotations

import re
import shutil
import warnings
from dataclasses import replace
from pathlib import Path

import pytest

from planners.loader import load_task
from planners.pddl_task import PddlTaskType
from planners.treecheck import (
    BranchRun,
    HazardOn,
    Maker,
    Point,
    TreeReport,
    UnseenCondition,
    report,
    unseen_conditions,
)
from tasker.world import WorldState

FIXTURE = Path(__file__).with_name("fixtures") / "hot_pot"
FORGETS_TAP = Path(__file__).resolve().parents[2] / "tests" / "domains" / "fixtures" / "water_plants_forgets_tap"
DOMAINS = Path(__file__).resolve().parents[2] / "domains"

COUNTER = """\
[[suspension]]
label = "pot held: put it on the counter"
when = [["holding", "$robot", "$pot"]]
goal = [["hand_empty", "$robot"]]
stages = [
  { action = "navigate", args = ["$robot", "$at:robot", "counter"] },
  { action = "put_pot", args = ["$robot", "$pot", "counter"] },
]
"""
"""A tree that assumes the counter is free: the [example]'s bread box breaks it."""

NEAREST_CLEAR = """\
[[suspension]]
label = "pot held: put it on the nearest clear heat-proof spot"
when = [["holding", "$robot", "$pot"], ["heat_proof", "?p"], ["clear", "?p"]]
goal = [["hand_empty", "$robot"]]
stages = [
  { action = "navigate", args = ["$robot", "$at:robot", "?p"] },
  { action = "put_pot", args = ["$robot", "$pot", "?p"] },
]
"""
"""A tree whose `when` asks for a fact only task.py computes: it never matches."""

HELD = ("holding", "robot", "pot")


def _folder(tmp_path: Path, tree: str | None = None, edit: dict[str, str] | None = None) -> Path:
    folder = tmp_path / "hot_pot"
    shutil.copytree(FIXTURE, folder)
    text = (folder / "task.toml").read_text()
    if tree is not None:
        text, n = re.subn(r"# BEGIN tree\n.*# END tree\n", lambda _: tree, text, flags=re.S)
        assert n == 1
    for old, new in (edit or {}).items():
        assert old in text, old
        text = text.replace(old, new)
    (folder / "task.toml").write_text(text)
    return folder


def _load(folder: Path) -> PddlTaskType:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_task(folder, use_cache=False)


def _warned(task: PddlTaskType, rep: TreeReport) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rep.warn(task)
    return [str(w.message) for w in caught]


def _held_points(rep: TreeReport) -> list[tuple[str, int]]:
    return sorted((r.point.exe, r.point.after) for r in rep.runs if r.branch == 0)


# -- completeness -------------------------------------------------------------------------------


def test_the_fixture_tree_is_complete_where_the_pot_is_held(tmp_path: Path) -> None:
    task = _load(_folder(tmp_path))
    rep = report(task)
    assert rep.complete and not rep.unseen and not _warned(task, rep)
    assert _held_points(rep) == [("planned", 2), ("planned", 3)]  # before navigate(stove table), put_pot(table)
    run = rep.runs_of(0)[0]
    assert run.stages == ("navigate(robot stove stove)", "put_pot(robot pot stove)")
    assert run.complete and not run.left_on and not run.missed and run.blocked is None
    assert [r.label for r in rep.runs_of(1)] == ["save", "save"]  # nothing held before the pick
    assert dict(rep.walked) == {"planned": 4, "template": 4}


def test_a_tree_broken_by_the_occupied_counter_names_branch_stage_and_hazard(tmp_path: Path) -> None:
    task = _load(_folder(tmp_path, COUNTER))
    rep = report(task)
    bad = rep.failing()
    assert [(r.point.after, r.branch) for r in bad] == [(2, 0), (3, 0)]
    for r in bad:
        assert r.label == "pot held: put it on the counter"
        assert r.blocked is not None and "put_pot(robot pot counter)" in r.blocked and "(clear counter)" in r.blocked
        assert r.missed == (("hand_empty", "robot"),)
        assert [(h.name, h.fact) for h in r.left_on] == [("pot_held", HELD)]
    said = _warned(task, rep)
    assert len(said) == 1
    assert "suspension[0]" in said[0] and "'pot held: put it on the counter'" in said[0]
    assert "pot_held (holding robot pot)" in said[0] and "1 more point" in said[0]
    text = "\n".join(rep.lines())
    assert "NOT complete at 2 of 2 point(s)" in text and "before stage 3 navigate(robot stove table)" in text


def test_the_same_tree_passes_where_the_counter_is_free(tmp_path: Path) -> None:
    task = _load(_folder(tmp_path, COUNTER, {'["at", "bread_box", "counter"],': ""}))
    rep = report(task)
    assert rep.complete, rep.lines()
    assert _held_points(rep) == [("planned", 2), ("planned", 3)]


def test_a_forgotten_hazard_is_named_on_water_plants_as_first_written() -> None:
    task = _load(FORGETS_TAP)
    rep = report(task)
    bad = rep.failing()
    # the tap runs while the can fills: before fill (stage 5) and before turn_off (stage 6)
    assert [(r.point.after, r.point.stage.split("(")[0], r.label) for r in bad] == [
        (4, "fill", "can held: put it down"), (5, "turn_off", "can held: put it down")]
    assert all([h.name for h in r.left_on] == ["tap_running"] and not r.missed and r.blocked is None for r in bad)
    assert "tap_running (tap_on tap)" in _warned(task, rep)[0]


def test_a_conditional_branch_may_leave_on_only_what_its_budget_covers(tmp_path: Path) -> None:
    keep = """\
[[suspension]]
label = "short interruption: keep the pot"
policy = "conditional"
max_interruption_s = 30
when = [["holding", "$robot", "$pot"]]
goal = []
stages = []

""" + COUNTER.replace('"counter"', '"$stove"').replace("on the counter", "back on the stove")
    for budget, tolerated in ((0, False), (45, True)):
        task = _load(_folder(tmp_path / str(budget), keep, {"budget_s = 0": f"budget_s = {budget}"}))
        conditional = report(task).runs_of(0)
        assert [(r.point.after, r.policy, r.interruption_s) for r in conditional] == [
            (2, "conditional", 30.0), (3, "conditional", 30.0)]
        for r in conditional:
            assert r.complete is tolerated
            assert [h.name for h in (r.tolerated if tolerated else r.left_on)] == ["pot_held"]
        assert all(r.complete for r in report(task).runs_of(1))  # the strict branch puts it back


@pytest.mark.slow
def test_the_bundled_cook_tree_leaves_the_cooker_on_only_within_its_budget() -> None:
    rep = report(_load(DOMAINS / "cook"))
    held = rep.runs_of(0)  # "short interruption, hot pan held: put it down, leave the cooker" (60 s)
    assert held and all(r.policy == "conditional" and r.interruption_s == 60.0 and r.complete for r in held)
    assert any([h.name for h in r.tolerated] == ["cooker_on"] for r in held)


def test_a_tree_that_cannot_be_read_is_reported(tmp_path: Path) -> None:
    # `$at:ghost` names an object with no place: at run time genSusp fails there.  Loading refuses
    # such a folder when its [example] meets it; a folder remembered by the check cache is not
    # checked again, so the report is given the tree as loading would have read it.
    task = _load(_folder(tmp_path))
    first = task.spec.suspension[0]
    ghost = replace(first, when=(*first.when, ("at", "$robot", "$at:ghost")))
    task.spec = replace(task.spec, suspension=(ghost, *task.spec.suspension[1:]))
    rep = report(task)
    unread = rep.runs_of(-1)
    assert [r.point.after for r in unread] == [2, 3]
    assert all("cannot be read" in (r.blocked or "") and "ghost" in (r.blocked or "") for r in unread)
    said = [w for w in _warned(task, rep) if "the tree cannot be read on the [example]" in w]
    assert len(said) == 1 and "no place known for 'ghost'" in said[0] and "1 more point" in said[0]


def test_a_hook_failing_in_a_suspension_state_blocks_the_branch(tmp_path: Path) -> None:
    # loading calls the hook on the [example] too; the report is given the failing hook afterwards
    task = _load(_folder(tmp_path, COUNTER))
    clear = task.hooks["extra_facts"]

    def extra_facts(ctx: object, world: WorldState) -> object:
        if world.holds("holding", "robot", "pot"):
            raise RuntimeError("no idea while held")
        return clear(ctx, world)

    task.hooks = {**task.hooks, "extra_facts": extra_facts}
    rep = report(task)
    assert any("stops before stage 3" in n and "no idea while held" in n for n in rep.notes)
    run = rep.runs_of(0)[0]
    assert run.point.after == 2 and "task.py fails" in (run.blocked or "") and not run.complete


def test_without_an_example_only_the_conditions_are_read(tmp_path: Path) -> None:
    folder = _folder(tmp_path, NEAREST_CLEAR)
    text = (folder / "task.toml").read_text()
    (folder / "task.toml").write_text(text[:text.index("# the counter is occupied")])
    rep = report(_load(folder))
    assert not rep.runs and any("no [example]" in n for n in rep.notes)
    # without an example nothing states heat_proof, and task.py is never called: what makes `clear` is unknown
    assert [(u.branch, u.literal, u.maker) for u in rep.unseen] == [
        (0, ("heat_proof", "?p"), Maker.NOTHING), (0, ("clear", "?p"), Maker.NOTHING)]


# -- conditions the tree never sees ---------------------------------------------------------------


def test_a_when_on_a_fact_only_task_py_makes_never_matches(tmp_path: Path) -> None:
    task = _load(_folder(tmp_path, NEAREST_CLEAR))
    rep = report(task)
    assert [(u.branch, u.literal, u.maker) for u in rep.unseen] == [(0, ("clear", "?p"), Maker.TASK_PY)]
    assert rep.runs_of(0) == ()  # never chosen: "save" is, with the pot in hand
    assert [(r.point.after, r.label, [h.name for h in r.left_on]) for r in rep.failing()] == [
        (2, "save", ["pot_held"]), (3, "save", ["pot_held"])]
    said = _warned(task, rep)
    unseen = [w for w in said if "never has" in w]
    assert len(unseen) == 1 and "['clear', '?p']" in unseen[0] and "task.py" in unseen[0]
    assert "'pot held: put it on the nearest clear heat-proof spot'" in unseen[0] and "never matches" in unseen[0]
    assert any("branch 'save'" in w and "pot_held" in w for w in said)


def test_a_fact_some_world_states_is_seen(tmp_path: Path) -> None:
    task = _load(_folder(tmp_path, NEAREST_CLEAR))
    assert unseen_conditions(task, world_facts=[("clear", "table")]) == ()
    assert [u.maker for u in unseen_conditions(task)] == [Maker.NOTHING]  # no hook facts given


@pytest.mark.parametrize(("when", "facts", "maker", "negated"), [
    ('["urgent", "$pot"]', "", Maker.NOTHING, False),
    ('["urgent", "$pot"]', 'facts = [["urgent", "$pot"]]', Maker.REQUEST, False),
    ('["connected", "$at:robot", "$stove"]', "", Maker.PLANNER, False),
    ('["not", "clear", "$stove"]', "", Maker.TASK_PY, True),
    ('["not", "urgent", "$pot"]', "", Maker.NOTHING, True),
])
def test_what_makes_an_unseen_fact_is_named(tmp_path: Path, when: str, facts: str, maker: Maker,
                                            negated: bool) -> None:
    folder = _folder(tmp_path, COUNTER.replace('when = [["holding", "$robot", "$pot"]]',
                                               f'when = [["holding", "$robot", "$pot"], {when}]'),
                     {"[problem]\n": f"[problem]\n{facts}\n"})
    domain = folder / "domain.pddl"
    domain.write_text(domain.read_text().replace("(clear ?p - place))", "(clear ?p - place)\n    (urgent ?x - pot))"))
    task = _load(folder)
    rep = report(task)
    assert [(u.branch, u.maker, u.negated) for u in rep.unseen] == [(0, maker, negated)]
    message = rep.unseen[0].message()
    assert "pot held: put it on the counter" in message and maker.value in message
    assert ("always holds" in message) is negated and ("never matches" in message) is not negated


@pytest.mark.slow
def test_the_shipped_trees_see_every_fact_given_the_shipped_worlds() -> None:
    from robot.spec import load_world, shipped_worlds

    known = [f for name in shipped_worlds() for f in load_world(name).facts]
    for name in ("carry_object", "cook", "guide_human", "human_fell"):
        assert unseen_conditions(_load(DOMAINS / name), world_facts=known) == (), name
    # cook's example has no door: of its trees only the branch closing a door the robot opened reads what
    # the example does not state (door_at), once per tree; a tree that reads what no world states is
    # flagged (test_what_makes_an_unseen_fact_is_named)
    unseen = unseen_conditions(_load(DOMAINS / "cook"))
    assert [(u.label, u.literal) for u in unseen] == [("a door the robot opened: close it", ("door_at", "?d", "?p"))]


# -- the report's types ---------------------------------------------------------------------------


@pytest.mark.parametrize(("build", "fragment"), [
    (lambda: UnseenCondition(-1, "x", ("clear", "?p"), Maker.NOTHING), "index of [[suspension]]"),
    (lambda: UnseenCondition(0, "x", ("not",), Maker.NOTHING), "must be a literal"),
    (lambda: UnseenCondition(0, "x", (), Maker.NOTHING), "must be a literal"),
    (lambda: Point("dreamt", 0, "a()"), "Point.exe must be one of"),
    (lambda: Point("planned", -1, "a()"), "counts the stages done"),
    (lambda: BranchRun(Point("planned", 0, "a()"), 0, "x", "lenient"), "BranchRun.policy must be one of"),
    (lambda: BranchRun(Point("planned", 0, "a()"), 0, "x", "conditional"), "interruption_s"),
    (lambda: BranchRun(Point("planned", 0, "a()"), 0, "x", "strict", 30.0), "interruption_s"),
    (lambda: BranchRun(Point("planned", 0, "a()"), 0, "x", "strict", None, tolerated=(
        HazardOn("h", ("p",), 0.0),)), "only the conditional policy"),
])
def test_post_init_checks_fire(build: object, fragment: str) -> None:
    with pytest.raises(ValueError, match=re.escape(fragment)):
        build()  # type: ignore[operator]


def urgent_pair(tmp_path: Path) -> tuple[Path, Path]:
    """Two hot_pot folders: one whose tree reads ``(urgent pot)`` but never makes it, and one (``hot_pot_b``)
    with an action that does: the world the two share can hold it."""
    urgent = "(clear ?p - place))", "(clear ?p - place)\n    (urgent ?x - pot))"
    reader = _folder(tmp_path / "a", COUNTER.replace('when = [["holding", "$robot", "$pot"]]',
                                                     'when = [["holding", "$robot", "$pot"], ["urgent", "$pot"]]'))
    maker = _folder(tmp_path / "b", edit={'name = "hot_pot"': 'name = "hot_pot_b"',
                                          "[actions.put_pot]": '[actions.mark]\nskill = "say"\n\n[actions.put_pot]'})
    for folder in (reader, maker):
        domain = folder / "domain.pddl"
        domain.write_text(domain.read_text().replace(*urgent))
    domain = maker / "domain.pddl"
    domain.write_text(domain.read_text().rstrip().removesuffix(")") + """
  (:action mark
    :parameters (?x - pot)
    :effect (and (urgent ?x) (increase (total-cost) 1)))
)
""")
    return reader, maker


def test_a_fact_another_task_type_makes_is_seen(tmp_path: Path) -> None:
    reader, maker = urgent_pair(tmp_path)
    task = _load(reader)
    assert [(u.literal, u.maker) for u in unseen_conditions(task)] == [(("urgent", "$pot"), Maker.NOTHING)]
    assert unseen_conditions(task, others=[_load(maker)]) == ()


@pytest.mark.slow
def test_every_tree_of_a_folder_gets_its_report_named_where_it_is_written() -> None:
    from planners.treecheck import reports
    from robot.spec import load_world, shipped_worlds

    known = [f for name in shipped_worlds() for f in load_world(name).facts]  # the door branch reads door_at
    got = reports(_load(DOMAINS / "cook"), world_facts=known)
    assert [(r.tree, r.where) for r in got] == [("default", "suspension"), ("cooker", "trees.cooker")]
    assert all(r.complete for r in got), [r.lines() for r in got]
    assert any("trees.cooker[2] 'hot pan held, cooker on: back on the cooker, cooker off'" in line
               for line in got[1].lines()), got[1].lines()
