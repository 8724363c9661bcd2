"""The parts of ``docs/`` generated from the definitions they describe, never typed.

* ``docs/trace.md``: every event's fields, from the types of :mod:`tasker.events`;
* ``docs/metrics.md``: every metric's unit, direction and meaning, from
  :mod:`experiments.metrics.registry`.

Each generated part sits between two markers (``<!-- generated: NAME ... -->`` and
``<!-- end generated: NAME -->``) in its document; :func:`update` rewrites them and
``tasker docs --check`` (a test runs it) fails when one is out of date.
"""

from __future__ import annotations

import ast
import dataclasses
from collections.abc import Callable
from pathlib import Path

from experiments.analysis.tables import markdown_table
from experiments.metrics.registry import METRICS, Direction
from tasker import events as ev

ROOT = Path(__file__).resolve().parents[2]
SOURCES = ("tasker", "planners", "robot", "experiments")
"""The packages whose code may emit trace events."""


def emitters(root: Path = ROOT) -> dict[str, list[str]]:
    """Per event type (class name), the modules that construct it (``ev.Decision(...)``), found in
    the source: what emits each documented event, and a test that none is documented but never made."""
    names = {cls.__name__ for cls in ev.TYPES}
    out: dict[str, set[str]] = {n: set() for n in names}
    for pkg in SOURCES:
        for path in sorted((root / pkg).rglob("*.py")):
            if path == root / "tasker" / "events.py":
                continue
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr in names \
                        and isinstance(node.func.value, ast.Name) and node.func.value.id in ("ev", "events"):
                    out[node.func.attr].add(path.relative_to(root).as_posix())
    return {n: sorted(m) for n, m in out.items()}


def events_markdown() -> str:
    """One table per event type: its JSON fields in written order, their types, what they mean, and
    the modules that emit it (:func:`emitters`)."""
    out = []
    made = emitters()
    for cls in ev.TYPES:
        rows: list[tuple[str, str, str]] = [("`t`", "float", "simulated seconds since the start")]
        if cls is ev.Decision:
            rows.append(("(the record's own fields)", "–", "`algorithm`, `switch`, usually `rule`, `dac`, `exeDA`, "
                                                           "and what the algorithm compared"))
        else:
            fields = {f.name: f for f in dataclasses.fields(cls)}
            for attr, name, optional in cls.spec():
                f = fields[attr]
                kind = str(f.type).replace(" | None", "") + (" (optional)" if optional else "")
                rows.append((f"`{name}`", kind.replace("|", "∣"), f.metadata.get("doc", "")))
        by = ", ".join(f"`{m}`" for m in made[cls.__name__]) or "nothing (reserved)"
        out += [f"#### `{cls.KIND}`: {cls.__name__}", "", (cls.__doc__ or "").strip().split("\n\n")[0], "",
                f"Emitted by {by}, as `Trace.emit(ev.{cls.__name__}(...))`.", "",
                *markdown_table(["field", "type", "meaning"], rows), ""]
    return "\n".join(out)


def metrics_markdown() -> str:
    """The registry as a table: every metric's name, unit, direction and meaning."""
    rows = [(f"`{m.name}`", m.unit,
             "– (host)" if m.host else ("–" if m.direction is Direction.NEITHER else m.direction.value), m.meaning)
            for m in METRICS]
    return "\n".join(markdown_table(["metric", "unit", "better", "meaning"], rows)) + "\n"


GENERATED: dict[str, dict[str, Callable[[], str]]] = {
    "docs/trace.md": {"events": events_markdown},
    "docs/metrics.md": {"registry": metrics_markdown},
}
"""Per document, its generated parts and what makes each."""


def _markers(name: str) -> tuple[str, str]:
    return (f"<!-- generated: {name} (run 'tasker docs' to update; do not edit by hand) -->",
            f"<!-- end generated: {name} -->")


def splice(text: str, name: str, block: str) -> str:
    """``text`` with its part ``name`` replaced by ``block`` (appended at the end if it has none)."""
    begin, end = _markers(name)
    body = f"{begin}\n{block.rstrip()}\n{end}"
    if begin in text and end in text:
        head, _, rest = text.partition(begin)
        _, _, tail = rest.partition(end)
        return head + body + tail
    return text.rstrip() + "\n\n" + body + "\n"


def update(root: Path, *, check: bool = False) -> list[Path]:
    """Rewrite every generated part under ``root``; return the documents that changed (with
    ``check``, those that would, writing nothing)."""
    stale = []
    for doc, parts in GENERATED.items():
        path = root / doc
        text = path.read_text(encoding="utf-8") if path.is_file() else ""
        new = text
        for name, make in parts.items():
            new = splice(new, name, make())
        if new != text:
            stale.append(path)
            if not check:
                path.write_text(new, encoding="utf-8")
    return stale
