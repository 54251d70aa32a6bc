"""The located curved seams in the 3D view, each coloured by what became of it, with the stretches left for a manual
weld marked over them: the welder's view of where the cell stopped and why.

Traces are plain dicts (plotly's JSON), so this module needs no plotly import. Input in the robot frame R [m];
drawn in millimetres. A stretch's hover text is the console's line for it (:func:`remainder_words`), its ends on
the drawing (the aligned map's frame M) where the run knows the map's pose.
"""

from __future__ import annotations

import html
import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from cell.export.reports.curve_report import remainder_entry, remainder_words
from cell.geometry import FloatArray
from cell.preview.views import MM, STATUS_COLOURS
from cell.types import SeamStatus
from cell.types.curve_estimate import CurveEstimate
from cell.types.run import SeamWeld, WeldReason

CURVE_COLOURS = {
    "curves welded": STATUS_COLOURS["found"],
    "curves planned": STATUS_COLOURS["found"],
    "curves welded in part": "#66a61e",
    "curves planned in part": "#66a61e",
    "curves not welded": STATUS_COLOURS["not_found"],
    "curves located": STATUS_COLOURS["found"],  # a run that welds nothing (detect, locate)
}
MANUAL_COLOUR = "#d95f02"  # the stretches left for a manual weld: dashed over their curve
_LEFT = (WeldReason.PARTIAL, WeldReason.PREVIEW)  # a curve whose stretches are left for a manual weld (or would be)
_STEP_M = 0.002  # a manual stretch is drawn through a point of the located curve every 2 mm


def _outcome(e: CurveEstimate, w: SeamWeld | None) -> tuple[str, str]:
    """(the trace a located curve goes in, its hover text)."""
    if w is None:
        return "curves located", f"located, sigma up to {e.sigma_max_m * MM:.2f} mm"
    if w.welded:
        return "curves welded", "welded"
    left = f"{w.manual_m * MM:.0f} mm left for a manual weld"
    if w.code is WeldReason.PREVIEW:  # a preview's: planned, nothing moves
        if w.partial:
            return "curves planned in part", f"planned in part ({w.share:.0%}), {left}"
        return "curves planned", "planned (preview: nothing moves)"
    if w.code is WeldReason.PARTIAL:
        return "curves welded in part", f"welded in part ({w.share:.0%}), {left}"
    return "curves not welded", f"not welded: {w.reason}"


def stretch_R(est: CurveEstimate, from_m: float, to_m: float) -> FloatArray:
    """(k, 3) [m] in R: the located curve from ``from_m`` to ``to_m`` along it (round a closed curve's start), a
    point every 2 mm or so (:meth:`CurveEstimate.points_at`: the report's lengths)."""
    n = max(2, math.ceil(abs(to_m - from_m) / _STEP_M) + 1)
    return est.points_at(np.linspace(from_m, to_m, n))


def _polyline(xyz: list[list[float | None]], text: list[str | None], p_mm: FloatArray, tip: str) -> None:
    """Appends one polyline (k, 3) [mm] and its hover text to a trace's columns, a None break after it."""
    for i in range(3):
        xyz[i] += [*np.round(p_mm[:, i], 1).tolist(), None]
    text += [tip] * len(p_mm) + [None]


def _trace(name: str, xyz: list[list[float | None]], text: list[str | None], line: dict[str, Any]) -> dict[str, Any]:
    return {
        "type": "scatter3d",
        "mode": "lines",
        "name": name,
        "legendgroup": "curves",
        "x": xyz[0],
        "y": xyz[1],
        "z": xyz[2],
        "text": text,
        "hoverinfo": "text+name",
        "line": line,
    }


def curve_traces(
    estimates: Sequence[CurveEstimate], welds: Mapping[str, SeamWeld], X_MR: FloatArray | None = None
) -> list[dict[str, Any]]:
    """One trace per outcome of the located curves (welded, welded in part, not welded; located when the run
    welds nothing) and one of the stretches left for a manual weld, each along the located curve from its start
    to its end (``Remainder.from_m`` .. ``to_m``, round a closed curve's start); curves not located have no points
    and are left to the results table. ``X_MR``: the robot frame in the drawing's, for the stretches' ends."""
    groups: dict[str, tuple[list[list[float | None]], list[str | None]]] = {}
    manual: tuple[list[list[float | None]], list[str | None]] = ([[], [], []], [])
    for e in estimates:
        if e.status is not SeamStatus.FOUND:
            continue
        w = welds.get(e.id)
        group, words = _outcome(e, w)
        p = np.asarray(e.p_RS) * MM
        if e.closed:
            p = np.vstack([p, p[:1]])
        xyz, text = groups.setdefault(group, ([[], [], []], []))
        _polyline(xyz, text, p, f"{e.id}<br>{html.escape(words)}")
        for r in w.remainder if w is not None and w.code in _LEFT else ():  # not when nothing ran
            stretch = stretch_R(e, r.from_m, r.to_m) * MM
            tip = f"{e.id}<br>manual weld {html.escape(remainder_words(remainder_entry(r, e, X_MR)))}"
            _polyline(*manual, stretch, tip)
    traces = [
        _trace(name, xyz, text, {"color": CURVE_COLOURS[name], "width": 6})
        for name in CURVE_COLOURS
        if name in groups
        for xyz, text in [groups[name]]
    ]
    if manual[1]:
        traces.append(_trace("manual weld", *manual, {"color": MANUAL_COLOUR, "width": 12, "dash": "dash"}))
    return traces
