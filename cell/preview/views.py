"""What a preview draws, numpy only: colours, the seams as lines, the thinned cloud, box edges, torch glyphs, labels.

Everything takes plain values in the robot frame R [m] and returns drawing coordinates in millimetres; the
figures (:mod:`cell.preview.figures`, :mod:`cell.preview.joint_plots`) and the HTML view
(:mod:`cell.preview.html`) draw them. The cloud is thinned deterministically (every k-th point).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.types import SeamRecord, WeldMap

MM = 1000.0  # [mm/m]
STATUS_COLOURS = {
    "found": "#2ca02c",
    "not_found": "#d62728",
    "not_visible": "#ff7f0e",
    "occluded": "#9467bd",
    "not_supported": "#7f7f7f",
}
TRUTH_COLOUR = "#000000"
PATH_COLOUR = "#17becf"
BOX_COLOUR = "#555555"
# torch x, y, z axes: magenta, brown, blue (not red/green, which mean seam status here)
AXIS_COLOURS = ("#c51b7d", "#8c510a", "#2166ac")
ARC_COLOUR = "#ffd92f"
_GLYPHS_PER_SEAM = 6  # torch axis glyphs drawn along each seam
_GLYPH_M = 0.04  # [m] length of a torch axis glyph


class SeamView(NamedTuple):
    """One seam to draw, in R [m]: its status (``found``/``not_found``/``not_visible``), the estimate's end
    points (empty arrays when not found) and the true end points (None when unknown)."""

    id: str
    status: str
    p_start: npt.ArrayLike
    p_end: npt.ArrayLike
    truth_start: npt.ArrayLike | None = None
    truth_end: npt.ArrayLike | None = None


def seam_views(records: Sequence[SeamRecord]) -> list[SeamView]:
    """SeamViews from a run's seam records: each estimate in R, with its true seam when the truth is known."""
    out = []
    for rec in records:
        e, t = rec.estimate, rec.truth
        out.append(SeamView(e.id, str(e.status), e.p_start, e.p_end, *(t if t is not None else (None, None))))
    return out


class Line(NamedTuple):
    """A seam line ready to draw: (2, 3) [mm], solid when it is the estimate, dashed when it is the map's."""

    id: str
    status: str
    pts: FloatArray
    estimated: bool
    truth: FloatArray | None


def seam_lines(seams: Sequence[SeamView | tuple[Any, ...]], weldmap: WeldMap) -> list[Line]:
    lines = []
    for raw in seams:
        s = SeamView(*raw)
        status = str(s.status)
        if status not in STATUS_COLOURS:
            raise ValueError(f"seam {s.id}: status {status!r} unknown; valid: {', '.join(STATUS_COLOURS)}")
        a, b = np.asarray(s.p_start, dtype=float), np.asarray(s.p_end, dtype=float)
        estimated = a.shape == (3,) and b.shape == (3,)
        if not estimated:  # nothing found: draw where the map says the seam is
            ms = weldmap.seam(s.id)
            a, b = np.asarray(ms.p_start), np.asarray(ms.p_end)
        truth = None
        if s.truth_start is not None and s.truth_end is not None:
            truth = np.array([s.truth_start, s.truth_end], dtype=float) * MM
        lines.append(Line(s.id, status, np.array([a, b]) * MM, estimated, truth))
    return lines


def thin(points: npt.ArrayLike, max_points: int) -> FloatArray:
    """At most ``max_points`` rows of points (n, 3), every k-th one (deterministic)."""
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    step = max(int(np.ceil(len(p) / max(max_points, 1))), 1)
    return p[::step]


def torch_glyphs(poses: npt.ArrayLike) -> FloatArray:
    """(k, 3, 2, 3) axis segments [mm] of a few torch poses X_RT (m, 4, 4): for each pose, x, y, z axes."""
    X = np.asarray(poses, dtype=float).reshape(-1, 4, 4)
    if len(X) == 0:
        return np.zeros((0, 3, 2, 3))
    X = X[np.unique(np.linspace(0, len(X) - 1, min(_GLYPHS_PER_SEAM, len(X))).round().astype(int))]
    origin = X[:, :3, 3]
    tips = origin[:, None, :] + _GLYPH_M * np.transpose(X[:, :3, :3], (0, 2, 1))  # (k, axis, 3)
    return np.stack([np.repeat(origin[:, None, :], 3, axis=1), tips], axis=2) * MM


def label_groups(lines: list[Line], radius_mm: float = 60.0) -> list[tuple[str, tuple[float, float]]]:
    """Seam numbers (1-based, as in the detail panels) grouped by nearby midpoints: one label per group."""
    groups: list[tuple[list[int], FloatArray]] = []
    for i, ln in enumerate(lines):
        mid = ln.pts.mean(axis=0)[:2]
        for members, centre in groups:
            if np.linalg.norm(mid - centre) < radius_mm:
                members.append(i + 1)
                break
        else:
            groups.append(([i + 1], mid))
    return [(",".join(str(m) for m in members), (float(c[0]), float(c[1]))) for members, c in groups]
