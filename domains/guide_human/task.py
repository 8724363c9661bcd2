"""Problem-builder hook of guide_human: passages without doors (:mod:`domains.doors`), so that
the robot opens a door it finds closed on its way to or with the person."""

from __future__ import annotations

from domains.doors import extra_facts

__all__ = ["extra_facts"]
