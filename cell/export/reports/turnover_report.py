"""The report of a whole part welded on two sides (docs/flip.md): the single-sided report's keys, each
seam from the side that searched it, the turn and what the second alignment measured."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from cell.export.reports.report import weld_report
from cell.export.reports.report_values import error_entry, point, rounded
from cell.pipeline.turnover_run import TurnoverRun
from cell.types import SeamStatus


def turnover_report(run: TurnoverRun, *, provenance: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The report of a whole part: side A's :func:`weld_report` with every key kept, each seam's entry
    taken from the side that searched it and given its ``side`` (``"A"``/``"B"``), a ``flip`` block (the turn
    planned, the placement error the second alignment measured, its fitness, the seams left with why), ``sides``
    (per side: welded, cycle time, the side's summary and error) and ``job_time_s`` (both sides' robot time, side
    A's with its tacks, and the operator's turn); ``flip.tacks`` lists the tacks laid before the turn. ``welded``
    and ``cycle_time_s`` count both sides."""
    rep = weld_report(run.side_a, provenance=provenance)
    sides: dict[str, Any] = {"A": _side_entry(rep)}
    side_of = run.side_of()
    b_entries: dict[str, dict[str, Any]] = {}
    if run.side_b is not None:
        rep_b = weld_report(run.side_b, provenance=provenance)
        b_entries = {e["id"]: e for e in rep_b["seams"]}
        sides["B"] = _side_entry(rep_b)
        # The part's counts: a seam visible (found) on side B counts as visible (found) for the whole part.
        rep["summary"] = {**rep["summary"]}
        for key in ("visible", "found"):
            rep["summary"][key] += rep_b["summary"][key]
    left = run.plan.left if run.plan is not None else {}
    seams = []
    for entry in rep["seams"]:
        e = dict(b_entries.get(entry["id"], entry))
        listed = e["status"] == SeamStatus.NOT_SUPPORTED  # a seam the cell cannot weld is on no side
        e["side"] = None if listed else side_of.get(entry["id"], "A")
        if entry["id"] in left and not e.get("welded"):
            e["weld_reason"] = f"{e.get('weld_reason', '')}; {left[entry['id']]}".lstrip("; ")
        seams.append(e)
    rep["seams"] = seams
    rep["welded"] = run.welded
    rep["cycle_time_s"] = rounded(run.cycle_time_s, 3)
    rep["job_time_s"] = rounded(run.job_time_s, 3)
    rep["sides"] = sides
    rep["flip"] = _turnover_entry(run)
    if rep["error"] is None and run.side_b is not None and run.side_b.error is not None:
        rep["error"] = error_entry(run.side_b.error)
    if rep["error"] is None and run.error is not None:
        rep["error"] = error_entry(run.error)
    return rep


def _side_entry(rep: Mapping[str, Any]) -> dict[str, Any]:
    """One side's figures from its own weld report."""
    return {
        "welded": rep["welded"],
        "seams": [e["id"] for e in rep["seams"] if e["status"] != SeamStatus.NOT_SUPPORTED],
        "cycle_time_s": rep["cycle_time_s"],
        "summary": rep["summary"],
        "error": rep["error"],
        "timings_s": rep["timings_s"],
    }


def _turnover_entry(run: TurnoverRun) -> dict[str, Any] | None:
    """The turn: planned (axis, angle, lean, nominal pose after), made or why not, and what was measured."""
    p = run.plan
    if p is None:
        return None
    res = run.result
    turn_s = run.positioner_turn_s
    return {
        "made": run.side_b is not None,
        "allowed": p.allowed,
        "stable": p.stable,
        "reason": p.reason,
        "axis": p.axis,
        "axis_R": point(p.axis_R),
        "rotation_deg": rounded(math.degrees(p.angle_rad), 3),
        "tilt_deg": rounded(math.degrees(p.tilt_rad), 3),
        "X_RM_after": [[rounded(v) for v in row] for row in p.X_RM_after],
        "exposed": list(p.exposed),
        "left": dict(p.left),
        "placement_error_mm": rounded(res.offset_m * 1000.0, 3) if res is not None else None,
        "placement_rotation_deg": rounded(math.degrees(res.rotation_rad), 3) if res is not None else None,
        "fitness": rounded(res.fitness, 4) if res is not None else None,
        "operator_s": rounded(run.operator_s, 3),
        # what a tilt-rotate positioner would take for the same turn, and what it would save of the job
        "positioner_turn_s": rounded(turn_s, 3),
        "positioner_saves_s": rounded(run.operator_s - turn_s, 3) if run.side_b is not None else None,
        "tacks_s": rounded(run.tacks_s, 3),
        "tacks": [
            {
                "id": t.id,
                "seam": t.seam_id,
                "end": t.end,
                "length_mm": t.length_mm,
                "planned": t.planned,
                "welded": t.welded,
                "reason": t.reason,
            }
            for t in run.tacks
        ],
    }
