"""The 2-D scene: exact distances, and a version that changes with the dynamic layer."""

from __future__ import annotations

import numpy as np

from robot.scene import Scene, segment_box_distance


def test_segment_box_distance_matches_dense_sampling() -> None:
    rng = np.random.default_rng(3)
    boxes = np.array([[1.0, 1.0, 2.0, 1.5], [3.0, 0.0, 3.2, 4.0]])
    a, b = rng.uniform(-1, 5, (200, 2)), rng.uniform(-1, 5, (200, 2))
    exact = segment_box_distance(a, b, boxes)
    t = np.linspace(0, 1, 2001)[None, :, None]
    pts = a[:, None, :] + t * (b - a)[:, None, :]
    for m, (x0, y0, x1, y1) in enumerate(boxes):
        dx = np.maximum(np.maximum(x0 - pts[..., 0], pts[..., 0] - x1), 0)
        dy = np.maximum(np.maximum(y0 - pts[..., 1], pts[..., 1] - y1), 0)
        sampled = np.hypot(dx, dy).min(axis=1)
        assert np.all(exact[:, m] <= sampled + 1e-9)
        assert np.all(sampled - exact[:, m] < 0.01)


def test_version_tracks_doors_and_people(flat) -> None:
    scene = Scene(flat, 0.35)
    v = scene.version
    scene.set_door("bedroom_door", False)  # already closed: no change
    assert scene.version == v
    scene.set_door("bedroom_door", True)
    scene.set_person("anna", 3.0, 4.2, "sitting")
    scene.set_person("anna", 3.0, 4.2, "sitting")
    assert scene.version == v + 2
    assert not scene.free(3.0, 4.2 + 0.5)
    assert scene.free(3.0, 4.2 + 0.5, ignore=("anna",))
