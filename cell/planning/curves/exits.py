"""An arc whose way out no transfer finds, planned again: where the move out of an arc of a curve welded in part
fails towards two places or more, the arc's exit is at fault (its end configuration, not what follows), so before
the order search drops anything the curve is covered again with that arc trimmed at its end (its end configuration
then differs) and chosen again, as an arc refused by the safety gate at one end is (docs/curves-welding.md
section 9, "A failing exit planned again").

Frames: everything in the robot base frame R [m]; joints [rad]."""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from cell.planning.curves.partial import shared_m
from cell.planning.curves.plan import cover_curves
from cell.planning.curves.split import ARC_MARK, Partial, seam_of
from cell.planning.failures import SeamFailure
from cell.planning.moves.pieces import TransferFail
from cell.planning.seam_search import SeamSearch, SeamSolution
from cell.types.curve_estimate import CurveEstimate
from cell.types.plan import PlanReason, Remainder
from cell.types.procedure import WeldProcedure

EXIT_TRIES = 3  # an arc's exit planned again at most this many times per curve (each trims its end once more)


def exit_at_fault(a: str, b: str, failed: Collection[tuple[str, str]], parts: Mapping[str, Partial]) -> bool:
    """Whether the failing transfer from ``a`` to ``b`` ("" = home) is ``a``'s exit's fault: ``a`` is an arc of a
    curve that may be welded in part (in ``parts``) and a move out of it towards another place than ``b`` failed
    too (in ``failed``, the transfers (from, to) the order search found no free way for)."""
    return bool(a) and seam_of(a) != a and seam_of(a) in parts and any(x == a and y != b for x, y in failed)


@dataclass(frozen=True)
class Replanned:
    """A curve covered again once an arc's exit failed: its arcs (arc id -> solutions, one per pass) and their
    stretches (arc id -> (from, to) [m]), what it leaves for a manual weld (``part``), or why no arc is left
    (``failure``)."""

    arcs: dict[str, tuple[SeamSolution, ...]]
    spans: dict[str, tuple[float, float]]
    part: Partial | None
    failure: SeamFailure | None


def exit_refusal(aid: str, span: tuple[float, float], fail: TransferFail, home: bool) -> Remainder:
    """The refusal of arc ``aid`` (its stretch ``span`` (from, to) [m]) whose move out failed (``fail``; towards
    home: ``home``), at its end: the partial cover trims it there (:func:`.partial.refusal`)."""
    move = f"transfer move {'home ' if home else ''}from the seam"
    why = f"arc {aid.rsplit(ARC_MARK, 1)[1]}: no free {move} (its way out planned again): {fail.reason}"
    return Remainder(span[0], span[1], PlanReason.TRANSFER_COLLISION, why, "end")


def replan_exit(
    curve: CurveEstimate,
    searches: Mapping[str, SeamSearch],
    q_seed: np.ndarray,
    procedures: Mapping[str, WeldProcedure],
    refused: Sequence[Remainder],
) -> Replanned:
    """``curve`` covered again (:func:`.plan.cover_curves`) with the ``refused`` stretches (the safety gate's and
    the failing exits' so far), from q_seed (dof,) [rad] with its search and procedure."""
    arcs, still, parts, spans = cover_curves([curve], searches, q_seed, procedures, {curve.id: refused})
    return Replanned(arcs, spans, parts.get(curve.id), still.get(curve.id))


def still_welds(got: Replanned, span: tuple[float, float], curve: CurveEstimate) -> bool:
    """Whether the curve covered again still welds most of the stretch ``span`` (from, to) [m] of the arc whose exit
    failed (that arc trimmed at its end, not left out: leaving it out is choosing which arc to lose, which the
    order search does)."""
    if got.part is None or not got.arcs:
        return False
    total, a, b = curve.length_m, *span
    return any(shared_m(x, y, a, b, total, curve.closed) >= 0.5 * (b - a) for x, y in got.spans.values())
