"""How to run a scenario, beside the scenario itself: one typed value passed whole.

:class:`RunOptions` is what ``tasker run``'s flags, a sweep's job, a replay and a day each
choose about a run — its seed, the strategies, the scheduler, a randomised variant and the
world's perturbation — and :func:`experiments.run.runner.run_scenario` and
:func:`experiments.run.runner.build_robot_actions` take it whole (``None`` in a field: the
scenario's own setting).  It checks its values on construction, so a bad one is refused
where it is written, not deep in a run.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from tasker.task import POLICIES, SUSPENSIONS, UPDATES

if TYPE_CHECKING:
    from experiments.inputs.perturbation import Perturbation
    from experiments.inputs.scenario import InterruptionGrid
    from experiments.inputs.strategy import Strategy

MODES = ("IT", "CT")


@dataclass(frozen=True)
class RunOptions:
    """Everything a run may set besides its scenario (``None``: the scenario's own).

    ``seed``: the run's seed; ``update``/``suspension``/``policy``/``scheduler``/``mode``: the
    strategies and harmonisation; ``tree``: the decision tree genSusp reads, ``NAME`` in every
    task folder that declares one so named or ``TYPE:NAME`` in one type's (``docs/domains.md``);
    ``hazard_waiting``: hazard-aware waiting on; ``randomize``: a randomised variant drawn from the
    seed, with ``interruption`` placing its interrupting request and ``perturbation`` changing its
    world; ``request_fields``: every task type takes ``deadline``/``priority``; ``task_paths``:
    task folders loaded besides the bundled ones."""

    seed: int | None = None
    update: str | None = None
    suspension: str | None = None
    scheduler: str | None = None
    mode: str | None = None
    policy: str | None = None
    hazard_waiting: bool = False
    tree: str | None = None
    randomize: bool = False
    interruption: InterruptionGrid | None = None
    perturbation: Perturbation | None = None
    request_fields: bool = False
    task_paths: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        for name, allowed in (("update", UPDATES), ("suspension", SUSPENSIONS), ("policy", POLICIES),
                              ("mode", MODES)):
            value = getattr(self, name)
            if value is not None and value not in allowed:
                raise ValueError(f"{name}: expected one of {list(allowed)}, got {value!r}")
        if self.seed is not None and (isinstance(self.seed, bool) or not isinstance(self.seed, int)
                                      or not 0 <= self.seed < 2**32):
            raise ValueError(f"seed: expected an integer 0 <= N < 2**32, got {self.seed!r}")
        if self.tree is not None:
            parts = self.tree.split(":") if isinstance(self.tree, str) else []
            if not 1 <= len(parts) <= 2 or not all(p.isidentifier() for p in parts):
                raise ValueError(f"tree: expected NAME or TYPE:NAME, got {self.tree!r}")
        if isinstance(self.task_paths, str) or not all(isinstance(p, str) for p in self.task_paths):
            raise TypeError(f"task_paths: expected a sequence of folders, got {self.task_paths!r}")
        object.__setattr__(self, "task_paths", tuple(self.task_paths))

    @classmethod
    def of(cls, strategy: Strategy, **others: Any) -> RunOptions:
        """The options of a sweep's strategy (its factors), with ``others`` (seed, variant, paths)."""
        return cls(update=strategy.update, suspension=strategy.suspension, scheduler=strategy.scheduler,
                   policy=strategy.policy, hazard_waiting=bool(strategy.hazard_waiting), tree=strategy.tree,
                   **others)

    def tree_for(self, task_type: str, trees: tuple[str, ...]) -> str | None:
        """The tree ``task_type`` (whose trees are ``trees``) reads under these options, or None (its default)."""
        if self.tree is None:
            return None
        kind, _, name = self.tree.rpartition(":")
        if kind and kind != task_type:
            return None
        return name if name in trees else None
