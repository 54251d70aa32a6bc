"""What became of every located curved seam of a weld run: handed to the planner (the found ones; on a track
too), then welded with its executed TCP against the true curve, or why not with the planner's code
(docs/curves-welding.md). Values in, values out; frames: R (the robot base) [m]."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from cell.pipeline.outcomes import Doubt, curve_welds
from cell.pipeline.records import Detection
from cell.scenario import Scenario
from cell.types import SeamStatus
from cell.types.curve_estimate import CurveEstimate
from cell.types.run import SeamWeld, WeldReason

if TYPE_CHECKING:
    from cell.types.execution import Execution
    from cell.types.plan import WeldPlan


def curve_doubt(c: CurveEstimate, sc: Scenario) -> Doubt | None:
    """Why a located curve is too uncertain to weld (None when it may be): its largest bound across the seam
    (``rescan.bound_sigmas`` times its largest sample sigma) over ``rescan.weld_tolerance_mm`` or its confidence
    under ``rescan.weld_min_confidence`` (``low_confidence``), or, on an open curve, an end's bound along it over
    ``rescan.end_tolerance_mm`` (``end_uncertain``): the straight seams' rule (:func:`cell.pipeline.outcomes.doubt`)
    taken at the curve's worst sample."""
    r = sc.rescan
    if c.sigma_max_m > r.max_sigma_m:
        bound_mm = r.bound_sigmas * c.sigma_max_m * 1000.0
        why = f"bound {r.bound_sigmas:g} sigma = {bound_mm:.2f} mm at its worst sample > weld tolerance "
        return Doubt(WeldReason.LOW_CONFIDENCE, why + f"{r.weld_tolerance_mm:g} mm")
    if c.confidence < r.weld_min_confidence:
        return Doubt(WeldReason.LOW_CONFIDENCE, f"confidence {c.confidence:.2f} < {r.weld_min_confidence:.2f}")
    if not c.closed and max(c.end_sigma_m) > r.max_end_sigma_m:
        bounds = ", ".join(f"{r.bound_sigmas * s * 1000.0:.2f}" for s in c.end_sigma_m)
        why = f"end bound {r.bound_sigmas:g} sigma = {bounds} mm > end tolerance {r.end_tolerance_mm:g} mm"
        return Doubt(WeldReason.END_UNCERTAIN, why)
    return None


def curves_to_plan(det: Detection, skip: Sequence[str] = ()) -> list[CurveEstimate]:
    """The located (found) curved seams the planner is given (a fixed arm's or one on a track), never those in
    ``skip`` nor one too uncertain to weld (:func:`curve_doubt`)."""
    return [
        c
        for c in det.curve_estimates
        if c.status is SeamStatus.FOUND and c.id not in skip and curve_doubt(c, det.scenario) is None
    ]


def curve_seam_welds(
    det: Detection,
    plan: WeldPlan | None,
    ex: Execution | None,
    pre_s: float,
    refused: str,
) -> dict[str, SeamWeld]:
    """Curved seam id -> what became of it, for every found curve: welded (its quality against the true curve,
    where the station knows it), or not with its code: too uncertain (:func:`curve_doubt`), the planner's refusal
    (``not_planned`` with the planner's code), planned but not executed (``not_executed``: ``refused`` says why;
    ``preview``); welded in part (``partial``: its arcs' quality, the remainder left for a manual weld). pre_s
    [s]: the move before the plan."""
    found = [c for c in det.curve_estimates if c.status is SeamStatus.FOUND]
    outcomes = {o.seam_id: o for o in plan.seams} if plan is not None else {}
    closed = {c.id: c.closed for c in found if c.id in outcomes and outcomes[c.id].feasible}
    ests = {c.id: c for c in found}
    quality = {}
    if plan is not None:
        quality = curve_welds(plan, ex, pre_s, det.curve_truths, closed, det.scenario.X_WR, ests)
    out: dict[str, SeamWeld] = {}
    for c in found:
        o = outcomes.get(c.id)
        welds = [g for g in plan.segments if g.arc_on and g.seam_id == c.id] if plan is not None else []
        proc = welds[0].procedure if welds else None
        doubt = curve_doubt(c, det.scenario)
        if doubt is not None:
            out[c.id] = SeamWeld(c.id, False, False, doubt.detail, code=doubt.code)
        elif o is None:
            why = refused or "not planned"
            code = WeldReason.NOT_EXECUTED if refused else WeldReason.NOT_PLANNED
            out[c.id] = SeamWeld(c.id, False, False, why, code=code)
        elif not o.feasible:
            out[c.id] = SeamWeld(c.id, False, False, o.reason, code=WeldReason.NOT_PLANNED, plan_code=o.code)
        elif ex is None:
            code = WeldReason.NOT_EXECUTED if refused else WeldReason.PREVIEW
            why = refused or ("planned, not executed (preview)" + (f"; {o.reason}" if o.partial else ""))
            out[c.id] = SeamWeld(c.id, True, False, why, code=code, procedure=proc, share=o.share,
                                 remainder=o.remainder)  # fmt: skip
        else:
            q = quality.get(c.id)
            passes = (q,) if q is not None else ()
            if o.partial:  # its arcs welded, the rest left for a manual weld: never counted as welded
                out[c.id] = SeamWeld(c.id, True, False, o.reason, q, WeldReason.PARTIAL, proc, passes, share=o.share,
                                     remainder=o.remainder)  # fmt: skip
            else:
                out[c.id] = SeamWeld(c.id, True, True, "", q, procedure=proc, passes=passes)
    return out
