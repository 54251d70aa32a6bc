"""The weld report's procedure part: per seam, the weld procedure it got and the bead each pass laid.

Read by :func:`cell.export.reports.report.weld_report` (values only: a :class:`~cell.types.run.SeamWeld`). Units as a
WPS states them: millimetres, seconds, amperes, volts, metres per minute.
"""

from __future__ import annotations

from typing import Any

from cell.types.execution import WeldQuality
from cell.types.procedure import WeldProcedure
from cell.types.run import SeamWeld


def _r(v: float, nd: int) -> float:
    return round(float(v), nd)


def procedure_dict(p: WeldProcedure) -> dict[str, Any]:
    """One procedure as the report prints it: name, arc settings, torch, weave, craters and passes."""
    w = p.weave
    return {
        "name": p.name,
        "process": p.process,
        "wire": p.wire,
        "gas": p.gas,
        "current_a": _r(p.current_a, 1),
        "voltage_v": _r(p.voltage_v, 2),
        "wire_feed_m_min": _r(p.wire_feed_m_min, 2),
        "travel_speed_mm_s": _r(p.travel_speed_mm_s, 2),
        "leg_mm": _r(p.leg_mm, 2),
        "throat_mm": _r(p.throat_mm, 2),
        "work_angle_deg": _r(p.work_angle_deg, 2),
        "travel_angle_deg": _r(p.travel_angle_deg, 2),
        "direction": p.direction,
        "weave": {
            "pattern": w.pattern,
            "width_mm": _r(w.width_mm, 2),
            "frequency_hz": _r(w.frequency_hz, 3),
            "dwell_s": [_r(w.dwell_s[0], 3), _r(w.dwell_s[1], 3)],
        },
        "crater_start_s": _r(p.crater_start_s, 2),
        "crater_end_s": _r(p.crater_end_s, 2),
        "passes": len(p.passes),
    }


def tcp_error_entry(q: WeldQuality) -> dict[str, float]:
    """A weld's ``tcp_error_mm`` [mm]: ``rms`` and ``max`` of the TCP's distance from the true seam, and at each
    end how much of the joint the bead left unwelded (``short_start``, ``short_end``) and how far it ran past it
    (``past_start``, ``past_end``), the ends being the true seam's start and end."""
    return {
        "rms": _r(q.tcp_rms_mm, 4),
        "max": _r(q.tcp_max_mm, 4),
        "short_start": _r(q.short_start_mm, 3),
        "short_end": _r(q.short_end_mm, 3),
        "past_start": _r(q.past_start_mm, 3),
        "past_end": _r(q.past_end_mm, 3),
    }


def _bead(q: WeldQuality) -> dict[str, Any]:
    return {
        "length_mm": _r(q.length_mm, 2),
        "weld_time_s": _r(q.weld_time_s, 3),
        "travel_speed_mm_s": _r(q.speed_mm_s, 3),
        "tcp_error_mm": tcp_error_entry(q),
    }


def procedure_entry(w: SeamWeld) -> dict[str, Any]:
    """``procedure`` (the row the seam got, or nothing when the plan used none) and ``passes``: per pass its
    offset in the joint's cross-section, its travel speed and, when measured, the bead it laid (driven length,
    arc time, travel speed along the seam, TCP error against the seam plus the intended weave and offset)."""
    p = w.procedure
    if p is None:
        return {}
    passes = []
    for k, wp in enumerate(p.passes):
        entry: dict[str, Any] = {
            "pass": k + 1,
            "lateral_mm": _r(wp.lateral_mm, 2),
            "lift_mm": _r(wp.lift_mm, 2),
            "travel_speed_mm_s": _r(wp.travel_speed_mm_s or p.travel_speed_mm_s, 2),
        }
        if k < len(w.passes):
            entry["bead"] = _bead(w.passes[k])
        passes.append(entry)
    return {"procedure": procedure_dict(p), "passes": passes}
