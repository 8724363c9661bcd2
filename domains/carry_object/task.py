"""Problem-builder hook of carry_object: passages without doors (:mod:`domains.doors`).

Closing the doors on a suspension is declared in ``task.toml`` (``[[suspension]]``), so the
static and the planned strategy pursue the same goal."""

from __future__ import annotations

from domains.doors import extra_facts

__all__ = ["extra_facts"]
