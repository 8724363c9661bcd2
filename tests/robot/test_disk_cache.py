"""The robot's on-disk caches: the dimensions read from Pinocchio and the grown roadmap.

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
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

import robot.roadmap as roadmap_module
import robot.tiago as tiago
import tasker.diskcache
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
    yield tmp_path / "c"
    tiago.robot_dimensions.cache_clear()


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
        m.setattr(tasker.diskcache, "__version__", "9.9.9")
        others.append(disk_key(paper, scene, 1, SMALL))
    with monkeypatch.context() as m:  # the roadmap module's source
        m.setattr(roadmap_module, "__file__", str(ROOT / "robot" / "spec.py"))
        others.append(disk_key(paper, scene, 1, SMALL))
    assert len({key, *others}) == len(others) + 1


def _grow_into(root: str) -> None:
    os.environ["TASKER_CACHE"] = root
    spec = load_world("paper")
    Roadmap.for_world(spec, Scene(spec, tiago.robot_dimensions()[2]), 1, SMALL)


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


def test_dimensions_from_disk_are_the_measured_ones_without_pinocchio(cache: Path) -> None:
    code = ("import json, sys\nfrom robot.tiago import robot_dimensions\n"
            "print(json.dumps([robot_dimensions(), 'pinocchio' in sys.modules]))")
    env = {**os.environ, "TASKER_CACHE": str(cache), "PYTHONPATH": str(ROOT)}

    def run() -> tuple[list[float], bool]:
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, env=env)
        dims, pinocchio = json.loads(out.stdout)
        return dims, pinocchio

    measured, imported = run()
    assert imported and len(_entries(cache, "robot-dimensions")) == 1
    cached, imported = run()
    assert cached == measured == list(tiago._measure_dimensions()) and not imported


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


def test_dimensions_key_has_every_input(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    key = tiago.dimensions_key()
    urdf = tmp_path / "tiago.urdf"
    urdf.write_bytes(tiago.urdf_path().read_bytes() + b" ")
    others = []
    with monkeypatch.context() as m:
        m.setattr(tiago, "urdf_path", lambda: urdf)
        others.append(tiago.dimensions_key())
    from importlib import metadata

    real = metadata.version
    for dist in ("pin", "coal", "example-robot-data"):
        with monkeypatch.context() as m:
            m.setattr(metadata, "version", lambda d, dist=dist: "0.0.0" if d == dist else real(d))
            others.append(tiago.dimensions_key())
    with monkeypatch.context() as m:
        m.setattr(tasker.diskcache, "__version__", "9.9.9")
        others.append(tiago.dimensions_key())
    assert len({key, *others}) == len(others) + 1


# -- off means off -------------------------------------------------------------------------------


def test_cache_off_writes_nothing(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, paper: WorldSpec,
                                  scene: Scene) -> None:
    monkeypatch.setenv("TASKER_CACHE", "off")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    monkeypatch.setattr(roadmap_module, "_CACHE", {})
    tiago.robot_dimensions.cache_clear()
    try:
        assert tiago.robot_dimensions()[2] == scene.radius
        Roadmap.for_world(paper, scene, 1, SMALL)
    finally:
        tiago.robot_dimensions.cache_clear()
    assert list(tmp_path.rglob("*")) == []


def test_unwritable_cache_is_no_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, paper: WorldSpec,
                                      scene: Scene) -> None:
    (tmp_path / "file").write_text("")
    monkeypatch.setenv("TASKER_CACHE", str(tmp_path / "file" / "c"))
    monkeypatch.setattr(roadmap_module, "_CACHE", {})
    fresh = _grown(paper, scene, monkeypatch, SMALL)
    monkeypatch.setattr(roadmap_module, "_CACHE", {})
    _assert_same(Roadmap.for_world(paper, scene, 1, SMALL), fresh)
