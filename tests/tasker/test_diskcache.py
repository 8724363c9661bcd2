"""The on-disk cache's folder, entries and writes (:mod:`tasker.support.diskcache`), shared by every cache."""

from __future__ import annotations

from pathlib import Path

import pytest

from tasker.support import diskcache


def test_entries_live_under_their_kind_and_key(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("TASKER_CACHE", str(tmp_path / "c"))
    key = diskcache.content_key("kind", ["a"])
    path = diskcache.entry_path("kind", key, ".npz")
    assert path == tmp_path / "c" / "kind" / key[:2] / f"{key}.npz"
    assert diskcache.read_entry(path) is None  # missing
    assert diskcache.write_atomic(path, b"one") and diskcache.read_entry(path) == b"one"
    assert diskcache.write_atomic(path, b"two, replaced whole") and diskcache.read_entry(path) == b"two, replaced whole"
    assert [p.name for p in path.parent.iterdir()] == [path.name]  # no temporary file left


def test_off_means_no_entries(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("TASKER_CACHE", "off")
    assert diskcache.cache_dir() is None
    assert diskcache.entry_path("kind", "0" * 64, ".json") is None
    assert diskcache.read_entry(None) is None


def test_unwritable_or_unreadable_is_no_cache(tmp_path: Path) -> None:
    (tmp_path / "file").write_text("")
    assert not diskcache.write_atomic(tmp_path / "file" / "k" / "entry.json", b"x")
    folder = tmp_path / "dir.json"
    folder.mkdir()
    assert diskcache.read_entry(folder) is None  # an entry that is a folder: unreadable, no error
