"""The engines tasker adds to unified-planning's factory, and the one-shot planners it knows.

``tasker-fd`` (:class:`planners.engine.TaskerFastDownward`) is registered with UP's
documented mechanism, ``factory.add_engine(name, module, class)``: the factory imports
:mod:`planners.engine` itself when the engine is first asked for.  That is why both the
:class:`~planners.planner.Planner` facade and the engine import this module, and neither
imports the other: the dependency goes one way, from each of them to here.

Nothing of unified-planning is imported until a function below runs.
"""

from __future__ import annotations

ENGINE_NAME = "tasker-fd"
"""The name of the in-process Fast Downward engine (:mod:`planners.engine`)."""

ENGINE_MODULE = "planners.engine"
ENGINE_CLASS = "TaskerFastDownward"


def register_engine(name: str = ENGINE_NAME) -> None:
    """Add the engine to UP's factory (idempotent), through UP's documented ``add_engine``;
    also silence UP's credits banner, which would otherwise go to stdout."""
    from unified_planning.environment import get_environment

    env = get_environment()
    env.credits_stream = None
    factory = env.factory
    if name not in factory.engines:
        factory.add_engine(name, ENGINE_MODULE, ENGINE_CLASS)


def oneshot_planners() -> list[str]:
    """Names of the one-shot planning engines installed in UP's factory (``tasker-fd`` among them)."""
    from unified_planning.environment import get_environment

    register_engine()
    factory = get_environment().factory
    return sorted(n for n in factory.engines if _is_oneshot(factory.engine(n)))


def _is_oneshot(cls: type) -> bool:
    try:
        return bool(getattr(cls, "is_oneshot_planner")())  # noqa: B009 - engines are duck-typed
    except Exception:  # noqa: BLE001 - meta-engine wrappers may refuse the question
        return False
