"""The report's entries for the map's seams a run does not weld: a curved seam with what its locator found (the
located curve's sigmas, its error against the true curve in simulation) and why it is not welded; any other with
its reason (docs/report.md). Millimetres where named _mm."""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from cell.export.reports.procedure_report import procedure_entry, tcp_error_entry
from cell.geometry import FloatArray, invert, transform_points
from cell.outputs import write_text
from cell.pipeline.records import Detection
from cell.types import SeamStatus, Unsupported, UnsupportedSeam
from cell.types.curve_estimate import CurveEstimate, CurveMetrics
from cell.types.plan import Remainder
from cell.types.rescan import CurveRescan, Rescan
from cell.types.run import SeamWeld, WeldReason


def _r(v: float, nd: int = 4) -> float | None:
    return None if not math.isfinite(v) else round(float(v), nd)


def _errors(m: CurveMetrics) -> dict[str, Any]:
    return {"rms": _r(m.rms_mm), "max": _r(m.max_mm), "within_2sigma": _r(m.within_2sigma, 3)}


def unsupported_entry(u: UnsupportedSeam) -> dict[str, Any]:
    """A seam the map draws that the cell cannot weld: never searched, with why as text and as a code."""
    return {"id": u.id, "status": SeamStatus.NOT_SUPPORTED.value, "reason": u.reason, "reason_code": u.code.value}


def curve_entry(
    u: UnsupportedSeam | None,
    est: CurveEstimate,
    m: CurveMetrics | None,
    w: SeamWeld | None = None,
    X_MR: FloatArray | None = None,
) -> dict[str, Any]:
    """A curved seam: its locator's status and reason, the located curve's figures when found, its error against
    the true curve (``error_mm``, simulation); what a weld run made of it (``w``: ``planned``, ``welded``, its
    ``tcp_error_mm`` against the true curve, or ``weld_reason_code`` and the planner's ``plan_reason_code``) and
    why it is not welded (``not_welded``: code and reason; None when welded). ``X_MR``: the robot frame in the
    aligned map's (the drawing's), where a remainder's ends are given (:func:`remainder_entry`)."""
    entry: dict[str, Any] = {
        "id": est.id,
        "curved": True,
        "status": est.status.value,
        "reason": est.reason if est.status is not SeamStatus.FOUND else (u.reason if u is not None else ""),
    }
    # Never searched (no joint, no round body, another method): the map's code, as for any seam not supported.
    entry["reason_code"] = (
        est.code.value
        if est.status is not SeamStatus.NOT_SUPPORTED and est.code is not None
        else (u.code.value if u is not None else None)
    )
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
        entry["error_mm"] = _errors(m)
    entry["time_ms"] = _r(est.time_s * 1000.0, 3)
    entry["not_welded"] = {"code": u.code.value, "reason": u.reason} if u is not None else None
    if w is not None:
        entry.update(weld_entry(w, est if X_MR is not None else None, X_MR))
    return entry


def weld_entry(w: SeamWeld, est: CurveEstimate | None = None, X_MR: FloatArray | None = None) -> dict[str, Any]:
    """A curved seam's weld fields, as a straight seam's: ``planned``, ``welded``, why not (``weld_reason``,
    ``weld_reason_code``, the planner's ``plan_reason_code``), and welded, its ``tcp_error_mm`` against the true
    curve, weld time and travel speed; welded in part (``weld_reason_code`` ``partial``), the ``share`` its arcs
    weld, ``manual_mm`` left for a manual weld and each stretch of the ``remainder`` (:func:`remainder_entry`; its
    ends in the drawing's frame with the located curve ``est`` and ``X_MR``)."""
    out: dict[str, Any] = {"planned": w.planned, "welded": w.welded}
    if not w.welded:
        out["weld_reason"] = w.reason
        out["weld_reason_code"] = w.code.value if w.code is not None else None
        if w.plan_code is not None:
            out["plan_reason_code"] = w.plan_code.value
    if w.partial:  # welded (planned, in a preview) in part: the rest left for a manual weld
        out["share"] = _r(w.share, 4)
        out["manual_mm"] = _r(w.manual_m * 1000.0, 1)
        out["remainder"] = [remainder_entry(r, est, X_MR) for r in w.remainder]
    if w.quality is not None:
        q = w.quality
        out["tcp_error_mm"] = tcp_error_entry(q)
        out["weld_time_s"] = _r(q.weld_time_s, 3)
        out["travel_speed_mm_s"] = _r(q.speed_mm_s, 4)
    return out | procedure_entry(w)


def remainder_entry(r: Remainder, est: CurveEstimate | None = None, X_MR: FloatArray | None = None) -> dict[str, Any]:
    """A stretch of a curved seam left for a manual weld: from and to [mm] along the located curve, its length,
    what stops the arm there as a code and in words; with the located curve ``est`` and the robot frame in the
    drawing's ``X_MR``, where the stretch starts and ends on the part (``from_xyz_mm``, ``to_xyz_mm``: in the
    drawing's frame M, as the welder reads the drawing)."""
    out: dict[str, Any] = {
        "from_mm": _r(r.from_m * 1000.0, 1),
        "to_mm": _r(r.to_m * 1000.0, 1),
        "length_mm": _r(r.length_m * 1000.0, 1),
        "code": r.code.value,
        "why": r.why,
    }
    if est is not None and X_MR is not None and est.status is SeamStatus.FOUND:
        p_MS = transform_points(X_MR, est.points_at([r.from_m, r.to_m])) * 1000.0
        out["from_xyz_mm"], out["to_xyz_mm"] = ([_r(float(v), 1) for v in p] for p in p_MS)
    return out


def remainder_words(entry: Mapping[str, Any]) -> str:
    """A stretch left for a manual weld (a :func:`remainder_entry`) in the words the console and the page give it:
    along the curve, how long, its code, and its ends on the drawing where the entry has them (whole mm)."""
    where = f"{entry['from_mm']:.0f}-{entry['to_mm']:.0f} mm along it ({entry['length_mm']:.0f} mm, {entry['code']})"
    if entry.get("from_xyz_mm") and entry.get("to_xyz_mm"):
        a, b = ("(" + ", ".join(str(round(v)) for v in entry[k]) + ")" for k in ("from_xyz_mm", "to_xyz_mm"))
        where += f" from {a} to {b} mm on the drawing"
    return f"{where}: {entry['why']}"


def not_welded_entries(det: Detection) -> list[dict[str, Any]]:
    """One entry per seam of the map outside the straight seams' records, in its order: every curved seam (welded
    or not: a weld run's curves carry their weld) and every other seam the run does not weld
    (:attr:`Detection.not_welded`)."""
    curves = {e.id: e for e in det.curve_estimates}
    undone = {u.id: u for u in det.not_welded}
    X_MR = invert(det.scene.X_RM) if det.scene is not None else None
    out = []
    for u in det.weldmap_R.not_straight:
        if u.id in curves:
            e = curves[u.id]
            out.append(curve_entry(undone.get(u.id), e, det.curve_metrics.get(u.id), det.curve_welds.get(u.id), X_MR))
        else:
            out.append(unsupported_entry(undone.get(u.id, u)))
    return out


def curve_summary(det: Detection) -> dict[str, Any]:
    """The curved seams at a glance: how many, found, welded whole, welded in part (``partial``, with the length
    left for a manual weld, ``manual_mm``), the ones not welded whole by code (``partial`` among them), and the
    largest RMS and max error of the located curves [mm]."""
    found = [e for e in det.curve_estimates if e.status is SeamStatus.FOUND]
    ms = [det.curve_metrics[e.id] for e in found if e.id in det.curve_metrics]
    undone = [u.code.value for u in det.not_welded if u.id in det.curve_welds]
    return {
        "seams": len(det.weldmap_R.curved),
        "found": len(found),
        "welded": sum(w.welded for w in det.curve_welds.values()),
        "partial": sum(w.code is WeldReason.PARTIAL for w in det.curve_welds.values()),
        "manual_mm": _r(sum(w.manual_m for w in det.curve_welds.values() if w.code is WeldReason.PARTIAL) * 1000, 1),
        "not_welded": {c: undone.count(c) for c in sorted(set(undone))},
        "rms_max_mm": _r(max((m.rms_mm for m in ms), default=math.nan)),
        "max_mm": _r(max((m.max_mm for m in ms), default=math.nan)),
    }


def weld_reason_code(entry: dict[str, Any]) -> str:
    """Why a seam the run does not weld was not welded, as a code: a located curve that no torch path was planned
    for (a run that plans no weld)."""
    code = (entry.get("not_welded") or {}).get("code")
    return (WeldReason.NO_TORCH_PATH if code == Unsupported.CURVED_NO_TORCH_PATH else WeldReason.NOT_SUPPORTED).value


def add_curve_rescan(rep: dict[str, Any], before: Detection, after: Detection, rs: Rescan) -> None:
    """The ``cell rescan`` report's curved seams: one entry per :class:`CurveRescan` of ``rs`` (every curved seam of
    the map), as :func:`curve_entry` after the re-scan with its reason, ``error_mm_before`` and ``rescan``
    (:func:`curve_rescan_entry`); and at the top, when the map has curves, ``rescan.curves`` {``seams``:
    re-scanned, ``used``, ``within_tolerance``: of those, now within the weld tolerance}."""
    limit = before.scenario.rescan.max_sigma_m
    entries = []
    for r in rs.curves:
        entry = curve_entry(None, r.after, after.curve_metrics.get(r.id))
        del entry["not_welded"]  # a re-scan welds nothing
        entry["reason"] = r.after.reason
        m = before.curve_metrics.get(r.id)
        if m is not None:
            entry["error_mm_before"] = _errors(m)
        entry["rescan"] = curve_rescan_entry(r, limit)
        entries.append(entry)
    rep["seams"] += entries
    taken = [e["rescan"] for e in entries if e["rescan"]["chosen"]]
    if rep.get("rescan") is not None and entries:  # a map without curves: none
        rep["rescan"]["curves"] = {
            "seams": len(taken),
            "used": sum(t["used"] for t in taken),
            "within_tolerance": sum(t["within_tolerance"] for t in taken),
        }


def curve_rescan_entry(r: CurveRescan, limit_m: float) -> dict[str, Any]:
    """What the re-scan did for one curve: ``chosen``, ``views`` taken, ``used`` and ``weight`` (the close-ups'
    share), the fixed cameras' ``sigma_max_mm_before`` and ``end_sigma_mm_before`` (null: closed or not located),
    ``within_tolerance`` after (its worst sigma within ``limit_m``), ``motion_s``, each view's ``distance_mm`` and
    ``e1_mm``, and ``reason``: why it was not re-scanned or is still over the tolerance."""
    b, a = r.before, r.after
    found = b.status is SeamStatus.FOUND
    return {
        "chosen": r.chosen,
        "views": len(r.views),
        "used": r.weight > 0.0,
        "weight": _r(r.weight, 3),
        "sigma_max_mm_before": _r(b.sigma_max_m * 1000.0) if found else None,
        "end_sigma_mm_before": [_r(v * 1000.0) for v in b.end_sigma_m] if found and not b.closed else None,
        "within_tolerance": a.status is SeamStatus.FOUND and a.sigma_max_m <= limit_m,
        "motion_s": _r(r.motion_s, 3),
        "distance_mm": [_r(v.distance_m * 1000.0, 1) for v in r.views],
        "e1_mm": [_r(v.e1_m * 1000.0, 1) for v in r.views],  # a linear track's carriage for each view (0: fixed)
        "reason": r.reason,
    }


MANUAL_WELDS = "manual_welds.csv"  # beside the programs: the stretches of curves the arm leaves to a welder
_MANUAL_COLUMNS = (
    "seam", "from_mm", "to_mm", "length_mm", "from_x_mm", "from_y_mm", "from_z_mm", "to_x_mm", "to_y_mm",
    "to_z_mm", "code", "why",
)  # fmt: skip


def write_manual_welds(rep: dict[str, Any], folder: Path) -> list[Path]:
    """The welder's list of what the programs leave undone on the report's curves welded in part: one row per
    stretch of a ``remainder`` (seam, from and to along the located curve, its length, where it starts and ends
    in the drawing's frame [mm], why the arm leaves it) in ``folder``/:data:`MANUAL_WELDS`, whole; nothing written
    (and [] returned) when no curve is welded in part."""
    rows = [(s["id"], r) for s in rep["seams"] for r in s.get("remainder") or ()]
    if not rows:
        return []
    text = io.StringIO()
    out = csv.writer(text, lineterminator="\n")
    out.writerow(_MANUAL_COLUMNS)
    for sid, r in rows:
        a, b = r.get("from_xyz_mm") or [None] * 3, r.get("to_xyz_mm") or [None] * 3
        out.writerow([sid, r["from_mm"], r["to_mm"], r["length_mm"], *a, *b, r["code"], r["why"]])
    return [write_text(folder / MANUAL_WELDS, text.getvalue(), what="welder's list")]
