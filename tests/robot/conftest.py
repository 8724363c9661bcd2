"""Shared fixtures for the robot tests: worlds, estimators and fresh simulations."""

from __future__ import annotations

import pytest

from robot.estimator import MotionEstimator, motion_model
from robot.spec import WorldSpec, load_world


@pytest.fixture(scope="session")
def paper() -> WorldSpec:
    return load_world("paper")


@pytest.fixture(scope="session")
def flat() -> WorldSpec:
    return load_world("flat")


@pytest.fixture(scope="session")
def paper_motion(paper: WorldSpec) -> MotionEstimator:
    """The paper apartment's estimator, walls and furniture only (people left out)."""
    return motion_model(paper, people=False)


@pytest.fixture(scope="session")
def flat_motion(flat: WorldSpec) -> MotionEstimator:
    return motion_model(flat)
