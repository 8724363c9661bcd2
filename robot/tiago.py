"""TIAGo, offline, from the ``example-robot-data`` URDF: Pinocchio and MuJoCo models.

* **Pinocchio** (with coal geometry) builds the robot on a ``JointModelPlanar`` root
  for kinematics and the full mesh collision model.  It gives the footprint radius the
  2-D planner uses and the wheels' radius and separation (:func:`robot_dimensions`), and
  checks planned paths against the real geometry (:class:`RobotCollision`).  Building it
  from the URDF takes about 0.4 s, so the dimensions are kept on disk
  (:mod:`tasker.support.diskcache`, kind ``robot-dimensions``) under the SHA-256 of the URDF, this
  module's source and the versions of Pinocchio, coal and example-robot-data: a process
  that finds them there imports no Pinocchio at all.
* **MuJoCo** compiles the same URDF at load time: ``package://`` paths are resolved,
  the DAE collision meshes are converted to STL **in memory** (coal reads them) and
  handed to MuJoCo as assets, non-positive-definite inertias are repaired, the arm,
  torso and head are locked in the tucked posture (their joints removed) and the
  casters are made frictionless (``priority=1, condim=1, friction=0``) so the
  differential-drive base can roll.  The converted source (URDF text and mesh assets,
:func:`mujoco_source`) is cached in-process and on disk (kind ``tiago-mujoco``, same
key as the dimensions less Pinocchio's version), so a cached process imports no coal.

Mesh files are keyed by the example-robot-data version that installed them, not hashed
(5 MB read per process would cost a third of what the cache saves): after editing them
in place, clear the cache (``docs/cli.md``).

Nothing is downloaded.
"""

from __future__ import annotations

import io
import json
import logging
import math
import re
import zipfile
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from tasker.support.diskcache import content_key, installed_version, remembered

if TYPE_CHECKING:  # imported lazily at run time; neither library ships type stubs, so these are Any to mypy
    import mujoco
    import pinocchio as pin

TUCK = {"torso_lift_joint": 0.15, "arm_1_joint": 0.20, "arm_2_joint": -1.34, "arm_3_joint": -0.20,
        "arm_4_joint": 1.94, "arm_5_joint": -1.57, "arm_6_joint": 1.37, "arm_7_joint": 0.0}
"""TIAGo's *home* posture: arm folded inside the base's footprint."""

WHEELS = ("wheel_left_joint", "wheel_right_joint")
PLANNING_MARGIN = 0.03  # metres added to the footprint for the 2-D planner
DIMENSIONS_KIND = "robot-dimensions"  # the on-disk caches' kinds (tasker.support.diskcache)
SOURCE_KIND = "tiago-mujoco"
_DIMENSIONS = ("wheel_radius", "wheel_separation", "planning_radius")
log = logging.getLogger(__name__)


_URDF = Path("tiago_description") / "robots" / "tiago.urdf"


@lru_cache(maxsize=1)
def urdf_path() -> Path:
    """TIAGo's URDF in the installed example-robot-data.

    Found where ``example_robot_data.getModelPath`` looks for an installed package
    (``<site-packages>/../../../share/example-robot-data/robots``) without importing it:
    its loaders import Pinocchio (0.15 s), which a cached :func:`robot_dimensions` avoids.
    Any other layout falls back to ``getModelPath`` itself.
    """
    import importlib.util
    import sys

    found = importlib.util.find_spec("example_robot_data")
    roots = [str(Path(found.origin).parents[1])] if found is not None and found.origin else []
    for root in [*roots, *sys.path]:
        candidate = Path(root, "../../../share/example-robot-data/robots") / _URDF
        if candidate.is_file():
            return candidate.resolve()
    import example_robot_data as erd

    return (Path(erd.getModelPath("tiago_description")) / _URDF).resolve()


@lru_cache(maxsize=1)
def _pin_models() -> tuple[pin.Model, pin.GeometryModel]:
    import pinocchio as pin

    urdf = urdf_path()
    package_dir = str(urdf.parents[4])  # the folder that holds example-robot-data/
    model, collision, _visual = pin.buildModelsFromUrdf(str(urdf), [package_dir], pin.JointModelPlanar())
    return model, collision


class TiagoModel:
    """TIAGo's kinematics on a planar base (Pinocchio), arm tucked unless told otherwise."""

    def __init__(self) -> None:
        import pinocchio as pin

        self._pin = pin
        self.model, self.collision = _pin_models()
        self.data = self.model.createData()
        self.q_tuck = pin.neutral(self.model)
        for joint, value in TUCK.items():
            self.q_tuck[self.model.joints[self.model.getJointId(joint)].idx_q] = value

    def configuration(self, x: float, y: float, yaw: float) -> np.ndarray:
        """The tucked configuration with the base at ``(x, y, yaw)``."""
        q = self.q_tuck.copy()
        q[0], q[1], q[2], q[3] = x, y, math.cos(yaw), math.sin(yaw)
        return q

    def wheel_geometry(self) -> tuple[float, float]:
        """``(wheel radius, wheel separation)`` read from the model."""
        sep = 2.0 * abs(self.model.jointPlacements[self.model.getJointId(WHEELS[0])].translation[1])
        for g in self.collision.geometryObjects:
            if g.name.startswith("wheel_left_link"):
                return float(g.geometry.radius), float(sep)
        raise LookupError("TIAGo model has no wheel collision cylinder")

    def footprint_radius(self) -> float:
        """Largest horizontal distance from the base axis to any collision geometry, tucked."""
        import coal

        cdata = self.collision.createData()
        self._pin.updateGeometryPlacements(self.model, self.data, self.collision, cdata, self.configuration(0, 0, 0))
        radius = 0.0
        for i, g in enumerate(self.collision.geometryObjects):
            M, geom = cdata.oMg[i], g.geometry
            if isinstance(geom, coal.BVHModelOBBRSS):
                v = np.asarray(geom.vertices()) @ M.rotation.T + M.translation
                r = float(np.hypot(v[:, 0], v[:, 1]).max())
            else:
                geom.computeLocalAABB()
                lo, hi = np.asarray(geom.aabb_local.min_), np.asarray(geom.aabb_local.max_)
                corners = np.array([[a, b, c] for a in (lo[0], hi[0]) for b in (lo[1], hi[1]) for c in (lo[2], hi[2])])
                v = corners @ M.rotation.T + M.translation
                r = float(np.hypot(v[:, 0], v[:, 1]).max())
            radius = max(radius, r)
        return radius

    def planning_radius(self) -> float:
        return round(self.footprint_radius() + PLANNING_MARGIN, 3)


class RobotCollision:
    """The full TIAGo mesh model against box obstacles (Pinocchio + coal), for verification."""

    def __init__(self, boxes: list[tuple[float, float, float, float, float]]) -> None:
        import coal
        import pinocchio as pin

        self._pin = pin
        self.robot = TiagoModel()
        self.geom = self.robot.collision.copy()
        robot_ids = range(self.geom.ngeoms)
        ids = []
        for k, (x0, y0, x1, y1, h) in enumerate(boxes):
            placement = pin.SE3(np.eye(3), np.array([(x0 + x1) / 2, (y0 + y1) / 2, h / 2]))
            ids.append(self.geom.addGeometryObject(pin.GeometryObject(f"obstacle{k}", 0, placement,
                                                                       coal.Box(x1 - x0, y1 - y0, h))))
        for g in robot_ids:
            for o in ids:
                self.geom.addCollisionPair(pin.CollisionPair(g, o))
        self.gdata = self.geom.createData()

    def collides(self, x: float, y: float, yaw: float) -> bool:
        q = self.robot.configuration(x, y, yaw)
        return bool(self._pin.computeCollisions(self.robot.model, self.robot.data, self.geom, self.gdata, q, True))


def _stl_bytes(dae: str) -> bytes:
    import coal

    mesh = coal.MeshLoader().load(dae, np.ones(3))
    v = np.asarray(mesh.vertices(), dtype=np.float64)
    tris = np.array([[t[0], t[1], t[2]] for t in map(mesh.tri_indices, range(mesh.num_tris))],
                    dtype=np.int64).reshape(-1, 3)
    a, b, c = v[tris[:, 0]], v[tris[:, 1]], v[tris[:, 2]]
    rec = np.zeros(len(tris), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    rec["n"] = np.cross(b - a, c - a)
    rec["v"] = np.stack([a, b, c], axis=1)
    return b"\0" * 80 + np.uint32(len(tris)).tobytes() + rec.tobytes()


def _fix_inertia(match: re.Match[str]) -> str:
    a = dict(re.findall(r'(i[xyz]{2})="([^"]*)"', match.group(0)))
    inertia = np.array([[a["ixx"], a["ixy"], a["ixz"]], [a["ixy"], a["iyy"], a["iyz"]],
                        [a["ixz"], a["iyz"], a["izz"]]], dtype=float)
    if np.linalg.eigvalsh(inertia).min() > 1e-9:
        return match.group(0)
    d = np.maximum(np.abs(np.diag(inertia)), 1e-6)
    return f'<inertia ixx="{d[0]}" ixy="0" ixz="0" iyy="{d[1]}" iyz="0" izz="{d[2]}"/>'


MjSource = tuple[str, tuple[tuple[str, bytes], ...]]


def source_key() -> str:
    """The on-disk cache key of :func:`mujoco_source`: the URDF (bytes and place), this module, coal."""
    urdf = urdf_path()
    return content_key(SOURCE_KIND, [urdf.read_bytes(), str(urdf), Path(__file__).read_bytes(),
                                     installed_version("coal", "hpp-fcl"), installed_version("example-robot-data")])


def _source_to_npz(source: MjSource) -> bytes:
    text, assets = source
    buf = io.BytesIO()
    arrays: dict[str, Any] = {f"asset{k}": np.frombuffer(b, dtype=np.uint8) for k, (_, b) in enumerate(assets)}
    np.savez(buf, text=np.frombuffer(text.encode(), dtype=np.uint8), names=np.array([n for n, _ in assets]), **arrays)
    return buf.getvalue()


def _source_from_npz(data: bytes) -> MjSource | None:
    try:
        with np.load(io.BytesIO(data), allow_pickle=False) as z:
            raw, names = z["text"], [str(n) for n in z["names"]]
            blobs, files = [z[f"asset{k}"] for k in range(len(names))], len(z.files)
        if not all(b.dtype == np.uint8 and b.ndim == 1 for b in [raw, *blobs]) or files != len(names) + 2:
            raise ValueError("arrays of the wrong type, or more arrays than names")
        text = raw.tobytes().decode()
    except (OSError, ValueError, KeyError, TypeError, EOFError, zipfile.BadZipFile) as exc:
        log.debug("TIAGo MuJoCo source cache entry unusable, converted again: %s", exc)
        return None
    return text, tuple((n, b.tobytes()) for n, b in zip(names, blobs, strict=True))


@lru_cache(maxsize=1)
def mujoco_source() -> MjSource:
    """The URDF rewritten for MuJoCo and its mesh assets (name, bytes); cached in-process and on disk."""
    return remembered(SOURCE_KIND, source_key(), ".npz", _convert_source, _source_to_npz, _source_from_npz)


def _convert_source() -> MjSource:
    urdf = urdf_path()
    robots_dir = urdf.parents[2]
    text = urdf.read_text(encoding="utf-8").replace("package://example-robot-data/robots/", f"{robots_dir}/")
    text = re.sub(r"<visual>.*?</visual>", "", text, flags=re.S)  # visuals are DAE, and unused
    text = re.sub(r"<(transmission|gazebo)\b.*?</\1>", "", text, flags=re.S)
    assets: dict[str, bytes] = {}

    def asset(m: re.Match[str]) -> str:
        src = Path(m.group(1))
        name = "_".join(src.relative_to(robots_dir).with_suffix(".stl").parts)
        if name not in assets:
            assets[name] = _stl_bytes(str(src)) if src.suffix == ".dae" else src.read_bytes()
        return f'filename="{name}"'

    text = re.sub(r'filename="([^"]*\.(?:dae|stl|STL))"', asset, text)
    text = re.sub(r"<inertia[^>]*/>", _fix_inertia, text)
    header = ('<mujoco><compiler fusestatic="true" strippath="false" balanceinertia="true" '
              'discardvisual="false"/></mujoco><link name="odom"/>'
              '<joint name="base_free" type="floating"><parent link="odom"/><child link="base_footprint"/></joint>')
    text = re.sub(r"(<robot[^>]*>)", lambda m: m.group(1) + header, text, count=1)
    return text, tuple(sorted(assets.items()))


def _quat_mul(a: np.ndarray, b: np.ndarray) -> list[float]:
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return [w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2]


def tiago_mjspec() -> mujoco.MjSpec:
    """A fresh MuJoCo spec of TIAGo: free base, wheel velocity actuators, everything else rigid.

    Robot geoms collide with the world only (``contype=2, conaffinity=1``).
    """
    import mujoco

    text, assets = mujoco_source()
    spec = mujoco.MjSpec.from_string(text, assets=dict(assets))
    for g in spec.geoms:
        g.contype, g.conaffinity = 2, 1
        if g.type == mujoco.mjtGeom.mjGEOM_SPHERE and "caster" in g.parent.name:
            g.friction, g.condim, g.priority = [0, 0, 0], 1, 1
    for j in list(spec.joints):
        if j.name in ("base_free", *WHEELS):
            continue
        value, body = TUCK.get(j.name, 0.0), j.parent
        if value and j.type == mujoco.mjtJoint.mjJNT_HINGE:  # URDF joints sit at the body origin
            axis = np.asarray(j.axis, dtype=float) / np.linalg.norm(j.axis)
            body.quat = _quat_mul(np.asarray(body.quat), np.array([math.cos(value / 2), *(math.sin(value / 2) * axis)]))
        elif value and j.type == mujoco.mjtJoint.mjJNT_SLIDE:
            mat = np.zeros(9)
            mujoco.mju_quat2Mat(mat, np.asarray(body.quat, dtype=float))
            body.pos = np.asarray(body.pos) + mat.reshape(3, 3) @ (value * np.asarray(j.axis))
        spec.delete(j)  # the link is now rigidly attached to its parent
    for w in WHEELS:
        act = spec.add_actuator(name=w, target=w, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        act.set_to_velocity(kv=20.0)
        act.ctrlrange, act.ctrllimited = [-12, 12], True
    return spec


def dimensions_key() -> str:
    """The on-disk cache key of :func:`robot_dimensions`: everything the Pinocchio model is built from."""
    return content_key(DIMENSIONS_KIND, [urdf_path().read_bytes(), Path(__file__).read_bytes(),
                                         installed_version("pin", "pinocchio"), installed_version("coal", "hpp-fcl"),
                                         installed_version("example-robot-data")])


def _measure_dimensions() -> tuple[float, float, float]:
    model = TiagoModel()
    radius, separation = model.wheel_geometry()
    return radius, separation, model.planning_radius()


def _cached_dimensions(data: bytes) -> tuple[float, float, float] | None:
    try:
        entry = json.loads(data)
        dims = tuple(float(entry[k]) for k in _DIMENSIONS)
    except (ValueError, TypeError, KeyError) as exc:
        log.debug("robot dimensions cache entry unusable, measured again: %s", exc)
        return None
    if not all(math.isfinite(d) and d > 0 for d in dims):
        log.debug("robot dimensions cache entry unusable, measured again: %s", dims)
        return None
    return dims[0], dims[1], dims[2]


@lru_cache(maxsize=1)
def robot_dimensions() -> tuple[float, float, float]:
    """``(wheel radius, wheel separation, planning radius)`` from the Pinocchio model; cached in
    the process and on disk (a hit imports no Pinocchio; floats round-trip exactly through JSON)."""
    return remembered(DIMENSIONS_KIND, dimensions_key(), ".json", _measure_dimensions,
                      lambda dims: json.dumps(dict(zip(_DIMENSIONS, dims, strict=True))).encode(), _cached_dimensions)
