"""The close-up re-scan's figures in a report (docs/report.md): per seam its re-scan and its errors before, and at
the top the re-scan's counts, robot time and the summary before (``cell weld`` and ``cell rescan`` reports)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from cell.export.reports.report_values import metrics_entry, rounded
from cell.pipeline.records import Detection
from cell.types import Rescan, SeamRecord


def add_rescan(rep: dict[str, Any], records: Sequence[SeamRecord], first: Detection | None, rs: Rescan | None) -> None:
    """Before/after figures of the close-up re-scan: per seam ``rescan`` and ``error_mm_before``, and at the top
    ``rescan`` (counts, robot time) and ``summary_before_rescan``."""
    if rs is None or first is None:
        rep["rescan"] = None
        return
    by_id = {rec.id: rec for rec in records}
    for entry in rep["seams"]:
        rec = by_id.get(entry["id"])  # none for a seam the cell cannot weld
        r = rec.rescan if rec is not None else None
        if rec is None or r is None:
            continue
        if rec.first_metrics is not None:
            entry["error_mm_before"] = metrics_entry(rec.first_metrics)
        entry["rescan"] = {
            "used": r.used,
            "weight": rounded(r.weight, 3),
            "reason": r.reason,
            "confidence_before": rounded(r.before.confidence, 4),
            "view_distance_m": rounded(r.viewpoint.distance_m, 4) if r.viewpoint is not None else None,
            "points": r.points,
        }
    s = first.summary
    rep["summary_before_rescan"] = {
        "found": s.found,
        "paper_me_mean_mm": rounded(s.paper_me_mean_mm, 4),
        "endpoint_mean_mm": rounded(s.endpoint_mean_mm, 4),
        "lateral_mean_mm": rounded(s.lateral_mean_mm, 4),
    }
    rep["rescan"] = {
        "seams": len(rs.seams),
        "used": sum(r.used for r in rs.seams),
        "motion_s": rounded(rs.motion_s, 3),
        "returned_to_scan_pose": rs.returned,
        "note": rs.note,
        "escalated_mm": rounded(rs.escalated_mm, 3),
    }
