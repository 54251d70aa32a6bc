"""The trust benchmark's figures for curved seams (a tube's fillet on a plate, a saddle), read from the report's
curved entries (``"curved": true``, :mod:`cell.export.reports.curve_report`) as a plain dict.

Per curved seam (:func:`curve_record`): what became of it; for a located one its error against the true curve over
its length (RMS and max) and the share of its samples within two of their own sigmas, as the report states them;
for a weld its TCP max error. Over many (:func:`curve_figures`): how many were located, the error distributions,
the share of samples within 2 sigma and the share of curves wholly within it, what was welded and why the rest was
not. A figure the report does not give is None, never a guess. Millimetres, as in the report.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

Row = dict[str, Any]
WHOLE = 1.0  # a curve is wholly within 2 sigma when this share of its samples is


def _share(count: int, of: int) -> float | None:
    return round(count / of, 4) if of else None


def _distribution(values: Sequence[float]) -> Row:
    v = np.asarray(values, float)
    if v.size == 0:
        return {"n": 0, "median": None, "max": None}
    return {"n": int(v.size), "median": round(float(np.median(v)), 4), "max": round(float(v.max()), 4)}


def curve_record(entry: Mapping[str, Any], *, weld_report: bool) -> Row:
    """One curved seam of a report, compact (see the module docstring)."""
    located = entry["status"] == "found"
    err = (entry.get("error_mm") or {}) if located else {}
    rec: Row = {
        "id": entry["id"],
        "curved": True,
        "status": entry["status"],
        "reason_code": entry.get("reason_code"),
        "visible": entry["status"] not in ("not_visible", "not_supported"),
        "located": located,
        "rms_mm": err.get("rms"),
        "max_mm": err.get("max"),
        "within_2sigma": err.get("within_2sigma"),
        "sigma_max_mm": (entry.get("curve") or {}).get("sigma_max_mm") if located else None,
    }
    if weld_report:
        tcp = entry.get("tcp_error_mm")
        rec["welded"] = bool(entry.get("welded"))
        rec["weld_reason_code"] = entry.get("weld_reason_code") or (entry.get("not_welded") or {}).get("code")
        rec["tcp_max_mm"] = tcp.get("max") if tcp else None
        rec["manual_mm"] = entry.get("manual_mm")  # a curve welded in part: the length left for a manual weld
    return rec


def curve_figures(curves: Sequence[Row], stage: str) -> Row:
    """The figures of a set of curved-seam records (one cell's or every cell's)."""
    visible = [c for c in curves if c["visible"]]
    located = [c for c in visible if c["located"]]
    measured = [c for c in located if c["max_mm"] is not None]
    shares = [float(c["within_2sigma"]) for c in measured if c["within_2sigma"] is not None]
    out: Row = {
        "seams": len(curves),
        "visible": len(visible),
        "located": len(located),
        "located_share": _share(len(located), len(visible)),
        "rms_mm": _distribution([c["rms_mm"] for c in measured if c["rms_mm"] is not None]),
        "max_mm": _distribution([c["max_mm"] for c in measured]),
        "samples_within_2sigma": round(float(np.mean(shares)), 4) if shares else None,
        "curves_within_2sigma": _share(sum(s >= WHOLE for s in shares), len(shares)),
    }
    if stage == "weld":
        welded = [c for c in visible if c.get("welded")]
        tcp = [c["tcp_max_mm"] for c in welded if c["tcp_max_mm"] is not None]
        out["welded"] = len(welded)
        out["worst_welded_tcp_max_mm"] = max(tcp) if tcp else None
        part = [c for c in visible if c.get("manual_mm") is not None]  # welded in part: never counted as welded
        out["partial"] = len(part)
        out["manual_mm"] = round(sum(float(c["manual_mm"]) for c in part), 1)
        tcp_part = [c["tcp_max_mm"] for c in part if c["tcp_max_mm"] is not None]
        out["worst_partial_tcp_max_mm"] = max(tcp_part) if tcp_part else None
        codes = Counter(c.get("weld_reason_code") or c["reason_code"] or "unknown" for c in visible if not c["welded"])
    else:
        codes = Counter(c["reason_code"] or "unknown" for c in visible if not c["located"])
    out["refused_reasons"] = dict(sorted(codes.items()))
    return out
