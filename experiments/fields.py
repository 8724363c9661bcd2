"""Reading one table of a scenario file, with errors that name the file and the field."""

from __future__ import annotations

from typing import Any

from tasker.errors import TaskerError


class ScenarioError(TaskerError, ValueError):
    """A scenario file is malformed; the message names the file and the field."""


class Fields:
    """Reads one table of a scenario file, naming ``file: path.to.field`` in every error."""

    def __init__(self, source: str, where: str, table: Any) -> None:
        if not isinstance(table, dict):
            raise ScenarioError(f"{source}: {where or 'top level'}: expected a table, got {type(table).__name__}")
        self.source, self.where, self.table = source, where, table
        self.used: set[str] = set()

    def path(self, key: str) -> str:
        return f"{self.where}.{key}" if self.where else key

    def error(self, key: str, msg: str) -> ScenarioError:
        return ScenarioError(f"{self.source}: {self.path(key)}: {msg}")

    def get(self, key: str, kind: type[Any] | tuple[type[Any], ...], default: Any = ..., *,
            positive: bool = False) -> Any:
        self.used.add(key)
        if key not in self.table:
            if default is ...:
                raise self.error(key, "missing (required)")
            return default
        value = self.table[key]
        if kind is float and isinstance(value, int) and not isinstance(value, bool):
            value = float(value)
        if isinstance(value, bool) and kind is not bool or not isinstance(value, kind):
            names = kind.__name__ if isinstance(kind, type) else " or ".join(k.__name__ for k in kind)
            raise self.error(key, f"expected {names}, got {value!r}")
        if positive and value <= 0:
            raise self.error(key, f"expected a positive number, got {value!r}")
        return value

    def seed(self, key: str, default: int) -> int:
        """A seed: an integer ``0 <= seed < 2**32`` (what NumPy, OMPL and MuJoCo accept)."""
        value = self.get(key, int, default)
        if not 0 <= value < 2**32:
            raise self.error(key, f"expected a seed 0 <= seed < 2**32, got {value}")
        return int(value)

    def sub(self, key: str, default: Any = ...) -> Fields:
        return Fields(self.source, self.path(key), self.get(key, dict, default))

    def done(self) -> None:
        extra = sorted(set(self.table) - self.used)
        if extra:
            raise self.error(extra[0], f"unknown field; expected one of {sorted(self.used)}")
