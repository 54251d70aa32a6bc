"""The welder's sheet: the part in the drawing's frame with every stretch a curve welded in part leaves for a manual
weld drawn along its located curve and numbered as the rows of the welder's list (``manual_welds.csv``), in a plan
and an elevation, each row's words below them.

matplotlib is imported inside the functions (through :mod:`cell.preview.figures`). Values only: the run records
and the report's entries (:func:`cell.export.reports.curve_report.remainder_entry`); drawn in millimetres in the aligned
map's frame M, as the welder reads the drawing.
"""

from __future__ import annotations

import textwrap
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from cell.export.reports.curve_report import remainder_words
from cell.geometry import FloatArray, invert, transform_points
from cell.preview.curves3d import MANUAL_COLOUR, stretch_R
from cell.preview.figures import new_figure, save_figure
from cell.preview.views import BOX_COLOUR, MM, STATUS_COLOURS
from cell.types import SeamStatus
from cell.types.curve_estimate import CurveEstimate

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from cell.pipeline.records import Detection

SHEET = "manual_welds.png"
_VIEWS = (((0, 1), "plan (looking down -z_M)"), ((0, 2), "elevation (looking along +y_M)"))
_LABEL_APART_MM = 15.0  # stretches whose middles lie closer in a view share one label ("1,3")
_ROW_CHARS = 150  # a row's words are wrapped at this many characters (monospace, 7 pt, on an 11 in sheet)


def _curves(dets: Sequence[Detection]) -> dict[str, tuple[CurveEstimate, FloatArray]]:
    """Seam id -> (its located curve in R, the drawing's pose X_MR of that detection's robot frame) for every
    located curve; a curve located on both sides is taken from the side that welded it in part."""
    out: dict[str, tuple[CurveEstimate, FloatArray]] = {}
    for det in dets:
        if det.scene is None:
            continue
        X_MR = invert(det.scene.X_RM)
        for e in det.curve_estimates:
            w = det.curve_welds.get(e.id)
            if e.status is SeamStatus.FOUND and (e.id not in out or (w is not None and w.partial)):
                out[e.id] = (e, X_MR)
    return out


def _in_M(est: CurveEstimate, X_MR: FloatArray) -> FloatArray:
    """(k, 3) [mm] in M: the located curve's samples (a closed one's first repeated at its end)."""
    p = np.asarray(est.p_RS)
    return transform_points(X_MR, np.vstack([p, p[:1]]) if est.closed else p) * MM


def _draw(ax: Axes, ij: tuple[int, int], edges_mm: FloatArray, curves_mm: Sequence[FloatArray],
          stretches: Sequence[tuple[int, FloatArray]]) -> None:  # fmt: skip
    """Projection onto axes ij of M [mm]: the parts' edges, the located curves, then each numbered stretch."""
    i, j = ij
    for e in edges_mm:
        ax.plot(e[:, i], e[:, j], color=BOX_COLOUR, lw=0.4, alpha=0.5, zorder=1)
    for p in curves_mm:
        ax.plot(p[:, i], p[:, j], color=STATUS_COLOURS["found"], lw=1.0, zorder=2)
    labels: list[tuple[list[str], FloatArray]] = []  # numbers whose stretches' middles fall together in this view
    for n, s in stretches:
        ax.plot(s[:, i], s[:, j], color=MANUAL_COLOUR, lw=3.5, solid_capstyle="round", zorder=3)
        mid = s[len(s) // 2][[i, j]]
        near = next((lb for lb in labels if np.linalg.norm(lb[1] - mid) < _LABEL_APART_MM), None)
        if near is None:
            labels.append(([str(n)], mid))
        else:
            near[0].append(str(n))
    for names, (x, y) in labels:
        ax.annotate(",".join(names), (x, y), xytext=(6, 6), textcoords="offset points", fontsize=8, zorder=4,
                    bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": MANUAL_COLOUR})  # fmt: skip
    ax.set_aspect("equal")
    ax.set_xlabel(f"{'xyz'[i]}_M [mm]", fontsize=8)
    ax.set_ylabel(f"{'xyz'[j]}_M [mm]", fontsize=8)
    ax.tick_params(labelsize=7)


def stretches_M(
    rows: Sequence[tuple[str, Mapping[str, Any]]], curves: Mapping[str, tuple[CurveEstimate, FloatArray]]
) -> list[tuple[int, FloatArray]]:
    """(its number in the welder's list, (k, 3) [mm] in M) for each row (seam id, remainder entry) whose curve is
    among ``curves``: the located curve from the entry's ``from_mm`` to its ``to_mm``, a point every 2 mm or so."""
    out = []
    for n, (sid, r) in enumerate(rows, start=1):
        if sid in curves:
            est, X_MR = curves[sid]
            out.append((n, transform_points(X_MR, stretch_R(est, r["from_mm"] / MM, r["to_mm"] / MM)) * MM))
    return out


def draw_sheet(
    name: str,
    rows: Sequence[tuple[str, Mapping[str, Any]]],
    curves: Mapping[str, tuple[CurveEstimate, FloatArray]],
    edges_mm: FloatArray,
    folder: Path,
) -> Path:
    """``folder``/:data:`SHEET` for the welder's list's ``rows`` (seam id, remainder entry) on the located
    ``curves`` (seam id -> (curve in R, X_MR)) and the parts' edges (m, 2, 3) in M [mm]; ``name`` the scenario's."""
    stretches, drawn = stretches_M(rows, curves), [_in_M(*c) for c in curves.values()]
    fig = new_figure(11.0, 8.5)
    grid = fig.add_gridspec(2, 2, height_ratios=[3.0, 1.0])
    for k, (ij, view) in enumerate(_VIEWS):
        ax = fig.add_subplot(grid[0, k])
        _draw(ax, ij, edges_mm, drawn, stretches)
        ax.set_title(view, fontsize=9)
    text = fig.add_subplot(grid[1, :])
    text.axis("off")
    lines = [
        textwrap.fill(f"{n:>2}  {sid}: {remainder_words(r)}", _ROW_CHARS, subsequent_indent="    ")
        for n, (sid, r) in enumerate(rows, start=1)
    ]
    text.text(0.0, 1.0, "\n".join(lines), va="top", ha="left", fontsize=7, family="monospace", transform=text.transAxes)
    fig.suptitle(f"{name}: left for a manual weld (the drawing's frame M, mm)", fontsize=10)
    return save_figure(fig, folder / SHEET)


def write_welder_sheet(dets: Sequence[Detection], rep: Mapping[str, Any], folder: Path) -> list[Path]:
    """The welder's sheet (:func:`draw_sheet`) of the report's stretches left for a manual weld, on the located
    curves of a job's detections (a side each; a positioner's, at its home) over the aligned map's parts (from the
    first that has a scene); [] and nothing written when no curve is welded in part, or none has a scene."""
    rows = [(s["id"], r) for s in rep["seams"] for r in s.get("remainder") or ()]
    first = next((d for d in dets if d.scene is not None), None)
    if not rows or first is None or first.scene is None:
        return []
    X_MR = invert(first.scene.X_RM)
    edges = [transform_points(X_MR, e) * MM for p in first.weldmap_R.parts for e in p.edges()]
    return [draw_sheet(first.scenario.name, rows, _curves(dets), np.asarray(edges).reshape(-1, 2, 3), folder)]
