"""The record of a two-sided job: side A's weld run, the turn planned before anything moved, side B's
run after the operator turned the part, and what the second alignment measured. Values only."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace

from cell.errors import CellError
from cell.pipeline.records import WeldRun
from cell.pipeline.tacks import TackRecord
from cell.types import SeamStatus, WeldMap
from cell.types.run import SeamRecord
from cell.types.turnover import TurnoverPlan, TurnoverResult


@dataclass(frozen=True)
class TurnoverRun:
    """A whole part welded: side A, then (when seams were left against the table and the turn was made) side B.

    plan : the turn (None when nothing was left for a second side, or ``--sides first``). side_b : side B's run
    (None when no turn was made, or in a preview). result : the second alignment's measure of the placement.
    operator_s : the operator's time to turn the part (the scenario's figure) [s]. tacks : the tack welds side A
    laid first (:mod:`cell.pipeline.tacks`), each welded or why not; tacks_s their robot time in side A's plan
    (moves, approaches, welds, departs) [s], a part of side A's cycle time.
    error : what stopped the job between the sides (the turn refused), or None. positioner_turn_s : what a
    positioner's axis would take for the same turn [s] (:mod:`cell.planning.positioner`).
    """

    side_a: WeldRun
    plan: TurnoverPlan | None = None
    side_b: WeldRun | None = None
    result: TurnoverResult | None = None
    operator_s: float = 0.0
    tacks_s: float = 0.0
    error: CellError | None = None
    timings: Mapping[str, float] = field(default_factory=dict)
    turned_map: WeldMap | None = None  # the map at its nominal pose after the turn (R), for previews
    tacks: tuple[TackRecord, ...] = ()
    positioner_turn_s: float = 0.0

    def side_of(self) -> dict[str, str]:
        """Seam id -> the side it belongs to: ``"B"`` for those side B searched, ``"A"`` for every other."""
        b = {e.id for e in self.side_b.detection.estimates} if self.side_b is not None else set()
        return {e.id: ("B" if e.id in b else "A") for e in self.side_a.detection.estimates}

    def records(self) -> tuple[SeamRecord, ...]:
        """One :class:`SeamRecord` per seam of the map, in map order: side B's for the seams it searched, side A's
        for the others (a seam the turn cannot expose says why in its weld's reason)."""
        b = {r.id: r for r in self.side_b.records()} if self.side_b is not None else {}
        left = self.plan.left if self.plan is not None else {}
        out = []
        for rec in self.side_a.records():
            if rec.id in b:
                out.append(b[rec.id])
            elif rec.id in left and rec.weld is not None:
                out.append(replace(rec, weld=replace(rec.weld, reason=f"{rec.weld.reason}; {left[rec.id]}")))
            else:
                out.append(rec)
        return tuple(out)

    @property
    def welded(self) -> int:
        """Seams welded on both sides together."""
        return sum(r.weld is not None and r.weld.welded for r in self.records())

    @property
    def cycle_time_s(self) -> float:
        """Robot time of both sides [s] (re-scans and welding programs)."""
        return self.side_a.cycle_time_s + (self.side_b.cycle_time_s if self.side_b is not None else 0.0)

    @property
    def job_time_s(self) -> float:
        """The whole job [s]: both sides' robot time (side A's with its tacks) and the operator's turn (when it
        was made)."""
        return self.cycle_time_s + (self.operator_s if self.side_b is not None else 0.0)

    @property
    def complete(self) -> bool:
        """Side A complete, side B (if it ran) complete, nothing stopped the job between them; a seam the turn
        cannot expose (or a forbidden turn) keeps its not_visible reason as a single side does."""
        b_ok = self.side_b is None or self.side_b.complete
        refused = self.plan is not None and self.plan.allowed and bool(self.plan.exposed) and self.side_b is None
        return self.side_a.complete and b_ok and self.error is None and not (refused and self.side_a.execution)

    @property
    def visible_left(self) -> tuple[str, ...]:
        """Seams against the table on side A that no side welded."""
        recs = self.records()
        return tuple(
            r.id
            for r in recs
            if r.estimate.status is SeamStatus.NOT_VISIBLE and not (r.weld is not None and r.weld.welded)
        )
