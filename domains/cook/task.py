"""Problem-builder hook of cook: passages without doors (:mod:`domains.doors`), so that a
cook that finds a door closed on its way opens it."""

from __future__ import annotations

from domains.doors import extra_facts

__all__ = ["extra_facts"]
