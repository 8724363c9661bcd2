"""The engine registry, Aries' settings, and LPG made to work as installed."""

from __future__ import annotations

import os
import sys
from fractions import Fraction

import pytest

from planners.temporal import engines, lpg
from tasker.errors import UnknownName
from tests.planners.temporal.conftest import pair


def test_unknown_engine_lists_the_known() -> None:
    with pytest.raises(UnknownName, match="aries, kairos, lpg, tamer"):
        engines.spec("popf")


def test_the_shipped_engines_are_installed() -> None:
    assert all(engines.installed(n) for n in engines.DEFAULT_ORDER)


def test_settings_are_set_while_solving_and_restored(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ARIES_STRATEGIES", "forward")
    monkeypatch.delenv("ARIES_PLANNING_PREPRO_STATE_VARS", raising=False)
    with engines.settings("aries"):
        assert os.environ["ARIES_STRATEGIES"] == "act-bool"
        assert os.environ["ARIES_PLANNING_PREPRO_STATE_VARS"] == "false"
    assert os.environ["ARIES_STRATEGIES"] == "forward" and "ARIES_PLANNING_PREPRO_STATE_VARS" not in os.environ


def test_up_lpg_imports_without_pkg_resources(monkeypatch: pytest.MonkeyPatch) -> None:
    for mod in [m for m in sys.modules if m.startswith("up_lpg")]:
        monkeypatch.delitem(sys.modules, mod)
    monkeypatch.setitem(sys.modules, "pkg_resources", None)  # what setuptools >= 81 leaves: no such module
    monkeypatch.setattr(lpg, "_CLASS", None)
    assert lpg.importable()
    assert sys.modules["pkg_resources"] is None  # the stand-in is gone again (the real state restored)
    assert lpg.engine_class().__name__ == "TaskerLPG"


def test_lpg_td_plan_lines_are_read() -> None:
    from planners.temporal.reading import parse

    d, p = pair("plansys2_simple")
    problem = parse(d.read_text(), p.read_text(), d, p)
    names = {x.name: x for x in [*problem.actions, *problem.all_objects]}
    text = ("; Version LPG-td-1.4\n; Seed 1\n\n0.0002:   (ASKCHARGE LEIA ENTRANCE CHARGINGROOM) [5.0000])\n"
            "5.0005:   (CHARGE LEIA CHARGINGROOM) [5.0000])\n")
    plan = lpg.read_plan(problem, text, names.__getitem__)
    starts = [(t, a.action.name, d) for t, a, d in plan.timed_actions]
    assert starts == [(Fraction("0.0002"), "askcharge", Fraction(5)), (Fraction("5.0005"), "charge", Fraction(5))]
    assert lpg.read_plan(problem, "; nothing\nno solution\n", names.__getitem__) is None
    from unified_planning.exceptions import UPException

    with pytest.raises(UPException, match="line 2: not a plan step"):
        lpg.read_plan(problem, "; c\n0.0: garbage\n", names.__getitem__)
