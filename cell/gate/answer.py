"""What the planner does about the safety gate's violations of a plan: another order without the move found at
fault, an arc of a curved seam welded in arcs left out alone, or a seam dropped (docs/reference.md section 7;
docs/curves-welding.md section 9)."""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import dataclass, field

from cell.gate.base import Violation
from cell.gate.blame import blamed_arcs, blamed_seams, in_arcs, incoming
from cell.planning.curves.split import seam_of as seam_of_arc
from cell.types.plan import Remainder, SeamOutcome, WeldPlan


@dataclass(frozen=True)
class GateAnswer:
    """The planner's answer to a plan's violations: ``moves``, seam id -> the transfer into it (from, to; "" =
    home) to leave out of the next order; ``arcs``, arc id -> its stretch along its curve with the gate's reason
    (left out alone, the stretch for a manual weld); ``drop``, seam id -> its outcome (dropped whole)."""

    moves: dict[str, tuple[str, str]] = field(default_factory=dict)
    arcs: dict[str, Remainder] = field(default_factory=dict)
    drop: dict[str, SeamOutcome] = field(default_factory=dict)


def gate_answer(
    plan: WeldPlan,
    found: Sequence[Violation],
    avoid: Collection[tuple[str, str]],
    *,
    by_arc: bool,
    reorder: bool = True,
) -> GateAnswer | None:
    """The answer to violations ``found`` in ``plan`` (None: none, or one that concerns the whole plan). A violation
    on the move into a seam (or its approach, the move blended into it) is first answered by another order without
    that transfer (``reorder``; not one in ``avoid``, tried already); a seam blamed on a move already avoided, or for
    its own motions, is dropped, except that a curved seam welded in several arcs or in part (``by_arc``: the
    process's ``curve_remainder`` is ``manual``) loses only the arc each violation falls on, the end of it named
    (``Remainder.end``: the planner trims a partial cover's arc there and chooses again)."""
    split = in_arcs(plan) if by_arc else set()
    blamed = blamed_seams(plan, found, split)
    if blamed is None:
        return None
    moves = {sid: e for sid, e in incoming(plan, found).items() if e not in avoid} if reorder else {}
    rest = [sid for sid in blamed if sid not in moves]
    arcs = blamed_arcs(plan, found, [sid for sid in rest if sid in split])
    cut = {seam_of_arc(a) for a in arcs}
    return GateAnswer(moves, arcs, {sid: blamed[sid] for sid in rest if sid not in cut})
