"""The robot's on-disk caches: the dimensions read from Pinocchio, TIAGo's MuJoCo source
(URDF text and converted meshes) and the grown roadmap.

A hit gives what a fresh build gives (bit for bit), an entry that cannot be used is built
again and rewritten, ``TASKER_CACHE=off`` writes nothing, and every input is in the key.
Every test has its own cache folder (never the user's).
"""

from __future__ import annotations

import dataclasses
import json
import multiprocessing
import os
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest

import robot.roadmap as roadmap_module
import robot.tiago as tiago
import tasker.support.diskcache
from robot.roadmap import Roadmap, disk_key
from robot.scene import Scene
from robot.spec import WorldSpec, load_world

ROOT = Path(__file__).resolve().parents[2]
SMALL = 300  # milestones: a quick roadmap of the paper apartment


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """A fresh cache folder, and no roadmap or dimensions remembered in this process."""
    monkeypatch.setenv("TASKER_CACHE", str(tmp_path / "c"))
    monkeypatch.setattr(roadmap_module, "_CACHE", {})
    tiago.robot_dimensions.cache_clear()
    tiago.mujoco_source.cache_clear()
    yield tmp_path / "c"
    tiago.robot_dimensions.cache_clear()
    tiago.mujoco_source.cache_clear()


@pytest.fixture(scope="module")
def scene(paper: WorldSpec) -> Scene:
    return Scene(paper, tiago.robot_dimensions()[2])


def _entries(root: Path, kind: str) -> list[Path]:
    return sorted((root / kind).rglob("*.*")) if (root / kind).is_dir() else []


def _grown(spec: WorldSpec, scene: Scene, monkeypatch: pytest.MonkeyPatch, milestones: int | None) -> Roadmap:
    """A roadmap grown now, the disk cache off."""
    monkeypatch.setattr(roadmap_module, "_CACHE", {})
    with monkeypatch.context() as m:
        m.setenv("TASKER_CACHE", "off")
        return Roadmap.for_world(spec, scene, 1, milestones)


def _loaded(spec: WorldSpec, scene: Scene, monkeypatch: pytest.MonkeyPatch, milestones: int | None) -> Roadmap:
    """The roadmap from the disk cache; growing one fails the test."""
    monkeypatch.setattr(roadmap_module, "_CACHE", {})

    def no_growth(*_: object) -> None:
        raise AssertionError("grown, not loaded")

    with monkeypatch.context() as m:
        m.setattr(roadmap_module, "_grow_with_ompl", no_growth)
        return Roadmap.for_world(spec, scene, 1, milestones)


def _assert_same(a: Roadmap, b: Roadmap) -> None:
    for name in ("nodes", "edges", "lengths", "corner_nodes"):
        x, y = getattr(a, name), getattr(b, name)
        assert x.dtype == y.dtype and x.shape == y.shape and np.array_equal(x, y), name
    assert a.stats == b.stats
    assert (a.graph != b.graph).nnz == 0


# -- the roadmap ---------------------------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("milestones", [SMALL, None], ids=["small", "default"])
def test_roadmap_from_disk_is_the_grown_one(cache: Path, paper: WorldSpec, scene: Scene,
                                            monkeypatch: pytest.MonkeyPatch, milestones: int | None) -> None:
    fresh = _grown(paper, scene, monkeypatch, milestones)
    assert _entries(cache, "roadmap") == []
    monkeypatch.setattr(roadmap_module, "_CACHE", {})
    first = Roadmap.for_world(paper, scene, 1, milestones)  # grown and written
    assert len(_entries(cache, "roadmap")) == 1
    _assert_same(first, fresh)
    _assert_same(_loaded(paper, scene, monkeypatch, milestones), fresh)


@pytest.mark.parametrize("damage", ["truncated", "garbage", "empty", "inconsistent", "pickled"])
def test_unusable_roadmap_entry_is_grown_again_and_rewritten(cache: Path, paper: WorldSpec, scene: Scene,
                                                             monkeypatch: pytest.MonkeyPatch, damage: str) -> None:
    fresh = Roadmap.for_world(paper, scene, 1, SMALL)
    (entry,) = _entries(cache, "roadmap")
    good = entry.read_bytes()
    if damage == "truncated":
        entry.write_bytes(good[: len(good) // 2])
    elif damage == "garbage":
        entry.write_bytes(b"\x00not a zip" * 50)
    elif damage == "empty":
        entry.write_bytes(b"")
    else:
        import io

        edges = fresh.edges.copy()
        edges[0, 0] = len(fresh.nodes) + 5  # a node that does not exist
        buf = io.BytesIO()
        arrays = {"nodes": fresh.nodes, "edges": edges, "lengths": fresh.lengths,
                  "corner_nodes": fresh.corner_nodes, "stats": np.zeros(5, dtype=np.int64),
                  "planner": np.array("x")}
        if damage == "pickled":
            arrays["nodes"] = np.array([object()], dtype=object)
        np.savez(buf, **arrays)
        entry.write_bytes(buf.getvalue())
    monkeypatch.setattr(roadmap_module, "_CACHE", {})
    again = Roadmap.for_world(paper, scene, 1, SMALL)  # no crash: grown again
    _assert_same(again, fresh)
    assert entry.read_bytes() == good  # and rewritten whole
    _assert_same(_loaded(paper, scene, monkeypatch, SMALL), fresh)


def test_roadmap_key_has_every_input(paper: WorldSpec, scene: Scene, monkeypatch: pytest.MonkeyPatch) -> None:
    key = disk_key(paper, scene, 1, SMALL)
    assert disk_key(paper, scene, 1, SMALL) == key
    moved = dataclasses.replace(paper, places={**paper.places, "hall": (0.5, 0.5, 0.0)})
    others = [disk_key(paper, scene, 2, SMALL), disk_key(paper, scene, 1, SMALL + 1), disk_key(paper, scene, 1, None),
              disk_key(paper, Scene(paper, scene.radius + 0.001), 1, SMALL), disk_key(moved, scene, 1, SMALL)]
    from importlib import metadata

    real = metadata.version
    with monkeypatch.context() as m:
        m.setattr(metadata, "version", lambda dist: "0.0.0" if dist == "ompl" else real(dist))
        others.append(disk_key(paper, scene, 1, SMALL))
    with monkeypatch.context() as m:
        m.setattr(tasker.support.diskcache, "__version__", "9.9.9")
        others.append(disk_key(paper, scene, 1, SMALL))
    with monkeypatch.context() as m:  # the roadmap module's source
        m.setattr(roadmap_module, "__file__", str(ROOT / "robot" / "spec.py"))
        others.append(disk_key(paper, scene, 1, SMALL))
    with monkeypatch.context() as m:  # the sources of the exact tests (scene's, spec's disc_clear)
        m.setattr(roadmap_module, "_GEOMETRY", ("scene.py",))
        others.append(disk_key(paper, scene, 1, SMALL))
    assert len({key, *others}) == len(others) + 1


def _grow_into(root: str) -> None:
    os.environ["TASKER_CACHE"] = root
    spec = load_world("paper")
    Roadmap.for_world(spec, Scene(spec, tiago.robot_dimensions()[2]), 1, SMALL)


@pytest.mark.slow
def test_concurrent_roadmap_writers_leave_one_whole_entry(cache: Path, paper: WorldSpec, scene: Scene,
                                                           monkeypatch: pytest.MonkeyPatch) -> None:
    ctx = multiprocessing.get_context("spawn")
    procs = [ctx.Process(target=_grow_into, args=(str(cache),)) for _ in range(3)]
    for p in procs:
        p.start()
    for p in procs:
        p.join(120)
        assert p.exitcode == 0
    assert len(_entries(cache, "roadmap")) == 1  # no temporary file left behind
    _assert_same(_loaded(paper, scene, monkeypatch, SMALL), _grown(paper, scene, monkeypatch, SMALL))


# -- the robot's dimensions ----------------------------------------------------------------------


@pytest.mark.slow
def test_robot_from_disk_is_the_measured_one_without_pinocchio_or_coal(cache: Path) -> None:
    code = ("import hashlib, json, sys\nfrom robot.tiago import mujoco_source, robot_dimensions\n"
            "text, assets = mujoco_source()\n"
            "h = hashlib.sha256(text.encode() + repr(assets).encode()).hexdigest()\n"
            "print(json.dumps([robot_dimensions(), h, 'pinocchio' in sys.modules, 'coal' in sys.modules]))")
    env = {**os.environ, "TASKER_CACHE": str(cache), "PYTHONPATH": str(ROOT)}

    def run() -> tuple[list[float], str, bool, bool]:
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, env=env)
        dims, digest, pinocchio, coal = json.loads(out.stdout)
        return dims, digest, pinocchio, coal

    measured, converted, pinocchio, coal = run()
    assert pinocchio and coal
    assert len(_entries(cache, "robot-dimensions")) == len(_entries(cache, "tiago-mujoco")) == 1
    cached, loaded, pinocchio, coal = run()
    assert cached == measured == list(tiago._measure_dimensions()) and loaded == converted
    assert not pinocchio and not coal


def test_mujoco_source_from_disk_is_the_converted_one(cache: Path) -> None:
    converted = tiago._convert_source()
    assert tiago.mujoco_source() == converted  # converted and written
    tiago.mujoco_source.cache_clear()
    assert tiago.mujoco_source() == converted  # loaded
    (entry,) = _entries(cache, "tiago-mujoco")
    good = entry.read_bytes()
    for damage in (good[: len(good) // 2], b"junk", b""):
        entry.write_bytes(damage)
        tiago.mujoco_source.cache_clear()
        assert tiago.mujoco_source() == converted
        assert entry.read_bytes() == good


@pytest.mark.parametrize("content", [b"", b"{not json", b'{"wheel_radius": 1}', b"[1, 2, 3]",
                                     b'{"wheel_radius": -1, "wheel_separation": 1, "planning_radius": 1}'])
def test_unusable_dimensions_entry_is_measured_again_and_rewritten(cache: Path, content: bytes) -> None:
    measured = tiago.robot_dimensions()
    (entry,) = _entries(cache, "robot-dimensions")
    good = entry.read_bytes()
    entry.write_bytes(content)
    tiago.robot_dimensions.cache_clear()
    assert tiago.robot_dimensions() == measured
    assert entry.read_bytes() == good



def _keys_under_other_versions(key: Callable[[], str], dists: tuple[str, ...],
                               monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """``key()`` with each of ``dists``' installed versions changed in turn, then tasker's."""
    from importlib import metadata

    real = metadata.version
    keys = []
    for dist in dists:
        with monkeypatch.context() as m:
            m.setattr(metadata, "version", lambda d, dist=dist: "0.0.0" if d == dist else real(d))
            keys.append(key())
    with monkeypatch.context() as m:
        m.setattr(tasker.support.diskcache, "__version__", "9.9.9")
        keys.append(key())
    return keys

def test_dimensions_key_has_every_input(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    key = tiago.dimensions_key()
    urdf = tmp_path / "tiago.urdf"
    urdf.write_bytes(tiago.urdf_path().read_bytes() + b" ")
    others = []
    with monkeypatch.context() as m:
        m.setattr(tiago, "urdf_path", lambda: urdf)
        others.append(tiago.dimensions_key())
    others += _keys_under_other_versions(tiago.dimensions_key, ("pin", "coal", "example-robot-data"), monkeypatch)
    assert len({key, *others}) == len(others) + 1


def test_mujoco_source_key_has_every_input(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    key = tiago.source_key()
    urdf = tmp_path / "tiago.urdf"
    urdf.write_bytes(tiago.urdf_path().read_bytes())
    others = []
    with monkeypatch.context() as m:  # the same bytes elsewhere: paths in the text differ
        m.setattr(tiago, "urdf_path", lambda: urdf)
        others.append(tiago.source_key())
        urdf.write_bytes(urdf.read_bytes() + b" ")
        others.append(tiago.source_key())
    others += _keys_under_other_versions(tiago.source_key, ("coal", "example-robot-data"), monkeypatch)
    with monkeypatch.context() as m:
        m.setattr(tiago, "__file__", str(ROOT / "robot" / "spec.py"))
        others.append(tiago.source_key())
    assert len({key, *others}) == len(others) + 1


# -- off means off -------------------------------------------------------------------------------


def test_cache_off_writes_nothing(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, paper: WorldSpec,
                                  scene: Scene) -> None:
    monkeypatch.setenv("TASKER_CACHE", "off")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    monkeypatch.setattr(roadmap_module, "_CACHE", {})
    tiago.robot_dimensions.cache_clear()
    tiago.mujoco_source.cache_clear()
    try:
        assert tiago.robot_dimensions()[2] == scene.radius
        assert tiago.mujoco_source() == tiago._convert_source()
        Roadmap.for_world(paper, scene, 1, SMALL)
    finally:
        tiago.robot_dimensions.cache_clear()
        tiago.mujoco_source.cache_clear()
    assert list(tmp_path.rglob("*")) == []


def test_unwritable_cache_is_no_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, paper: WorldSpec,
                                      scene: Scene) -> None:
    (tmp_path / "file").write_text("")
    monkeypatch.setenv("TASKER_CACHE", str(tmp_path / "file" / "c"))
    monkeypatch.setattr(roadmap_module, "_CACHE", {})
    fresh = _grown(paper, scene, monkeypatch, SMALL)
    monkeypatch.setattr(roadmap_module, "_CACHE", {})
    _assert_same(Roadmap.for_world(paper, scene, 1, SMALL), fresh)
