"""The domain schema (Fast Downward's parser) says what unified-planning's model says, and
loading remembered task folders does not import unified-planning."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from domains import BUNDLED
from planners.checks import parse_domain
from planners.schema import SchemaError, read_schema
from tests.planners.conftest import DOMAIN, UP_PDDL

ROOT = Path(__file__).resolve().parents[2]
FIXTURES = ROOT / "tests" / "domains" / "fixtures"


def _reference(text: str) -> dict[str, object]:
    """The schema as the previous DomainModel read it from unified-planning's model."""
    m = parse_domain(text)

    def chain(t: object) -> frozenset[str]:
        out, cur = set(), t
        while cur is not None:
            out.add(cur.name)  # type: ignore[attr-defined]
            cur = cur.father  # type: ignore[attr-defined]
        return frozenset(out)

    def ref(e: object) -> str:
        return f"?{e.parameter().name}" if e.is_parameter_exp() else e.object().name  # type: ignore[attr-defined]

    actions = []
    for a in m.actions:
        effects, cost = [], None
        for e in a.effects:
            if e.is_increase() and e.fluent.fluent().name == "total-cost":
                cost = float(e.value.constant_value()) if e.value.is_constant() else None
            elif not (e.is_conditional() or e.is_forall() or e.is_increase() or e.is_decrease()) \
                    and e.value.is_bool_constant():
                effects.append((e.fluent.fluent().name, tuple(ref(x) for x in e.fluent.args),
                                e.value.bool_constant_value()))
        actions.append((a.name, tuple(p.name for p in a.parameters), tuple(effects), cost,
                        tuple(p.type.name if p.type.is_user_type() else "" for p in a.parameters)))
    return {
        "name": m.name,
        "types": {t.name: chain(t) for t in m.user_types},
        "predicates": [(f.name, tuple(p.type.name if p.type.is_user_type() else "" for p in f.signature))
                       for f in m.fluents if f.type.is_bool_type()],
        "functions": frozenset(f.name for f in m.fluents if not f.type.is_bool_type()),
        "actions": actions,
    }


def _schema(text: str) -> dict[str, object]:
    s = read_schema(text)
    return {
        "name": s.name,
        "types": dict(s.types),
        "predicates": list(s.predicates),
        "functions": s.functions,
        "actions": [(a.name, a.params, tuple((e.fluent, e.args, e.positive) for e in a.effects), a.constant_cost,
                     a.param_types) for a in s.actions],
    }


def _domains() -> list[Path]:
    shipped = sorted(BUNDLED.glob("*/domain.pddl")) + sorted(FIXTURES.glob("*/domain.pddl"))
    # UP's own classical test domains: typed, untyped, constants, costs, ADL (those both parsers read)
    classical = sorted(p for p in UP_PDDL.glob("*/domain.pddl") if "htn" not in p.parts[-2])
    return shipped + classical


@pytest.mark.slow
@pytest.mark.parametrize("path", _domains(), ids=lambda p: p.parent.name)
def test_schema_matches_unified_planning(path: Path) -> None:
    text = path.read_text()
    try:
        expected = _reference(text)
    except Exception:  # noqa: BLE001 - a domain unified-planning cannot read says nothing here
        pytest.skip("unified-planning does not read this domain")
    try:
        got = _schema(text)
    except SchemaError:
        if path.is_relative_to(BUNDLED) or path.is_relative_to(FIXTURES):
            raise
        pytest.skip("Fast Downward's parser does not read this domain (it would not plan it either)")
    assert got == expected


def test_schema_of_the_test_domain() -> None:
    s = read_schema(DOMAIN)
    actions = {a.name: a for a in s.actions}
    assert dict(s.types) == {"room": {"room"}, "item": {"item"}}
    assert actions["pick"].constant_cost == 1.0 and actions["move"].constant_cost is None
    assert actions["pick"].param_types == ("item", "room")
    assert [(e.fluent, e.positive) for e in actions["drop"].effects] == [("item-at", True), ("holding", False),
                                                                        ("free", True)]


def test_schema_error_names_the_fault() -> None:
    with pytest.raises(SchemaError, match="define"):
        read_schema("(domain x)")


_LOAD = """
import sys
from planners.bundled import task_types
task_types()
print(sorted({m.split('.')[0] for m in sys.modules} & {'unified_planning', 'pyparsing', 'ConfigSpace'}))
"""


@pytest.mark.slow
def test_remembered_task_folders_load_without_unified_planning(tmp_path: Path) -> None:
    """First load checks with unified-planning and records it; the next process reads the
    domains with Fast Downward's parser only (about a second less start-up)."""
    env = {"TASKER_CACHE": str(tmp_path), "PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"}
    runs = [subprocess.run([sys.executable, "-c", _LOAD], capture_output=True, text=True, env=env, cwd=ROOT,
                           check=True).stdout.strip().splitlines()[-1] for _ in range(2)]
    assert "'unified_planning'" in runs[0]  # the first load checks with unified-planning
    assert runs[1] == "[]"


def test_a_domain_fast_downward_refuses_is_a_definition_error(tmp_path: Path) -> None:
    """unified-planning reads fractional action costs; Fast Downward, which would plan with the
    domain, does not: loading says so, naming the file, instead of failing at the first plan."""
    from planners.checks import PddlError, load_domain
    from planners.problem import DomainModel

    path = tmp_path / "domain.pddl"
    path.write_text(DOMAIN.replace("(increase (total-cost) 1)))\n  (:action drop", "(increase (total-cost) 1.5)))\n"
                                   "  (:action drop"))
    with pytest.raises(PddlError, match=r"domain\.pddl: Fast Downward's parser refuses the domain: .*[Ff]ractional"):
        DomainModel(load_domain(path))
