"""render_problem remembers its answers per domain: a remembered answer is the one a fresh
rendering gives, whatever order the same inputs come in and whatever came between."""

from __future__ import annotations

import random
from pathlib import Path

from planners.checks import load_domain
from planners.problem import DomainModel, _render_problem, render_problem
from tasker.world import WorldState

DOMAIN = Path(__file__).resolve().parents[2] / "domains" / "carry_object" / "domain.pddl"


def _random_inputs(rng: random.Random, domain: DomainModel) -> tuple[WorldState, list[list[str]], list[tuple[str, ...]],
                                                                      dict[tuple[str, str], float] | None]:
    places = [f"p{i}" for i in range(rng.randint(1, 4))]
    objects = {**{p: "place" for p in places}, "robot": "robot", "cup": "item", "ghost": "no_such_type"}
    preds = sorted(domain.predicates)
    facts = set()
    for _ in range(rng.randint(0, 8)):
        name = rng.choice(preds)
        facts.add((name, *(rng.choice(list(objects)) for _ in domain.predicates[name])))
    items = list(objects.items())
    rng.shuffle(items)  # the same objects in another order: the same problem
    world = WorldState(frozenset(facts), {}, dict(items))
    goal = [list(f) for f in rng.sample(sorted(facts), min(len(facts), 2))]
    extra = [f for f in sorted(facts) if rng.random() < 0.2]
    travel = None if rng.random() < 0.3 else {(a, b): float(rng.randint(1, 9)) for a in places for b in places}
    return world, goal, extra, travel


def test_remembered_renderings_are_fresh_renderings() -> None:
    domain = DomainModel(load_domain(DOMAIN))
    rng = random.Random(11)
    asked = [_random_inputs(rng, domain) for _ in range(60)]
    for world, goal, extra, travel in [*asked, *reversed(asked), *rng.sample(asked, 30)]:
        try:
            fresh = _render_problem(domain, world, goal, extra, travel, "t")
        except Exception as exc:  # noqa: BLE001 -- an error must be the same error through the memo
            try:
                render_problem(domain, world, goal, extra_facts=extra, travel=travel, name="t")
            except type(exc) as again:
                assert str(again) == str(exc)
                continue
            raise AssertionError(f"the memo answered where a fresh rendering raised {exc!r}") from None
        assert render_problem(domain, world, goal, extra_facts=iter(extra), travel=travel, name="t") == fresh
    assert 0 < len(domain.rendered)
