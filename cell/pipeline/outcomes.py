"""What became of every seam of a weld run: welded with its quality against the true seam, or why not; whether a
found seam is too uncertain to weld; the planned torch paths for pictures and reports. Values in, values out."""

from __future__ import annotations

from collections.abc import Collection, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from cell.geometry import FloatArray, invert, transform_points
from cell.pipeline.records import Detection
from cell.rescan.fusion import ends_within_tolerance, within_tolerance
from cell.scenario import Scenario
from cell.station import Station
from cell.types import CheckFail, SeamEstimate, SeamStatus
from cell.types.run import SeamWeld, WeldReason

if TYPE_CHECKING:
    from cell.types.curve_estimate import CurveEstimate
    from cell.types.execution import Execution, WeldQuality
    from cell.types.plan import SeamTask, Segment, WeldPlan


@dataclass(frozen=True)
class Doubt:
    """Why a found seam is too uncertain to weld: ``code`` (``low_confidence`` or ``end_uncertain``) and the
    ``detail`` for people (which bound, by how much against what)."""

    code: WeldReason
    detail: str


def doubt(est: SeamEstimate, sc: Scenario) -> Doubt | None:
    """Why a found seam is too uncertain to weld (None when it may be welded): its bound (``rescan.bound_sigmas``
    times its calibrated sigma) over ``rescan.weld_tolerance_mm``, its confidence under
    ``rescan.weld_min_confidence`` (both ``low_confidence``), or an end's bound over ``rescan.end_tolerance_mm``
    (:func:`end_doubt`)."""
    r = sc.rescan
    if not within_tolerance(est, r.max_sigma_m):
        bound_mm = r.bound_sigmas * est.sigma_m * 1000.0
        why = f"bound {r.bound_sigmas:g} sigma = {bound_mm:.2f} mm > weld tolerance {r.weld_tolerance_mm:g} mm"
        return Doubt(WeldReason.LOW_CONFIDENCE, why)
    if est.confidence < r.weld_min_confidence:
        return Doubt(WeldReason.LOW_CONFIDENCE, f"confidence {est.confidence:.2f} < {r.weld_min_confidence:.2f}")
    return end_doubt(est, sc)


def end_doubt(est: SeamEstimate, sc: Scenario) -> Doubt | None:
    """Why a found seam's ends are too uncertain to weld (``end_uncertain``; None when they are not): an end's
    bound along the seam (``rescan.bound_sigmas`` times its sigma) over ``rescan.end_tolerance_mm``."""
    r = sc.rescan
    if ends_within_tolerance(est, r.max_end_sigma_m):
        return None
    bounds = ", ".join(f"{r.bound_sigmas * s * 1000.0:.2f}" for s in est.end_sigma_m)
    where = "/".join(str(k) for k in est.end_source)
    why = f"end bound {r.bound_sigmas:g} sigma = {bounds} mm ({where}) > end tolerance {r.end_tolerance_mm:g} mm"
    return Doubt(WeldReason.END_UNCERTAIN, why)


def seam_welds(
    det: Detection,
    plan: WeldPlan | None,
    ex: Execution | None,
    pre_s: float,
    refused: str,
    sc: Scenario,
    gated: bool,
    unplaceable: Collection[str] = (),
    checked: Mapping[str, CheckFail] | None = None,
) -> tuple[SeamWeld, ...]:
    """Per seam: welded (with its quality against the true seam) or the reason it was not. gated : the weld gate
    applied (not a preview): a found seam too uncertain to weld is ``low_confidence``, but one no torch can be
    placed on (``unplaceable``: planned anyway) gets the planner's reason. checked : the seams that failed the
    last check before the arc (``last_check``, with the test)."""
    from cell.planning.tasks import seam_tasks
    from cell.process.quality import combined, weld_quality

    X_RW = invert(det.scenario.X_WR)
    ss = det.scene.seam_scene if det.scene is not None else None
    found = [e for e in det.estimates if e.status is SeamStatus.FOUND]
    tasks = {t.id: t for t in seam_tasks(found, ss.weldmap, ss.joints, ss.table_z)} if ss is not None else {}
    out = []
    for est in det.estimates:
        if est.status is SeamStatus.NOT_VISIBLE:
            out.append(SeamWeld(est.id, False, False, est.reason, code=WeldReason.NOT_VISIBLE))  # against the table
            continue
        if est.status is not SeamStatus.FOUND:
            why = f"not located ({est.status.value}): {est.reason}"
            out.append(SeamWeld(est.id, False, False, why, code=WeldReason.NOT_LOCATED))
            continue
        doubtful = doubt(est, sc)
        if doubtful is not None and gated and est.id not in unplaceable:
            why = f"{doubtful.code.value}: {doubtful.detail}"
            out.append(SeamWeld(est.id, False, False, why, code=doubtful.code))
            continue
        fail = (checked or {}).get(est.id)
        if fail is not None:
            why = f"last_check: {fail.describe()}"
            out.append(SeamWeld(est.id, False, False, why, code=WeldReason.LAST_CHECK, check=fail))
            continue
        outcome = next((o for o in plan.seams if o.seam_id == est.id), None) if plan is not None else None
        if outcome is None or not outcome.feasible:
            reason = outcome.reason if outcome is not None else refused or "not planned"
            code = WeldReason.NOT_EXECUTED if outcome is None and refused else WeldReason.NOT_PLANNED
            out.append(SeamWeld(est.id, False, False, reason, code=code))
            continue
        welds = [g for g in plan.segments if g.arc_on and g.seam_id == est.id] if plan is not None else []
        if ex is None or plan is None:
            note = f"; {doubtful.detail}: would be re-scanned before welding" if doubtful is not None else ""
            code = WeldReason.NOT_EXECUTED if refused else WeldReason.PREVIEW
            why = (refused or "planned, not executed (preview)") + note
            proc = welds[0].procedure if welds else None
            out.append(SeamWeld(est.id, True, False, why, code=code, procedure=proc))
            continue
        truth = det.truths.get(est.id)  # none on a station that knows no truth: welded, quality unmeasured
        passes = []
        for seg in welds:
            if truth is None:
                break
            t0, t1 = pre_s + seg.t0, pre_s + seg.t1
            k = np.flatnonzero((ex.times >= t0 - 1e-9) & (ex.times <= t1 + 1e-9))
            tcp_R = transform_points(X_RW, ex.tcp_W[k])
            offsets = _intended(tasks.get(est.id), outcome.reversed, seg, tcp_R)
            passes.append(weld_quality(ex.times[k], tcp_R, truth[0], truth[1], offsets))
        quality = combined(passes) if passes else None
        out.append(SeamWeld(est.id, True, True, "", quality, procedure=welds[0].procedure, passes=tuple(passes)))
    return tuple(out)


def _intended(task: SeamTask | None, reversed_: bool, seg: Segment, tcp_R: FloatArray) -> FloatArray | None:
    """Where the plan meant each TCP record of a weld segment to lie off the seam (its pass's offset and the
    weave), from the planned seam (None without a procedure or a task: on the seam line)."""
    from cell.process.weave import cross_section, intended_offsets

    if seg.procedure is None or task is None:
        return None
    a, b = (task.p_end, task.p_start) if reversed_ else (task.p_start, task.p_end)
    d = (b - a) / task.length
    e_R, b_R = cross_section(d, task.n_a, task.n_b)
    return intended_offsets(tcp_R, a, d, task.length, seg.procedure, seg.pass_index, e_R, b_R)


def curve_welds(
    plan: WeldPlan,
    ex: Execution | None,
    pre_s: float,
    truths_R: Mapping[str, FloatArray],
    closed: Mapping[str, bool],
    X_WR: FloatArray,
    estimates: Mapping[str, CurveEstimate] | None = None,
) -> dict[str, WeldQuality]:
    """Curved seam id -> its weld measured against its true curve (:func:`cell.process.curve_quality.
    curve_weld_quality`) on the records while its arc burned, for every welded curved seam (``closed``: seam id ->
    a full loop) with a truth (in R), all passes together; a pass off the root against the true curve moved by its
    offset (:func:`cell.process.curve_quality.pass_truth`, the cross-section from ``estimates``: seam id -> its
    located curve). Empty without an execution. pre_s [s]: the move before the plan."""
    from cell.process.curve_quality import curve_weld_quality, pass_truth
    from cell.process.quality import combined

    if ex is None:
        return {}
    X_RW = invert(np.asarray(X_WR, dtype=float))
    out: dict[str, WeldQuality] = {}
    for sid, is_closed in closed.items():
        welds = [g for g in plan.segments if g.arc_on and g.seam_id == sid]
        truth = truths_R.get(sid)
        if not welds or truth is None:
            continue
        passes = []
        for k in sorted({g.pass_index for g in welds}):
            on = np.zeros(len(ex.times), dtype=bool)  # the records of its welds (arcs of a split seam: not the air)
            for g in (g for g in welds if g.pass_index == k):
                on |= (ex.times >= pre_s + g.t0 - 1e-9) & (ex.times <= pre_s + g.t1 + 1e-9)
            i = np.flatnonzero(on)
            proc, est = welds[0].procedure, (estimates or {}).get(sid)
            aim = truth
            if k and proc is not None and est is not None:
                lat, lift = proc.passes[k].lateral_mm / 1000.0, proc.passes[k].lift_mm / 1000.0
                aim = pass_truth(truth, est.p_RS, est.n_abutting_R, est.n_receiving_R, lat, lift)
            passes.append(curve_weld_quality(ex.times[i], transform_points(X_RW, ex.tcp_W[i]), aim, is_closed))
        out[sid] = combined(passes)
    return out


def torch_paths(station: Station, plan: WeldPlan, step_s: float = 0.5) -> dict[str, FloatArray]:
    """Planned torch poses X_RT (n, 4, 4) along each weld (its passes in order), every ``step_s`` of arc time (for
    pictures and reports)."""
    if station.arm is None:
        return {}
    model = station.arm.model
    out: dict[str, FloatArray] = {}
    for seg in plan.segments:
        if seg.arc_on:
            tr = seg.trajectory
            k = np.unique(np.r_[np.searchsorted(tr.times, np.arange(0.0, tr.duration, step_s)), len(tr.times) - 1])
            poses = np.stack([model.fk(tr.q[i]) for i in k])
            if plan.track is not None:  # the base where the track put it (poses in R: the base at E1 = 0)
                poses[:, :3, 3] += plan.track.offset_R(seg.e1_end)
            prev = out.get(seg.seam_id)  # a multi-pass seam: its passes one after the other
            out[seg.seam_id] = poses if prev is None else np.concatenate([prev, poses])
    return out
