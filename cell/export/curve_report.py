"""The report's entries for the map's seams a run does not weld: a curved seam with what its locator found (the
located curve's sigmas, its error against the true curve in simulation) and why it is not welded; any other with
its reason (docs/report.md). Millimetres where named _mm."""

from __future__ import annotations

import math
from typing import Any

from cell.pipeline.records import Detection
from cell.types import SeamStatus, Unsupported, UnsupportedSeam
from cell.types.curve_estimate import CurveEstimate, CurveMetrics
from cell.types.run import WeldReason


def _r(v: float, nd: int = 4) -> float | None:
    return None if not math.isfinite(v) else round(float(v), nd)


def unsupported_entry(u: UnsupportedSeam) -> dict[str, Any]:
    """A seam the map draws that the cell cannot weld: never searched, with why as text and as a code."""
    return {"id": u.id, "status": SeamStatus.NOT_SUPPORTED.value, "reason": u.reason, "reason_code": u.code.value}


def curve_entry(u: UnsupportedSeam, est: CurveEstimate, m: CurveMetrics | None) -> dict[str, Any]:
    """A curved seam: its locator's status and reason, the located curve's figures when found, its error against
    the true curve (``error_mm``, simulation) and why it is not welded (``not_welded``: code and reason)."""
    entry: dict[str, Any] = {
        "id": est.id,
        "curved": True,
        "status": est.status.value,
        "reason": est.reason if est.status is not SeamStatus.FOUND else u.reason,
        # Never searched (no joint, no round body, another method): the map's code, as for any seam not supported.
        "reason_code": u.code.value if est.status is SeamStatus.NOT_SUPPORTED or est.code is None else est.code.value,
    }
    if est.status is SeamStatus.FOUND:
        entry["curve"] = {
            "closed": est.closed,
            "samples": len(est.p_RS),
            "length_mm": _r(est.length_m * 1000.0, 2),
            "sigma_max_mm": _r(est.sigma_max_m * 1000.0),
            "end_sigma_mm": None if est.closed else [_r(v * 1000.0) for v in est.end_sigma_m],
            # The samples in the report's frame [m], about 1 mm apart, start to end, and each one's sigma [mm].
            "points": [[_r(float(v), 7) for v in p] for p in est.p_RS],
            "sigma_mm": [_r(float(v) * 1000.0) for v in est.sigma_m],
        }
        entry["confidence"] = _r(est.confidence)
    if m is not None:
        entry["error_mm"] = {"rms": _r(m.rms_mm), "max": _r(m.max_mm), "within_2sigma": _r(m.within_2sigma, 3)}
    entry["time_ms"] = _r(est.time_s * 1000.0, 3)
    entry["not_welded"] = {"code": u.code.value, "reason": u.reason}
    return entry


def not_welded_entries(det: Detection) -> list[dict[str, Any]]:
    """One entry per seam of the map the run does not weld (:attr:`Detection.not_welded`), in its order."""
    curves = {e.id: e for e in det.curve_estimates}
    return [
        curve_entry(u, curves[u.id], det.curve_metrics.get(u.id)) if u.id in curves else unsupported_entry(u)
        for u in det.not_welded
    ]


def curve_summary(det: Detection) -> dict[str, Any]:
    """The curved seams at a glance: how many, found, and the largest RMS and max error over the found ones [mm]."""
    found = [e for e in det.curve_estimates if e.status is SeamStatus.FOUND]
    ms = [det.curve_metrics[e.id] for e in found if e.id in det.curve_metrics]
    return {
        "seams": len(det.weldmap_R.curved),
        "found": len(found),
        "welded": 0,
        "rms_max_mm": _r(max((m.rms_mm for m in ms), default=math.nan)),
        "max_mm": _r(max((m.max_mm for m in ms), default=math.nan)),
    }


def weld_reason_code(entry: dict[str, Any]) -> str:
    """Why a seam the run does not weld was not welded, as a code: a located curve has no torch path yet."""
    code = entry.get("not_welded", {}).get("code")
    return (WeldReason.NO_TORCH_PATH if code == Unsupported.CURVED_NO_TORCH_PATH else WeldReason.NOT_SUPPORTED).value
