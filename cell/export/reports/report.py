"""JSON reports: the contract other tools read (docs/report.md). Metres inside, millimetres only where named _mm."""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

from cell.export.reports.curve_report import add_curve_rescan, curve_summary, not_welded_entries, weld_reason_code
from cell.export.reports.procedure_report import procedure_entry, tcp_error_entry
from cell.export.reports.report_values import error_entry, metrics_entry, point, rounded
from cell.export.reports.rescan_figures import add_rescan
from cell.outputs import write_atomic
from cell.pipeline.records import Detection, WeldRun
from cell.types import Rescan, SeamRecord, SeamStatus, UnsupportedSeam, Violation
from cell.types.rescan import PlannedCloseup

REPORT_VERSION = 1


def _seam_entry(rec: SeamRecord) -> dict[str, Any]:
    """A seam's detection fields: status and reason (text and code), the located segment, truth and errors."""
    est = rec.estimate
    entry: dict[str, Any] = {
        "id": rec.id,
        "status": est.status.value,
        "reason": est.reason,
        "reason_code": est.code.value if est.code is not None else None,
    }
    if est.status is SeamStatus.FOUND:
        entry["detected"] = {"start": point(est.p_start), "end": point(est.p_end)}
        entry["confidence"] = rounded(est.confidence, 4)
        entry["sigma_mm"] = rounded(est.sigma_m * 1000.0, 4)
        entry["end_sigma_mm"] = [rounded(v * 1000.0, 4) for v in est.end_sigma_m]
        entry["end_source"] = [k.value for k in est.end_source]
    if rec.truth is not None:  # none when the station knows no truth (real data)
        entry["truth"] = {"start": point(rec.truth[0]), "end": point(rec.truth[1])}
    if rec.metrics is not None:
        entry["error_mm"] = metrics_entry(rec.metrics)
    entry["time_ms"] = rounded(est.time_s * 1000.0, 3)
    return entry


def not_supported(not_welded: Sequence[UnsupportedSeam]) -> dict[str, int]:
    """The map's seams the run does not weld, counted by reason code (``curved_not_located``: 1), in code order."""
    codes = [u.code.value for u in not_welded]
    return {c: codes.count(c) for c in sorted(set(codes))}


def detection_report(
    det: Detection,
    records: Sequence[SeamRecord] | None = None,
    *,
    provenance: Mapping[str, Any] | None = None,
    unsupported: bool = True,
) -> dict[str, Any]:
    """The ``cell detect`` report as a JSON-ready dict (schema in docs/report.md), one entry per seam record,
    then (``unsupported``) one per seam of the map the cell cannot weld (status ``not_supported``).

    provenance : what made it (:func:`cell.provenance.provenance`), stored under ``provenance`` (null if None).

    ``frame`` names the frame of every point and pose of the report: ``R`` (the robot base) for a scenario's run,
    the cloud's own frame for a brought cloud (``cell locate``: ``F`` unless ``--frame`` says otherwise). Without
    ground truth (real data) the seams have no ``truth`` or ``error_mm`` and the summary's errors are null."""
    seams = [_seam_entry(rec) for rec in (records if records is not None else det.records())]
    if unsupported:
        seams += not_welded_entries(det)
    s = det.summary
    summary = {
        "seams": len(det.estimates) + len(det.weldmap_R.not_straight),  # every seam of the map
        "not_supported": not_supported([u for u in det.not_welded if u.id not in det.curve_welds]),
        "curved": curve_summary(det),
        "visible": sum(e.status is not SeamStatus.NOT_VISIBLE for e in det.estimates),
        "found": s.found,
        "paper_me_mean_mm": rounded(s.paper_me_mean_mm, 4),
        "paper_me_p95_mm": rounded(s.paper_me_p95_mm, 4),
        "endpoint_mean_mm": rounded(s.endpoint_mean_mm, 4),
        "lateral_mean_mm": rounded(s.lateral_mean_mm, 4),
        "time_ms_per_seam_median": rounded(s.time_ms_per_seam_median, 3),
    }
    return {
        "report_version": REPORT_VERSION,
        "provenance": dict(provenance) if provenance is not None else None,
        "scenario": det.scenario.name,
        "method": det.method,
        "source": det.source,
        # The sensor noise this run simulated: none was simulated for a replayed capture or a brought cloud.
        "noise": det.scenario.noise if det.source == "simulation" else None,
        "frame": det.weldmap_R.frame,
        "units": "m",
        "X_WR": [[rounded(v, 9) for v in row] for row in det.scenario.X_WR],
        "lost_cameras": list(det.lost_cameras),
        # Per registered camera: the splice's correction of its calibration, applied or refused and why.
        "splice": det.scene.perceived.splice_corrections() if det.scene is not None else None,
        # Per camera: its depth scale and focal length checked on the table in this run's own image.
        "camera_checks": _camera_checks(det),
        "seams": seams,
        "summary": summary,
        "timings_s": {k: rounded(v, 4) for k, v in det.timings.items()},
        "error": error_entry(det.error),
        # What ran: the whole scenario as resolved (every default filled in, the --method/--noise/--rescan
        # overrides applied), so a report says exactly which configuration produced it.
        "config": det.scenario.model_dump(mode="json"),
    }


def _closeup_plan(c: PlannedCloseup) -> dict[str, Any]:
    """A preview's planned close-up of one seam: ``planned``, the camera's place ``eye`` in R [m], ``distance_mm``,
    ``incidence_deg`` on face A and B; or the seam whose close-up serves it (``served_by``); or why none works."""
    vp = c.viewpoint
    return {
        "planned": c.planned,
        "eye": point(vp.X_RC[:3, 3]) if vp is not None else None,
        "distance_mm": rounded(vp.distance_m * 1000.0, 1) if vp is not None else None,
        "incidence_deg": [rounded(a, 1) for a in vp.incidence_deg] if vp is not None else None,
        "served_by": c.served_by or None,
        "reason": c.reason,
    }


STDOUT = "-"  # the path that means standard output


def write_json(path: str | Path, data: Mapping[str, Any] | list[Any]) -> Path:
    """Write JSON whole (a crash never leaves half a report: :mod:`cell.outputs`) into an existing folder;
    ``-`` writes it to standard output. OutputError (one line) when the file cannot be written."""
    text = json.dumps(data, indent=2) + "\n"
    if str(path) == STDOUT:
        sys.stdout.write(text)
        sys.stdout.flush()
        return Path(STDOUT)
    return write_atomic(path, text.encode("utf-8"), what="report")


def violation_entry(v: Violation) -> dict[str, Any]:
    """One violation of the safety gate: its ``code`` (the kind), the ``detail`` line, where (``t_s``, ``joint``,
    ``seam``, ``body``: "" when the check does not say) and by how much (``excess``, in the kind's SI unit)."""
    return {
        "code": v.kind.value,
        "detail": str(v),
        "t_s": rounded(v.t, 4),
        "joint": v.joint,
        "seam": v.seam_id,
        "body": v.body,
        "excess": rounded(v.excess, 6),
    }


def weld_report(run: WeldRun, *, provenance: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The ``cell weld`` / ``cell preview`` report: the detection report plus, per seam, ``welded``, ``reason``,
    ``tcp_error_mm`` {rms, max, short_start, short_end, past_start, past_end} of the executed tool path against the
    true seam and ``weld_time_s``; at the top, ``cycle_time_s``, ``events``, the gate's ``violations`` and the
    ``error`` that stopped the run (or null)."""
    records = run.records()
    rep = detection_report(run.detection, records, provenance=provenance)
    plan = run.plan
    for entry in rep["seams"][len(records) :]:  # the map's seams the cell cannot weld, the curves
        if "welded" in entry:  # a curve the run tried: its weld's own fields
            continue
        why = entry.get("not_welded", {}).get("reason", entry["reason"])
        entry.update(planned=False, welded=False, weld_reason=why, weld_reason_code=weld_reason_code(entry))
    for entry, rec in zip(rep["seams"], records, strict=False):
        w = rec.weld
        if w is None:
            raise ValueError(f"seam {rec.id}: a weld run without a weld record")
        entry["planned"] = w.planned
        entry["welded"] = w.welded
        if not w.welded:
            # The detection's reason says why a seam was not found; the weld's why it was not welded.
            entry["weld_reason"] = w.reason
            entry["weld_reason_code"] = w.code.value if w.code is not None else None
            if w.check is not None:  # the last check before the arc: which test, by how much
                c = w.check
                entry["last_check"] = {
                    "code": c.code.value,
                    "end": c.end,
                    "part": c.part,
                    "value_mm": rounded(c.value_m * 1000.0, 3),
                    "limit_mm": rounded(c.limit_m * 1000.0, 3),
                }
        o = rec.outcome
        if o is not None and o.feasible:
            entry["torch"] = {
                "work_angle_deg": rounded(math.degrees(o.work_angle), 2),
                "travel_angle_deg": rounded(math.degrees(o.travel_angle), 2),
                "spin_deg": rounded(math.degrees(o.spin), 2),
                "reversed": o.reversed,
            }
            entry["trimmed_mm"] = rounded(o.trimmed * 1000.0, 2)  # not welded at the table end (the stand-off)
        elif o is not None:
            entry["plan_reason_code"] = o.code.value if o.code is not None else None
            if o.p_fail.size == 3:
                entry["failing_point"] = point(o.p_fail)
        if w.quality is not None:
            q = w.quality
            entry["tcp_error_mm"] = tcp_error_entry(q)
            entry["weld_time_s"] = rounded(q.weld_time_s, 3)
            entry["travel_speed_mm_s"] = rounded(q.speed_mm_s, 4)
        entry.update(procedure_entry(w))  # the weld procedure it got and the bead per pass
    add_rescan(rep, records, run.first_detection, run.rescan)
    planned = {c.seam_id: c for c in run.closeups}
    for entry in rep["seams"]:
        if entry["id"] in planned:
            entry["closeup_plan"] = _closeup_plan(planned[entry["id"]])
    ex = run.execution
    rep["welded"] = sum(w.welded for w in run.seams) + rep["summary"]["curved"]["welded"]
    rep["cycle_time_s"] = rounded(run.cycle_time_s, 3)
    rep["planned_cycle_time_s"] = (
        rounded(plan.cycle_time + (run.pre_move.duration if run.pre_move is not None else 0.0), 3) if plan else None
    )
    rep["arc_time_s"] = rounded(ex.arc_time, 3) if ex is not None else None
    rep["weld_order"] = list(plan.order) if plan is not None else []
    # How far each axis travels over the plan (A6: the hose package's wind-up), [deg].
    rep["joint_range_deg"] = (
        {n: [rounded(math.degrees(lo), 2), rounded(math.degrees(hi), 2)] for n, (lo, hi) in plan.joint_ranges().items()}
        if plan is not None
        else None
    )
    rep["events"] = [{"t_s": rounded(e.t, 4), "kind": e.kind, "detail": e.detail} for e in ex.events] if ex else []
    rep["violations"] = [violation_entry(v) for v in run.violations]
    rep["error"] = error_entry(run.error)
    rep["timings_s"] = {k: rounded(v, 4) for k, v in run.timings.items()}
    return rep


def rescan_report(
    before: Detection, after: Detection, rs: Rescan, *, provenance: Mapping[str, Any] | None = None
) -> dict[str, Any]:
    """The ``cell rescan`` report: the detection report of the fused estimates, with the figures before."""
    rescans = {r.id: r for r in rs.seams}
    records = [
        replace(rec, first=rescans[rec.id].before, first_metrics=before.metrics.get(rec.id), rescan=rescans[rec.id])
        for rec in after.records()
        if rec.id in rescans
    ]
    rep = detection_report(after, records, provenance=provenance, unsupported=False)
    add_rescan(rep, records, before, rs)
    add_curve_rescan(rep, before, after, rs)  # every curved seam: re-scanned, or why not
    return rep


def _camera_checks(det: Detection) -> dict[str, dict[str, Any]] | None:
    if det.scene is None:
        return None
    return {
        name: {
            "table_pixels": c.pixels,
            "depth_scale": rounded(c.depth_scale, 5),
            "depth_scale_sigma": rounded(c.depth_scale_sigma, 5),
            "focal_scale": rounded(c.focal_scale, 5),
            "focal_scale_sigma": rounded(c.focal_scale_sigma, 5),
            "flags": list(c.flags),
        }
        for name, c in det.scene.perceived.sensor_checks.items()
    }
