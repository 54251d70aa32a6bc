"""Which points lie near a body's triangles, for :meth:`cell.types.Polyhedron.contains` with a margin: the test
"distance to the nearest triangle <= margin" computed only for the point-triangle pairs that can pass it (the
others lie outside the triangle's bounds or off its plane by more than the margin). Metres, any one frame."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray


def pair_distance(p: FloatArray, a: FloatArray, b: FloatArray, c: FloatArray) -> FloatArray:
    """Distances (k,) from each point p (k, 3) to its own triangle a, b, c (k, 3) each: the distance to its plane
    where the point lies over the triangle, else to its nearest edge."""
    ab, ac = b - a, c - a
    n = np.cross(ab, ac)
    nn = np.maximum(np.einsum("ik,ik->i", n, n), 1e-300)
    ap = p - a
    w = np.einsum("ik,ik->i", np.cross(ab, ap), n) / nn
    v = np.einsum("ik,ik->i", np.cross(ap, ac), n) / nn
    inside = (v >= 0) & (w >= 0) & (v + w <= 1)
    d_plane = np.abs(np.einsum("ik,ik->i", ap, n)) / np.sqrt(nn)
    best = np.full(d_plane.shape, np.inf)
    for s, e in ((a, b), (b, c), (c, a)):
        se = e - s
        ll = np.maximum(np.einsum("ik,ik->i", se, se), 1e-300)
        sp = p - s
        t = np.clip(np.einsum("ik,ik->i", sp, se) / ll, 0.0, 1.0)
        q = sp - t[:, None] * se
        best = np.minimum(best, np.sqrt(np.einsum("ik,ik->i", q, q)))
    return np.asarray(np.where(inside, d_plane, best))


def within(p: FloatArray, a: FloatArray, b: FloatArray, c: FloatArray, margin: float) -> npt.NDArray[np.bool_]:
    """(n,) whether each point p (n, 3) lies within ``margin`` [m] of one of the triangles a, b, c (t, 3) each: the
    test ``min over the triangles of pair_distance <= margin``, with the distance computed only for the
    pairs that can pass it (the point inside the triangle's bounds grown by the margin, and that near its plane)."""
    reach = margin * (1.0 + 1e-9) + 1e-12  # a pair culled here is farther than the margin by more than rounding
    lo = np.minimum(np.minimum(a, b), c) - reach
    hi = np.maximum(np.maximum(a, b), c) + reach
    n = np.cross(b - a, c - a)
    n /= np.maximum(np.linalg.norm(n, axis=1), 1e-300)[:, None]
    near = np.abs(p @ n.T - np.einsum("tk,tk->t", n, a)) <= reach
    for k in range(3):
        near &= (p[:, k, None] >= lo[None, :, k]) & (p[:, k, None] <= hi[None, :, k])
    i, j = np.nonzero(near)
    out = np.zeros(len(p), dtype=bool)
    if len(i):
        d = pair_distance(p[i], a[j], b[j], c[j])
        out[i[d <= margin]] = True
    return out
