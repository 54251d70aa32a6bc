"""The report of a part welded on a positioner (docs/positioner.md, "Report"): per seam its pose, its ISO 6947
position (``weld_position``: code, slope and rotation, the worst over its waypoints, and whether within the
tolerance), welded or why not, the TCP against the truth; per pose the axes and times; the job's totals."""

from __future__ import annotations

import math
from typing import Any

from cell.coordinated.record import CoordinatedWeld
from cell.export.reports.curve_report import remainder_entry
from cell.geometry import FloatArray, invert
from cell.pipeline.positioned.run import PositionerRun
from cell.types import SeamEstimate, WeldReason
from cell.types.curve_estimate import CurveEstimate
from cell.types.execution import WeldQuality
from cell.types.run import SeamWeld


def _r(v: float, d: int = 3) -> float | None:
    return round(v, d) if math.isfinite(v) else None


def _code(run: PositionerRun, seam_id: str, w: SeamWeld | None) -> str | None:
    """Why a seam was not welded, as a code (None: welded)."""
    if w is not None:
        return None if w.welded else (w.code or WeldReason.NOT_PLANNED).value
    return (run.unheld_codes.get(seam_id) or WeldReason.NOT_PLANNED).value


def positioner_report(run: PositionerRun) -> dict[str, Any]:
    """The report as a JSON-ready dict (mm, deg, s)."""
    welds = run.welds()
    pose_of: dict[str, int] = {}
    position: dict[str, dict[str, Any]] = {}
    for k, g in enumerate(run.groups):
        for i, wp in g.pose.positions.items():
            pose_of[i], position[i] = (
                k,
                {
                    "code": wp.code,
                    "target": wp.target,
                    "slope_deg": _r(wp.slope_deg),
                    "rotation_deg": _r(wp.rotation_deg),
                    "within_tolerance": wp.within,
                },
            )
    seams: list[dict[str, Any]] = []
    tcp: list[float] = []
    found: list[SeamEstimate | CurveEstimate] = [*run.detection.estimates, *run.detection.curve_estimates]
    X_MR = invert(run.detection.scene.X_RM) if run.detection.scene is not None else None
    for e in found:
        w = welds.get(e.id)
        q = w.quality if w is not None else None
        if q is not None:
            tcp.append(q.tcp_max_mm)
        seams.append(
            {
                "id": e.id,
                "located": e.status.value,
                "pose": pose_of.get(e.id),
                "weld_position": position.get(e.id),
                "welded": bool(w is not None and w.welded),
                "reason": (w.reason if w is not None and not w.welded else run.unheld.get(e.id, "")),
                "reason_code": _code(run, e.id, w),
                "tcp_max_mm": _r(q.tcp_max_mm) if q is not None else None,
                "tcp_rms_mm": _r(q.tcp_rms_mm) if q is not None else None,
            }
            | (_in_part(w, e, X_MR) if w is not None and w.partial else {})
            | ({"arcs": [_tcp(a) for a in w.arc_quality]} if w is not None and w.arc_quality else {})
        )
    poses = [
        {
            "tilt_deg": _r(math.degrees(g.pose.tilt)),
            "rotate_deg": _r(math.degrees(g.pose.rotate)),
            "seams": list(g.pose.seams),
            "move_s": _r(g.move_s),
            "robot_s": _r(g.robot_s),
            "plan_wall_s": _r(g.plan_wall_s),
            "error": g.error.message if g.error is not None else None,
        }
        for g in run.groups
    ]
    return {
        "scenario": run.detection.scenario.name,
        "seams": seams,
        "poses": poses,
        "totals": {
            "seams": len(seams),
            "located": run.located(),
            "welded": run.welded,
            "operator_turns": 0,
            "cycle_time_s": _r(run.cycle_time_s),
            "positioner_s": _r(run.positioner_s),
            "rescan_s": _r(run.rescan_s),
            "tcp_max_mm": _r(max(tcp, default=math.nan)),
            "partial": sum(w.partial and w.planned for w in welds.values()),
            "manual_mm": _r(sum(w.manual_m for w in welds.values()) * 1000.0, 1),
        },
        "coordinated": [coordinated_entry(cw) for cw in run.coordinated],
        "error": run.error.message if run.error is not None else None,
        "timings": {k: _r(v) for k, v in run.timings.items()},
    }


def _tcp(q: WeldQuality) -> dict[str, Any]:
    """One coordinated arc of a seam welded in several: its TCP against the true curve [mm]."""
    return {"tcp_rms_mm": _r(q.tcp_rms_mm), "tcp_max_mm": _r(q.tcp_max_mm)}


def _in_part(w: SeamWeld, e: SeamEstimate | CurveEstimate, X_MR: FloatArray | None) -> dict[str, Any]:
    """A curved seam welded in part: the ``share`` welded, ``manual_mm`` left for a manual weld and each stretch of
    its ``remainder``, its ends on the drawing (as the fixed arm's report: :func:`.curve_report.remainder_entry`)."""
    est = e if isinstance(e, CurveEstimate) else None
    return {
        "share": _r(w.share, 4),
        "manual_mm": _r(w.manual_m * 1000.0, 1),
        "remainder": [remainder_entry(r, est, X_MR) for r in w.remainder],
    }


def coordinated_entry(cw: CoordinatedWeld) -> dict[str, Any]:
    """A curved seam welded with the rotate axis turning: its times, axes' sweep, the torch's spread and every
    knot's ISO 6947 slope and rotation (mm, deg, s)."""
    deg = lambda a: [round(math.degrees(float(v)), 3) for v in a]  # noqa: E731
    return {
        "id": cw.seam_id,
        "arc_s": _r(cw.arc_s),
        "job_s": _r(cw.duration),
        "plan_wall_s": _r(cw.plan_s),
        "speed_mm_s": _r(cw.speed * 1000.0),
        "tilt_deg": _r(math.degrees(float(cw.knot_axes[0, 0]))),
        "tilt_range_deg": deg((cw.knot_axes[:, 0].min(), cw.knot_axes[:, 0].max())),
        "rotate_deg": deg((cw.knot_axes[0, 1], cw.knot_axes[-1, 1])),
        "torch_spread_mm": _r(cw.tcp_spread_mm),
        "in_position": cw.in_position,
        "closed": cw.closed,
        "span_mm": None if cw.span_m is None else [_r(v * 1000.0, 1) for v in cw.span_m],  # welded in part: its stretch
        "waypoints": {
            "s_mm": [round(float(v) * 1000.0, 2) for v in cw.s],
            "slope_deg": [round(float(v), 3) for v in cw.slope_deg],
            "rotation_deg": [round(float(v), 3) for v in cw.rotation_deg],
        },
    }
