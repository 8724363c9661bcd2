"""The translator's reuse path gives byte for byte the library's own output, and reads a domain once.

The reference is ``fast_downward.translate``'s ``main()`` on files, as its command line
runs it; the reuse path (:mod:`planners.translate`) must agree on every problem the bundled
task types plan on their example worlds and on unified-planning's classical test problems.
These tests are also the guard of the one monkeypatch: they fail if the library changes
under it.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from typing import Any

import pytest

import planners.translate as translate_module
from planners.bundled import task_types
from planners.examples import StraightLineMotion, example_context
from planners.pddl_task import PddlTaskType
from planners.planner import PddlText
from planners.translate import INPUT_ERROR, OK, Translation, domain_sexp, translate
from tasker.stage import Purpose
from tests.planners.conftest import DOMAIN, UP_PDDL, problem_text


def _bundled_problems() -> Iterator[tuple[str, PddlText]]:
    """upTsk and genSusp of every bundled task type on its example world: from the start and
    after every prefix of the plan it executes (what bench_planner.py measures)."""
    for task in task_types():
        assert isinstance(task, PddlTaskType)
        ctx = example_context(task, motion=StraightLineMotion())
        assert ctx is not None and ctx.world is not None
        world = ctx.world
        for k, stage in enumerate(task.update_task(ctx).stages):
            here = example_context(task, motion=StraightLineMotion(), world=world)
            assert here is not None
            for purpose in Purpose:
                yield f"{task.name} {purpose.value}@{k}", task.planning_problem(here, purpose)
            world = world.updated([tuple(f) for f in stage.data["add"]], [tuple(f) for f in stage.data["delete"]])


def _classical() -> list[Any]:
    """unified-planning's classical test problems (typed, untyped, constants, costs, ADL)."""
    return [pytest.param(domain.read_text(), problem.read_text(), id=f"{domain.parent.name}/{problem.name}")
            for domain in sorted(UP_PDDL.glob("*/domain.pddl"))
            for problem in sorted(domain.parent.glob("problem*.pddl"))]


@pytest.fixture(autouse=True)
def _fresh_caches() -> None:
    domain_sexp.cache_clear()
    translate_module._parsed_domain.cache_clear()


@pytest.mark.slow
def test_reuse_is_byte_identical_on_every_bundled_domain() -> None:
    seen: dict[str, set[str]] = {}
    for label, text in _bundled_problems():
        reference = translate(text.domain, text.problem, reuse=False)
        reused = translate(text.domain, text.problem)
        assert reference.code == OK, label
        assert reused == reference, label
        seen.setdefault(label.split()[0], set()).add(text.problem)
    assert len(seen) == len(task_types()) and all(len(p) >= 3 for p in seen.values()), "many problems per domain"


@pytest.mark.slow
@pytest.mark.parametrize(("domain", "problem"), _classical())
def test_reuse_is_byte_identical_on_classical_problems(domain: str, problem: str) -> None:
    reference = translate(domain, problem, reuse=False)
    first, again = translate(domain, problem), translate(domain, problem)
    assert first.code == reference.code == again.code
    if reference.code == OK:
        assert first.sas == reference.sas == again.sas


def test_a_domain_is_parsed_once_per_process(monkeypatch: pytest.MonkeyPatch) -> None:
    from fast_downward.translate.pddl_parser import parsing_functions

    calls = []
    real = parsing_functions.parse_domain_pddl

    def counted(*args: Any) -> Any:
        calls.append(1)
        return real(*args)

    monkeypatch.setattr(parsing_functions, "parse_domain_pddl", counted)
    outs = [translate(DOMAIN, problem_text(extra_init=f"; {k}\n")) for k in range(4)]
    assert all(o.code == OK for o in outs) and len(calls) == 1
    assert parsing_functions.parse_domain_pddl is counted, "restored after every call"


def test_the_library_still_reads_the_domain_the_way_the_patch_assumes() -> None:
    from fast_downward.translate.pddl_parser import parsing_functions

    # parse_task looks parse_domain_pddl up as a module global: what _parse_task replaces
    assert "parse_domain_pddl" in parsing_functions.parse_task.__code__.co_names
    original = parsing_functions.parse_domain_pddl
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a fallback (the library called it other than once) fails here
        assert translate(DOMAIN, problem_text()).code == OK
    assert translate(DOMAIN, problem_text(goal="(nonsense cup)")).code == INPUT_ERROR
    assert parsing_functions.parse_domain_pddl is original, "restored, after success and after an error"


def test_a_library_that_reads_the_domain_otherwise_falls_back_exactly(monkeypatch: pytest.MonkeyPatch) -> None:
    from fast_downward.translate.pddl_parser import parsing_functions

    real_parse_task = parsing_functions.parse_task

    def twice(domain_pddl: Any, problem_pddl: Any) -> Any:  # a changed library: reads the domain twice
        list(parsing_functions.parse_domain_pddl(parsing_functions.Context(), domain_pddl))
        return real_parse_task(domain_pddl, problem_pddl)

    reference = translate(DOMAIN, problem_text(), reuse=False)
    monkeypatch.setattr(parsing_functions, "parse_task", twice)
    with pytest.warns(RuntimeWarning, match="parses the domain on every call"):
        assert translate(DOMAIN, problem_text()) == reference


def test_bad_input_is_an_input_error_on_both_paths() -> None:
    for reuse in (True, False):
        out = translate(DOMAIN, problem_text(goal="(nonsense cup)"), reuse=reuse)
        assert out.code == INPUT_ERROR and out.message.startswith("translator") and not out.sas
        out = translate("(define (domain broken", problem_text(), reuse=reuse)
        assert out.code == INPUT_ERROR and out.message.startswith("translator")


def test_translation_checks_fire() -> None:
    with pytest.raises(ValueError, match="must carry SAS"):
        Translation(OK)
    with pytest.raises(ValueError, match="must not carry SAS"):
        Translation(INPUT_ERROR, "bad", "begin_version")
