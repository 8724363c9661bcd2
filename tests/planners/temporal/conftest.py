"""Fixtures for the temporal tests: the shipped temporal set (``benchmarks/data/temporal``)."""

from __future__ import annotations

from pathlib import Path

import pytest

SHIPPED = Path(__file__).resolve().parents[3] / "benchmarks" / "data" / "temporal"


def pair(name: str) -> tuple[Path, Path]:
    """``(domain.pddl, problem.pddl)`` of a shipped temporal problem."""
    return SHIPPED / name / "domain.pddl", SHIPPED / name / "problem.pddl"


@pytest.fixture
def simple() -> tuple[Path, Path]:
    """PlanSys2's simple example (its empty ``(:functions )`` block included)."""
    return pair("plansys2_simple")
