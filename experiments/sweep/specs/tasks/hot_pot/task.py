"""Problem-builder hook of hot_pot: passages without doors (:mod:`domains.doors`), so that the
robot opens a door it finds closed on its way (with an empty hand)."""

from __future__ import annotations

from domains.doors import extra_facts

__all__ = ["extra_facts"]
