"""The trust benchmark's figures, read from the pipeline's JSON report (``cell detect --json`` / ``cell weld --json``,
:mod:`cell.export.reports.report`) as a plain dict, so every key the report gains plugs in.

Per seam (:func:`seam_record`): what became of it, its lateral error and each end's error along the seam against
the truth, each as a multiple of the sigma the report states for it. Per cell (:func:`cell_record`): the seams'
records, whether the cameras were calibrated exactly, the splice corrections applied. Over many cells
(:func:`block`): the shares located / re-scanned / refused, the error distributions, the sigma coverage, the
splice corrections with exact extrinsics and, for a weld, the worst bead. A figure whose report key is absent is
None (JSON null), never a guess. Millimetres throughout, as in the report.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np
import trust_curves as tcv

from cell.seams.metrics import segment_errors

SIGMAS = (1, 2, 3)  # the coverage is counted at these multiples of sigma
BEAD_END_TOLERANCE_MM = 1.0  # a bead ending further than this past or short of its joint's end counts
BEAD_KEYS = ("short_start", "short_end", "past_start", "past_end")  # in a welded seam's ``tcp_error_mm``
SIGMA_RESOLUTION_MM = 1e-4  # the report's rounding of a sigma: a stated 0 is at most this
_DIGITS = 4
_MM = 1000.0

Row = dict[str, Any]


def _mm(v: float | None) -> float | None:
    return None if v is None or not np.isfinite(v) else round(float(v), _DIGITS)


def _z(error_mm: float | None, sigma_mm: float | None) -> float | None:
    """|error| in sigmas (None when either is unknown; a stated sigma is taken as at least the report's
    resolution)."""
    if error_mm is None or sigma_mm is None:
        return None
    return round(abs(error_mm) / max(float(sigma_mm), SIGMA_RESOLUTION_MM), 3)


def seam_errors_mm(
    detected: Mapping[str, Sequence[float]], truth: Mapping[str, Sequence[float]]
) -> tuple[float, tuple[float, float], bool] | None:
    """(lateral, (start, end), swapped) of a located seam against its true one, from the report's points [m].

    lateral : the largest distance of the located segment from the true seam line [mm] (the report's
    ``error_mm.lateral``). start, end : each located end's error ALONG the true seam [mm], signed outward:
    positive when it lies beyond the true end (the seam located too long there), negative when short of it.
    The located ends are matched to the true ends first (``swapped`` when the seam was reported reversed), so
    the pair is in the truth's order. None when a point is missing (null in the report)."""
    pts = [detected.get("start"), detected.get("end"), truth.get("start"), truth.get("end")]
    if any(p is None or len(p) != 3 or any(v is None for v in p) for p in pts):
        return None
    d0, d1, t0, t1 = (np.asarray(p, float) for p in pts)
    _, _, lateral_mm, swapped = segment_errors(d0, d1, t0, t1)
    if swapped:
        d0, d1 = d1, d0
    length = float(np.linalg.norm(t1 - t0))
    if length == 0.0:
        return None
    u = (t1 - t0) / length
    start_mm = float((t0 - d0) @ u) * _MM
    end_mm = float((d1 - t1) @ u) * _MM
    return lateral_mm, (start_mm, end_mm), swapped


def _bead_ends(tcp: Mapping[str, Any] | None) -> dict[str, float | None] | None:
    """The bead's ends against its joint's [mm] (``short_start`` ... ``past_end``), None unless all four keys."""
    if tcp is None or any(k not in tcp for k in BEAD_KEYS):
        return None
    return {k: tcp[k] for k in BEAD_KEYS}


def bead_off_end(ends: Mapping[str, float | None]) -> bool:
    """Whether a bead ends more than BEAD_END_TOLERANCE_MM past or short of its joint's end (either end)."""
    return any(v is not None and abs(float(v)) > BEAD_END_TOLERANCE_MM for v in ends.values())


def seam_record(entry: Mapping[str, Any], *, weld_report: bool, rescan_known: bool) -> Row:
    """One seam of a report, compact: status and reason code; for a located seam with a truth its lateral and
    end errors [mm] (:func:`seam_errors_mm`), the stated ``sigma_mm`` and ``end_sigma_mm`` [start, end] (in the
    truth's order; None when the report has no such key) and the errors in those sigmas (``z_across``,
    ``z_ends``); for a weld report whether it was re-scanned (``rescan_known``: the report says), welded, why not,
    its TCP max error and its bead's ends. A curved seam's record is :func:`trust_curves.curve_record`'s."""
    if entry.get("curved"):
        return tcv.curve_record(entry, weld_report=weld_report)
    status = entry["status"]
    located = status == "found"
    rec: Row = {
        "id": entry["id"],
        "status": status,
        "reason_code": entry.get("reason_code"),
        "visible": status not in ("not_visible", "not_supported"),  # a curve the cell cannot weld is listed apart
        "located": located,
    }
    errors = None
    if located and entry.get("detected") and entry.get("truth"):
        errors = seam_errors_mm(entry["detected"], entry["truth"])
    lateral = errors[0] if errors else None
    ends = list(errors[1]) if errors else None
    sigma = entry.get("sigma_mm") if located else None
    end_sigma = list(entry["end_sigma_mm"]) if located and entry.get("end_sigma_mm") is not None else None
    if end_sigma is not None and errors is not None and errors[2]:
        end_sigma = end_sigma[::-1]
    rec["lateral_mm"] = _mm(lateral)
    rec["end_mm"] = [_mm(e) for e in ends] if ends is not None else None
    rec["sigma_mm"] = sigma
    rec["end_sigma_mm"] = end_sigma
    rec["z_across"] = _z(lateral, sigma)
    rec["z_ends"] = [_z(e, s) for e, s in zip(ends, end_sigma, strict=True)] if ends and end_sigma else None
    if weld_report:
        tcp = entry.get("tcp_error_mm")
        rec["rescanned"] = ("rescan" in entry) if rescan_known else None
        rec["welded"] = bool(entry.get("welded"))
        rec["weld_reason_code"] = entry.get("weld_reason_code")
        rec["tcp_max_mm"] = tcp.get("max") if tcp else None
        rec["bead_ends_mm"] = _bead_ends(tcp)
    return rec


def exact_extrinsics(report: Mapping[str, Any]) -> bool | None:
    """Whether every camera of the run was exactly calibrated (``extrinsic_error`` zero in the report's
    ``config``); None when the report does not say."""
    cams = (report.get("config") or {}).get("cameras")
    if not cams:
        return None
    errs = [c.get("extrinsic_error") for c in cams.values()]
    if any(e is None for e in errs):
        return None
    return all(float(e.get("translation_mm", 0.0)) == 0.0 and float(e.get("rotation_deg", 0.0)) == 0.0 for e in errs)


def splice_applied(report: Mapping[str, Any]) -> list[dict[str, Any]] | None:
    """The splice corrections the run applied (camera, ``applied_mm``), from the report's ``splice``; None when
    the report has none (no splice ran) or does not say which were applied."""
    splice = report.get("splice")
    if splice is None or any("applied" not in r for r in splice.values()):
        return None
    return [{"camera": cam, "applied_mm": r.get("applied_mm")} for cam, r in sorted(splice.items()) if r["applied"]]


def cell_record(report: Mapping[str, Any], stage: str) -> Row:
    """A cell's figures from its run's report: ``exact``, ``splice_applied``, per seam :func:`seam_record`, the
    run's ``error`` type (None when it finished)."""
    weld_report = stage == "weld"
    rescan_known = "rescan" in report
    seams = [seam_record(e, weld_report=weld_report, rescan_known=rescan_known) for e in report["seams"]]
    err = report.get("error")
    return {
        "exact": exact_extrinsics(report),
        "splice_applied": splice_applied(report),
        "run_error": err.get("type") if err else None,
        "seams": seams,
    }


def distribution(values: Iterable[float | None]) -> dict[str, Any]:
    """n, median, 95th percentile and max of the known values (None for each figure when there is none)."""
    v = np.array([x for x in values if x is not None], float)
    if v.size == 0:
        return {"n": 0, "median": None, "p95": None, "max": None}
    return {
        "n": int(v.size),
        "median": _mm(float(np.median(v))),
        "p95": _mm(float(np.percentile(v, 95))),
        "max": _mm(float(v.max())),
    }


def coverage(z: Iterable[float | None]) -> dict[str, Any]:
    """The share of errors within 1, 2 and 3 of their sigmas (``"1"``, ``"2"``, ``"3"``) and ``n``, over the
    errors whose sigma is known; each share None when none is."""
    v = np.array([x for x in z if x is not None], float)
    out: dict[str, Any] = {"n": int(v.size)}
    for k in SIGMAS:
        out[str(k)] = round(float(np.mean(v <= k)), 4) if v.size else None
    return out


def _share(count: int, of: int) -> float | None:
    return round(count / of, 4) if of else None


def _located(seams: Sequence[Row]) -> list[Row]:
    return [s for s in seams if s["located"] and s["lateral_mm"] is not None]


def seam_figures(seams: Sequence[Row], stage: str) -> Row:
    """The figures of a set of seam records (one cell's or every cell's): see the module docstring; the curved
    seams' apart, under ``curved`` (:func:`trust_curves.curve_figures`)."""
    curved = [s for s in seams if s.get("curved")]
    seams = [s for s in seams if not s.get("curved")]
    visible = [s for s in seams if s["visible"]]
    located = _located(visible)
    n_vis = len(visible)
    out: Row = {
        "seams_visible": n_vis,
        "located": sum(s["located"] for s in visible),
        "located_share": _share(sum(s["located"] for s in visible), n_vis),
    }
    ends = [e for s in located if s["end_mm"] is not None for e in s["end_mm"]]
    out["lateral_mm"] = distribution(s["lateral_mm"] for s in located)
    out["end_mm"] = distribution(abs(e) for e in ends if e is not None)
    out["end_past_max_mm"] = _mm(max((e for e in ends if e is not None), default=None))
    across = coverage(s["z_across"] for s in located)
    with_end_sigma = [s for s in located if s["z_ends"] is not None]
    starts = coverage(s["z_ends"][0] for s in with_end_sigma)
    finishes = coverage(s["z_ends"][1] for s in with_end_sigma)
    both = coverage(z for s in with_end_sigma for z in s["z_ends"])
    out["coverage_across"], out["coverage_start"], out["coverage_end"], out["coverage_ends"] = (
        across,
        starts,
        finishes,
        both,
    )
    out["coverage_2sigma_across"] = across["2"]
    out["coverage_2sigma_ends"] = both["2"]
    out["z_across_max"] = max((s["z_across"] for s in located if s["z_across"] is not None), default=None)
    out["z_ends_max"] = max((z for s in with_end_sigma for z in s["z_ends"] if z is not None), default=None)
    if stage == "weld":
        out.update(weld_figures(visible))
        refused = [s for s in visible if not s["welded"]]
        codes = Counter(s["weld_reason_code"] or s["reason_code"] or "unknown" for s in refused)
    else:  # a detection re-scans nothing and welds nothing: no such figures
        out["rescanned_share"] = None
        refused = [s for s in visible if not s["located"]]
        codes = Counter(s["reason_code"] or "unknown" for s in refused)
    out["refused"] = len(refused)
    out["refused_share"] = _share(len(refused), n_vis)
    out["refused_reasons"] = dict(sorted(codes.items()))
    out["curved"] = tcv.curve_figures(curved, stage)
    return out


def weld_figures(visible: Sequence[Row]) -> Row:
    """Of the visible seams of a weld run: re-scanned and welded (counts and shares), the worst welded seam's TCP
    max error [mm], and ``beads_past_end`` (welded seams whose bead ends more than 1 mm past or short of the
    joint's end; None when a welded seam's report has no bead ends)."""
    n = len(visible)
    known = [s for s in visible if s["rescanned"] is not None]
    rescanned = sum(bool(s["rescanned"]) for s in known)
    welded = [s for s in visible if s["welded"]]
    tcp = [s["tcp_max_mm"] for s in welded if s["tcp_max_mm"] is not None]
    beads: int | None = None
    if all(s["bead_ends_mm"] is not None for s in welded):
        beads = sum(bead_off_end(s["bead_ends_mm"]) for s in welded)
    return {
        "rescanned": rescanned if len(known) == n else None,
        "rescanned_share": _share(rescanned, n) if len(known) == n else None,
        "welded": len(welded),
        "welded_share": _share(len(welded), n),
        "worst_welded_tcp_max_mm": max(tcp) if tcp else None,
        "beads_past_end": beads,
    }


def _splice_count(lines: Sequence[Mapping[str, Any]], exact: bool) -> int | None:
    """Splice corrections applied over the cells whose extrinsics are exact (or not); None when no such cell's
    report says which were applied."""
    known = [ln["splice_applied"] for ln in lines if ln["exact"] is exact and ln["splice_applied"] is not None]
    return sum(len(a) for a in known) if known else None


def cell_row(line: Mapping[str, Any], stage: str) -> Row:
    """One cell, compact, for the results' per-cell rows (see docs/trust.md)."""
    row: Row = {k: line.get(k) for k in ("cell", "cell_seed", "scenario", "exact", "wall_s")}
    if line.get("error") is not None:
        return {**row, "error": line["error"]["type"]}
    f = seam_figures(line["seams"], stage)
    row.update(
        visible=f["seams_visible"],
        located=f["located"],
        refused=f["refused"],
        lateral_max_mm=f["lateral_mm"]["max"],
        end_max_mm=f["end_mm"]["max"],
        z_across_max=f["z_across_max"],
        z_ends_max=f["z_ends_max"],
        splice_applied=len(line["splice_applied"]) if line["splice_applied"] is not None else None,
        run_error=line["run_error"],
    )
    if stage == "weld":
        row.update(
            rescanned=f["rescanned"],
            welded=f["welded"],
            worst_tcp_max_mm=f["worst_welded_tcp_max_mm"],
            beads_past_end=f["beads_past_end"],
        )
    return row


def block(lines: Sequence[Mapping[str, Any]], stage: str) -> Row:
    """The figures over every cell of ``lines`` (the stored per-cell lines, :func:`cell_record` plus ``cell``,
    ``error``, ``wall_s``): the seams of the cells pooled (not a mean of the cells' shares), the splice
    corrections with exact and with perturbed extrinsics, the cells that failed and why, and one row per cell."""
    ok = [ln for ln in lines if ln.get("error") is None]
    failed = Counter(ln["error"]["type"] for ln in lines if ln.get("error") is not None)
    seams = [s for ln in ok for s in ln["seams"]]
    exact = [ln for ln in ok if ln["exact"]]
    applied_exact = [a for ln in exact if ln["splice_applied"] for a in ln["splice_applied"]]
    out: Row = {
        "cells": len(lines),
        "cells_failed": sum(failed.values()),
        "cells_failed_by": dict(sorted(failed.items())),
        "cells_run_error": dict(sorted(Counter(ln["run_error"] for ln in ok if ln["run_error"]).items())),
        "cells_exact": len(exact),
        **seam_figures(seams, stage),
        "splice_corrections_exact": _splice_count(ok, True),
        "splice_corrections_exact_max_mm": max((a["applied_mm"] for a in applied_exact), default=None),
        "splice_corrections_perturbed": _splice_count(ok, False),
        "cell_wall_s": distribution(ln.get("wall_s") for ln in lines),
    }
    out["rows"] = [cell_row(ln, stage) for ln in lines]
    return out
