"""Which of tasker's files a TOML file is, from its top-level keys.

A day protocol given to ``tasker run``, or a scenario given to ``tasker day``, was refused
for the first key the reader missed in it (``tasks.transport.stages: missing``,
``day: missing``), which sends the user to fix a file that is fine.  Each reader of a
file kind calls :func:`expect` first, so a file of another kind is named for what it is
and the command that runs it.
"""

from __future__ import annotations

from tasker.support.reader import Table

KINDS: dict[str, tuple[tuple[str, ...], str]] = {
    "day protocol": (("arrivals",), "run it with 'tasker day --protocol FILE'"),
    "sweep spec": (("scenarios",), "run it with 'tasker sweep FILE --db DB'"),
    "scenario": (("requests", "terminations"), "run it with 'tasker run FILE', or list it in a sweep spec's scenarios"),
    "world file": (("rooms", "walls"), "check it with 'tasker world FILE'; a scenario names it in 'world', "
                                        "a protocol in [robot_backend] 'world'"),
}
"""Each kind, the top-level keys only that kind has, and how such a file is used."""


def expect(top: Table, kind: str) -> None:
    """Raise ``top.error`` when ``top`` (a file's top level, read to be a ``kind``) is plainly
    another kind of file: it has a key that only that kind has, and none only ``kind`` has."""
    if any(key in top for key in KINDS[kind][0]):
        return
    for other, (markers, how) in KINDS.items():
        found = [key for key in markers if key in top]
        if other != kind and found:
            raise top.error(None, f"this is a {other} (it has {found[0]!r}), not a {kind}: {how}")
