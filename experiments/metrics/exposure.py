"""Each hazard episode cut into what the user must tell apart: attended, unattended, over budget, nobody's.

A declared hazard (``[[hazards]]`` of a task folder) is *attended* while its owner holds the
robot (is in ``cmd``); *unattended* while it does not — whether it waits, or ended (hazard time
runs until the hazard is off or the run ends, whoever ended); and *over budget* for the part of
an unattended stretch beyond the hazard's ``budget_s``.  A hazard *nobody owns* (no task
declared it with its arguments, and no stage of a task declaring it made it true) is drawn
apart, with why: it was so in the world file, a world event made it so, or a task that does not
declare it did.  The report (:mod:`experiments.report.run_page`), its figures and ``tasker
run``'s summary read these stretches; the numbers in ``metrics.json`` are
:func:`experiments.metrics.run.safety`'s, from the same definitions.
"""

from __future__ import annotations

from dataclasses import dataclass

from experiments.trace.timeline import CMD, AgentTimeline, HazardEpisode, Timeline

KINDS = ("attended", "unattended", "over budget", "nobody's")
"""What a stretch of a hazard episode was, in the order a legend lists them."""


@dataclass(frozen=True, slots=True)
class Stretch:
    """A piece of one hazard episode: ``owner`` (None: nobody's), the hazard's ``label``
    (``name arg …``), ``[start, end]``, its ``kind`` (:data:`KINDS`) and, for nobody's, ``why``."""

    owner: str | None
    label: str
    start: float
    end: float
    kind: str
    why: str = ""

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"Stretch.kind: expected one of {list(KINDS)}, got {self.kind!r}")
        if not self.end >= self.start:
            raise ValueError(f"Stretch: end {self.end} before start {self.start}")


def _cmd_spans(owner: AgentTimeline, start: float, end: float) -> list[tuple[float, float]]:
    """The owner's time in ``cmd`` within ``[start, end]``, adjoining states merged."""
    out: list[tuple[float, float]] = []
    for s in owner.states:
        lo, hi = max(s.start, start), min(s.end, end)
        if s.state not in CMD or hi <= lo:
            continue
        if out and lo <= out[-1][1] + 1e-9:
            out[-1] = (out[-1][0], max(out[-1][1], hi))
        else:
            out.append((lo, hi))
    return out


def stretches(tl: Timeline) -> list[Stretch]:
    """Every hazard episode of ``tl`` as stretches (see the module docstring), in time order."""
    out: list[Stretch] = []
    for h in tl.hazards:
        end = h.end if h.end is not None else tl.t_end
        owner = tl.agents.get(h.owner) if h.owner is not None else None
        if owner is None:
            out.append(Stretch(None, h.label, h.start, end, "nobody's", unowned_reason(tl, h)))
            continue
        cursor = h.start
        for lo, hi in _cmd_spans(owner, h.start, end) + [(end, end)]:
            if lo > cursor:  # unattended from cursor to lo: the first budget_s of it within budget
                edge = min(lo, cursor + h.budget_s)
                if edge > cursor:
                    out.append(Stretch(h.owner, h.label, cursor, edge, "unattended"))
                if lo > edge:
                    out.append(Stretch(h.owner, h.label, edge, lo, "over budget"))
            if hi > lo:
                out.append(Stretch(h.owner, h.label, lo, hi, "attended"))
            cursor = max(cursor, hi)
    return sorted(out, key=lambda s: (s.start, s.owner or "", s.label, KINDS.index(s.kind)))


def unowned_reason(tl: Timeline, h: HazardEpisode) -> str:
    """Why nobody owns hazard episode ``h``: the world file, a world event, or a task not declaring it."""
    made = [w for w in tl.world if abs(w.t - h.start) < 1e-6]
    if made:
        return f"a world event made it so ({made[0].note or made[0].what})"
    done = [(a, st) for a in tl.agents.values() for st in a.stages
            if st.status == "done" and st.end is not None and abs(st.end - h.start) < 1e-6]
    if done:
        a, st = done[0]
        return f"{a.id} {a.task_type}'s {st.action} made it so, and {a.task_type} does not declare it"
    first = min((e.t for e in tl.events), default=0.0)
    if h.start <= first + 1e-6:
        return "so in the world file"
    return "the world changed it"
