"""Which points of the map's surfaces are open to the sky: nothing of the map's parts lies straight above them
(frame R, z up, metres). The parts-seen check (:func:`cell.perception.alignment_checks.part_coverage`) judges a
part only by the samples of its top a camera above the table can see: an open tube's inner bottom wall faces up
but lies under the tube's own top wall."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.types import Part

BoolArray = npt.NDArray[np.bool_]
CLEAR_M = 1e-4  # a surface this little above a point is the point's own face (its triangles), not a cover [m]


def open_to_sky(p: FloatArray, parts: Sequence[Part], clear_m: float = CLEAR_M) -> BoolArray:
    """(n,) whether the vertical ray up from each point p (n, 3) meets no triangle of ``parts`` more than
    ``clear_m`` [m] above it. Triangles seen edge-on from above (vertical walls) cover nothing; a point under
    an edge shared by two triangles counts as covered (either triangle's test takes it)."""
    p = np.asarray(p, dtype=float).reshape(-1, 3)
    covered = np.zeros(len(p), dtype=bool)
    if not len(p):
        return ~covered
    lo, hi = p.min(axis=0), p.max(axis=0)
    for part in parts:
        V, T = part.triangles()
        tri = V[T]  # (t, 3, 3)
        # Only triangles above some point and over the points' footprint can cover any.
        keep = (tri[:, :, 2].max(axis=1) > lo[2] + clear_m) & np.all(
            (tri[:, :, :2].max(axis=1) >= lo[:2]) & (tri[:, :, :2].min(axis=1) <= hi[:2]), axis=1
        )
        for a, b, c in tri[keep]:
            covered |= _under(p, a, b, c, clear_m)
    return ~covered


def _under(p: FloatArray, a: FloatArray, b: FloatArray, c: FloatArray, clear_m: float) -> BoolArray:
    """(n,) which points p (n, 3) lie under the triangle abc (3,) each, by more than ``clear_m`` [m]."""
    e1, e2 = b[:2] - a[:2], c[:2] - a[:2]
    det = float(e1[0] * e2[1] - e1[1] * e2[0])
    out = np.zeros(len(p), dtype=bool)
    if abs(det) < 1e-12:  # seen edge-on from above
        return out
    x0, x1 = np.minimum(np.minimum(a[:2], b[:2]), c[:2]), np.maximum(np.maximum(a[:2], b[:2]), c[:2])
    idx = np.flatnonzero(np.all((p[:, :2] >= x0) & (p[:, :2] <= x1), axis=1))
    if not len(idx):
        return out
    w = p[idx, :2] - a[:2]
    u = (w[:, 0] * e2[1] - w[:, 1] * e2[0]) / det
    v = (e1[0] * w[:, 1] - e1[1] * w[:, 0]) / det
    inside = (u >= 0.0) & (v >= 0.0) & (u + v <= 1.0)
    z = a[2] + u * (b[2] - a[2]) + v * (c[2] - a[2])
    out[idx] = inside & (z > p[idx, 2] + clear_m)
    return out
