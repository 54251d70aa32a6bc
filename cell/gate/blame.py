"""Which seam a gate violation belongs to, so that a plan drops that seam and welds the rest: a violation during a
seam's approach, weld, depart or the transfer to it is that seam's, the last move home the last seam's; a
start-state violation, or one that blames every seam, concerns the whole plan."""

from __future__ import annotations

from collections.abc import Collection, Sequence

import numpy as np

from cell.gate.base import Violation, ViolationKind
from cell.geometry import readonly
from cell.planning.curves.split import ARC_MARK
from cell.planning.curves.split import seam_of as seam_of_arc
from cell.planning.failures import reason_text
from cell.types.plan import ArcSpan, PlanReason, Remainder, SeamOutcome, Segment, WeldPlan

_CODE = {
    ViolationKind.COLLISION: PlanReason.COLLISION,
    ViolationKind.SINGULARITY: PlanReason.SINGULAR,
    ViolationKind.BODY: PlanReason.ENTERS_BODY,
}


def seam_of(plan: WeldPlan, v: Violation) -> str:
    """The seam whose motion violation ``v`` happens in ("" when it concerns the whole plan: the start state, or
    a time outside every segment)."""
    if v.kind is ViolationKind.START_STATE or not plan.segments:
        return ""
    seg = _segment_at(plan, v.t)
    if seg.seam_id:
        return seg.seam_id
    return plan.order[-1] if plan.order else ""  # the move home: the transfer from the last seam


def blamed_seams(
    plan: WeldPlan, violations: Sequence[Violation], split: Collection[str] = ()
) -> dict[str, SeamOutcome] | None:
    """Per seam to drop, its outcome with the first violation as the reason; None when some violation concerns
    the whole plan (then the plan is refused), when every seam of the plan is at fault (nothing would be left:
    the reason is the whole's, e.g. a gate threshold no pose meets) and none is in ``split`` (curved seams
    welded in arcs, which lose only the arc at fault: :func:`blamed_arcs`), or there is none."""
    out: dict[str, SeamOutcome] = {}
    for v in violations:
        sid = seam_of(plan, v)
        if not sid:
            return None
        if sid not in out:
            out[sid] = _outcome(plan, v, sid)
    if set(out) >= set(plan.order) and not set(out) & set(split):  # every seam at fault: the whole's reason
        return None
    return out or None


def in_arcs(plan: WeldPlan) -> set[str]:
    """The curved seams of ``plan`` welded in several arcs or in part (:attr:`WeldPlan.arcs`)."""
    return {seam_of_arc(a.arc_id) for a in plan.arcs}


def _outcome(plan: WeldPlan, v: Violation, sid: str) -> SeamOutcome:
    """Seam ``sid`` (or one of its arcs) refused for violation ``v``."""
    seg = next(s for s in plan.segments if s.seam_id == seam_of_arc(sid))
    transfer = v.kind is ViolationKind.COLLISION and _segment_at(plan, v.t).kind == "move"
    code = PlanReason.TRANSFER_COLLISION if transfer else _CODE.get(v.kind, PlanReason.TIMING)
    detail = f"the safety gate: {v}"
    return SeamOutcome(sid, False, reason_text(code, detail), readonly(seg.X_end[:3, 3].copy()), code=code)


def blamed_arcs(plan: WeldPlan, violations: Sequence[Violation], seams: Collection[str]) -> dict[str, Remainder]:
    """Arc id -> its stretch along its curve with the first violation on it as the reason (code and words, "arc K:
    the safety gate: ..."), for each arc of ``seams`` (curved seams welded in arcs, :attr:`WeldPlan.arcs`) that a
    violation falls on: on its move in, approach, weld or depart (the move home after it: the last arc's)."""
    out: dict[str, Remainder] = {}
    for v in violations:
        sid = seam_of(plan, v)
        if sid not in seams:
            continue
        t = _segment_at(plan, v.t).t0
        mine = [a for a in plan.arcs if seam_of_arc(a.arc_id) == sid and a.t0 <= t + 1e-9]
        if not mine:
            continue
        arc = max(mine, key=lambda a: a.t0)
        if arc.arc_id not in out:
            o = _outcome(plan, v, sid)
            assert o.code is not None
            why = f"arc {arc.arc_id.rsplit(ARC_MARK, 1)[1]}: the safety gate: {v}"
            out[arc.arc_id] = Remainder(arc.from_m, arc.to_m, o.code, why, _end_of(plan, arc, sid, t))
    return out


def _end_of(plan: WeldPlan, arc: ArcSpan, sid: str, t: float) -> str:
    """Which end of ``arc`` (of seam ``sid``) the segment starting at plan time t [s] lies at: "start" (the move into
    it, its approach: before its first weld), "end" (its depart, the move home after it: after its last weld), ""
    (its weld)."""
    welds = [s for s in plan.segments if s.seam_id == sid and s.arc_on and arc.t0 - 1e-9 <= s.t0 < arc.t1]
    if not welds or t < welds[0].t0 - 1e-9:
        return "start"
    return "end" if t >= welds[-1].t1 - 1e-9 else ""


def _segment_at(plan: WeldPlan, t: float) -> Segment:
    """The segment running at plan time t [s] (the earlier one at a join)."""
    t0 = np.array([s.t0 for s in plan.segments])
    k = int(np.clip(np.searchsorted(t0, t, side="left") - 1, 0, len(t0) - 1))
    return plan.segments[k]


def incoming(plan: WeldPlan, violations: Sequence[Violation]) -> dict[str, tuple[str, str]]:
    """Seam id -> the transfer into it, (the seam before it in the plan's order or "" for home, itself), for each
    seam whose first violation lies on that move or on its approach (before its first arc: the move blended into
    the approach is motion the seam's own search never checked, so another order may weld it)."""
    out: dict[str, tuple[str, str]] = {}
    seen: set[str] = set()
    for v in violations:
        sid = seam_of(plan, v)
        if not sid or sid in seen:
            continue
        seen.add(sid)
        seg = _segment_at(plan, v.t)
        if seg.seam_id != sid or seg.kind not in ("move", "approach") or sid not in plan.order:
            continue
        at = next(i for i, s in enumerate(plan.segments) if s is seg)
        before = [s for s in plan.segments[:at] if s.seam_id == sid and s.arc_on]
        k = plan.order.index(sid)
        if before:
            continue  # past its first arc (a pass, a curve's next arc): not the move into the seam
        out[sid] = (plan.order[k - 1] if k else "", sid)
    return out
