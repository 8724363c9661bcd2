"""What a run reads and changes of the simulated world: the seam between ``experiments`` and ``robot``.

A robot scenario's run (:mod:`experiments.run.runner`), the targeted perturbations
(:mod:`experiments.run.targeting`) and a live session (:mod:`experiments.serve`) drive the world
through :class:`SimulatedWorld`, never through a concrete class: :class:`robot.sim.Simulation`
(MuJoCo, OMPL) is the one implementation here; a bridge to a real robot would be another.  It is
the loop's :class:`~tasker.protocols.World` and :class:`~tasker.protocols.CoreAgent` too (the
robot runs the skills).  ``robot`` is imported for the types only, so importing this costs nothing.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence, Set
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from tasker.protocols import CoreAgent, World
from tasker.world import MotionModel, Pose, WorldState

if TYPE_CHECKING:
    from robot.people import People
    from robot.recording import Recorder
    from robot.spec import WorldSpec
    from tasker.meaning import Binding

Sample = tuple[float, float, float, float]
"""A recorded robot pose: ``(t, x, y, yaw)``."""


class SimulatedWorld(World, CoreAgent, Protocol):
    """The simulated world a robot run steps: its file, motion model, people, doors and devices,
    what the robot holds, and the changes a scenario's actions make to it."""

    @property
    def spec(self) -> WorldSpec:
        """The world file as read (places, rooms, doors, devices, objects, people)."""

    @property
    def motion(self) -> MotionModel:
        """The robot's motion-cost model in this world (what the tasks' estimates read)."""

    @property
    def people(self) -> People:
        """The people, by name (each walks, falls, waits)."""

    @property
    def door_open(self) -> Mapping[str, bool]:
        """Each door: open or not, now."""

    @property
    def device_state(self) -> Mapping[str, str]:
        """Each device's state now (``on``/``off``)."""

    @property
    def held(self) -> Set[str]:
        """The objects the robot holds now."""

    @property
    def skill(self) -> object | None:
        """The skill running now, if any (a live page draws it)."""

    @property
    def trajectory(self) -> Sequence[Sample]:
        """The robot's poses so far, at the recording rate."""

    @property
    def recording(self) -> Recorder:
        """Poses and postures at a fixed rate, for the run's replay."""

    def robot_pose(self) -> Pose:
        """The robot's base pose now."""

    def snapshot(self) -> WorldState:
        """The state task hooks read: facts grounded in the physics, poses."""

    def facts_key(self) -> tuple[Any, ...]:
        """A key that changes whenever the symbolic state may have (what the hazard monitor watches)."""

    def bind(self, bindings: Iterable[Binding]) -> None:
        """Take the task folders' physical bindings (a fact that a device's state grounds)."""

    def set_door(self, name: str, is_open: bool) -> None:
        """Open or close a door."""

    def set_device(self, name: str, state: str) -> None:
        """Switch a device."""

    def move(self, thing: str, place: str) -> bool:
        """Put an object at a place; False if it cannot be moved now (the robot holds it)."""

    def apply(self, add: Iterable[Iterable[str]] = (), delete: Iterable[Iterable[str]] = ()) -> None:
        """Change facts the physics does not ground."""

    def write_trajectory(self, path: str | Path) -> Path:
        """Write the recorded poses and postures (``trajectory.jsonl``)."""
