"""The apartment in MuJoCo: TIAGo plus walls, furniture, doors and people.

Walls and furniture are static boxes; each door is a box whose collision is switched
off while it is open (``geom_contype``/``geom_conaffinity`` are set at run time, the
model is not recompiled); people are mocap bodies (capsules, or lying boxes when
fallen) that the scripted people module moves and that do not collide — safety
around people is the navigation skill's job, on the 2-D scene.

Physics runs at a fixed timestep (``TIMESTEP``, 5 ms: four steps a 50 Hz control tick)
with the implicit-fast integrator; the same commands give the same trajectory.  MuJoCo
costs about the same per step whatever its length, so the step is as long as the runs
allow: 5 ms keeps the checks of ``tests/robot/test_sim.py`` (drive times within 15 % of
the time model, no contact with walls, the base at rest after braking) and the course of
every shipped scenario (the same stages in the same order, arrivals within about 1 % of
2 ms steps).  10 ms keeps the checks too but delays arrivals by up to 5 %, which moves
where the compound scenario's fall interrupts its carry task (``tests/domains/
test_doors.py``); 20 ms lags the commands by 20 %.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from robot.spec import WorldSpec
from robot.tiago import robot_dimensions, tiago_mjspec

if TYPE_CHECKING:  # imported lazily at run time; MuJoCo ships no type stubs, so this is Any to mypy
    import mujoco

TIMESTEP = 0.005
_COLOURS = {"wall": [0.75, 0.72, 0.68, 1], "furniture": [0.55, 0.4, 0.25, 1], "door": [0.4, 0.3, 0.2, 1]}


def build_model(spec: WorldSpec) -> mujoco.MjModel:
    """Compile the MuJoCo model of ``spec`` with the robot at its start pose."""
    import mujoco

    m = tiago_mjspec()
    m.option.timestep = TIMESTEP
    m.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    wb = m.worldbody
    (x0, y0), (x1, y1) = spec.bounds
    wb.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[(x1 - x0) / 2, (y1 - y0) / 2, 0.1],
                pos=[(x0 + x1) / 2, (y0 + y1) / 2, 0])
    for o in spec.obstacles:
        bx0, by0, bx1, by1 = o.box
        wb.add_geom(name=o.name, type=mujoco.mjtGeom.mjGEOM_BOX, rgba=_COLOURS[o.kind],
                    pos=[(bx0 + bx1) / 2, (by0 + by1) / 2, o.height / 2],
                    size=[(bx1 - bx0) / 2, (by1 - by0) / 2, o.height / 2])
    for d in spec.doors.values():
        bx0, by0, bx1, by1 = d.box
        wb.add_geom(name=f"door_{d.name}", type=mujoco.mjtGeom.mjGEOM_BOX, rgba=_COLOURS["door"],
                    pos=[(bx0 + bx1) / 2, (by0 + by1) / 2, 1.0], size=[(bx1 - bx0) / 2, (by1 - by0) / 2, 1.0])
    for p in spec.people.values():
        body = wb.add_body(name=f"person_{p.name}", mocap=True, pos=[p.pose[0], p.pose[1], 0.0])
        body.add_geom(name=f"person_{p.name}", type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[0.2, 0.65, 0],
                      pos=[0, 0, 0.85], contype=0, conaffinity=0, rgba=[0.9, 0.6, 0.5, 1])
    wb.add_light(pos=[(x0 + x1) / 2, (y0 + y1) / 2, 8], dir=[0, 0, -1], type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL)
    return m.compile()


class MjApartment:
    """A compiled apartment with its data; drives the base through wheel velocities."""

    def __init__(self, spec: WorldSpec) -> None:
        import mujoco

        self._mj = mujoco
        self.model = build_model(spec)
        self.data = mujoco.MjData(self.model)
        self.wheel_radius, self.wheel_separation, _ = robot_dimensions()
        self._wheels = [self.model.actuator(n).id for n in ("wheel_left_joint", "wheel_right_joint")]
        self._doors = {d: self.model.geom(f"door_{d}").id for d in spec.doors}
        self._people = {p: self.model.body(f"person_{p}").mocapid[0] for p in spec.people}
        x, y, yaw = spec.robot.pose
        self.data.qpos[0:7] = [x, y, 0.0, math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)]
        for name, d in spec.doors.items():
            self.set_door(name, d.open)
        mujoco.mj_forward(self.model, self.data)
        # the base's pose and velocity change only in :meth:`step` (nothing else writes
        # qpos/qvel): read once per step, not once per question (a tick asks several times)
        self._pose: tuple[float, float, float] | None = None
        self._velocity: tuple[float, float] | None = None

    @property
    def time(self) -> float:
        return float(self.data.time)

    def pose(self) -> tuple[float, float, float]:
        if self._pose is None:
            x, y, _, qw, qx, qy, qz = self.data.qpos[0:7].tolist()
            self._pose = (x, y, math.atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz)))
        return self._pose

    def velocity(self) -> tuple[float, float]:
        """Planar speed (m/s) and yaw rate (rad/s) of the base."""
        if self._velocity is None:
            v = self.data.qvel[0:6].tolist()
            self._velocity = (math.hypot(v[0], v[1]), v[5])
        return self._velocity

    def at_rest(self, tolerance: float = 1e-4) -> bool:
        """Is the base still (planar speed below ``tolerance`` m/s, turn rate below ``tolerance`` rad/s)?"""
        speed, turn = self.velocity()
        return speed < tolerance and abs(turn) < tolerance

    def command(self, v: float, w: float) -> None:
        half = w * self.wheel_separation / 2
        self.data.ctrl[self._wheels[0]] = (v - half) / self.wheel_radius
        self.data.ctrl[self._wheels[1]] = (v + half) / self.wheel_radius

    def step(self, n: int) -> None:
        self._mj.mj_step(self.model, self.data, nstep=n)
        self._pose = self._velocity = None

    def set_door(self, name: str, is_open: bool) -> None:
        g = self._doors[name]
        self.model.geom_contype[g] = 0 if is_open else 1
        self.model.geom_conaffinity[g] = 0 if is_open else 1
        self.model.geom_rgba[g, 3] = 0.15 if is_open else 1.0

    def set_person(self, name: str, x: float, y: float, yaw: float, posture: str) -> None:
        k = self._people[name]
        self.data.mocap_pos[k] = [x, y, -0.6 if posture == "fallen" else (-0.3 if posture == "sitting" else 0.0)]
        self.data.mocap_quat[k] = [math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)]

    def contacts_with_world(self) -> int:
        """Robot contacts with walls, furniture or doors (the floor excluded)."""
        floor = self.model.geom("floor").id
        n = 0
        for c in self.data.contact[: self.data.ncon]:
            a, b = int(c.geom1), int(c.geom2)
            if floor in (a, b):
                continue
            if (self.model.geom_bodyid[a] == 0) != (self.model.geom_bodyid[b] == 0):
                n += 1
        return n

    def state(self) -> np.ndarray:
        """The full physics state (time, qpos, qvel), for determinism checks."""
        return np.concatenate([[self.data.time], self.data.qpos, self.data.qvel])
