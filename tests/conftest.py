"""Shared fixtures and builders for the test suite."""

from __future__ import annotations

import os
import tempfile

os.environ.setdefault("MPLBACKEND", "Agg")
# the check cache (planners.cache) of a test session is its own: never the user's ~/.cache
os.environ.setdefault("TASKER_CACHE", tempfile.mkdtemp(prefix="tasker-test-cache-"))
