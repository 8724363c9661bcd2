"""The robot and its world: TIAGo (Pinocchio, MuJoCo), apartments, people, OMPL planning.

Entry points: :func:`load_world` (a world file), :class:`Simulation` (the TaskER
``World`` and ``CoreAgent``), :func:`motion_model` (a ``MotionModel`` for a world).
Heavy dependencies (OMPL, Pinocchio, MuJoCo) are imported when first used.
"""

from __future__ import annotations

from robot.spec import WorldFileError, WorldSpec, load_world, shipped_worlds

__all__ = ["WorldFileError", "WorldSpec", "load_world", "shipped_worlds", "Simulation", "motion_model"]


def __getattr__(name: str) -> object:
    if name == "Simulation":
        from robot.sim import Simulation

        return Simulation
    if name == "motion_model":
        from robot.estimator import motion_model

        return motion_model
    raise AttributeError(f"module 'robot' has no attribute {name!r}")
