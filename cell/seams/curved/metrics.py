"""A located curve against its true one (simulation): each located sample's distance to the true polyline, over
the located curve's length (its RMS and largest), and how many samples lie within two of their sigmas."""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from cell.geometry import FloatArray
from cell.types.curve_estimate import CurveEstimate, CurveMetrics


def distances_to_polyline(p: FloatArray, truth: FloatArray, closed: bool) -> FloatArray:
    """(n,) the distance [m] of each point p (n, 3) to the polyline ``truth`` (k, 3) (its last point joined to its
    first when ``closed``): to the nearer of the two segments at the nearest vertex."""
    t = np.asarray(truth)
    k = len(t)
    _, i = cKDTree(t).query(p)
    best = np.full(len(p), np.inf)
    for lo in (i - 1, i):
        if closed:
            ok, a, b = np.ones(len(p), bool), t[lo % k], t[(lo + 1) % k]
        else:
            ok = (lo >= 0) & (lo < k - 1)
            a, b = t[np.clip(lo, 0, k - 2)], t[np.clip(lo + 1, 1, k - 1)]
        ab = b - a
        s = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-30), 0.0, 1.0)
        d = np.linalg.norm(p - (a + s[:, None] * ab), axis=1)
        best = np.where(ok, np.minimum(best, d), best)
    return best


def curve_error(est: CurveEstimate, truth: FloatArray) -> CurveMetrics:
    """``est`` (found) measured against its true curve ``truth`` (k, 3) [m], both in R."""
    d = distances_to_polyline(np.asarray(est.p_RS), truth, est.closed)
    return CurveMetrics(
        rms_mm=float(np.sqrt(np.mean(d**2))) * 1000.0,
        max_mm=float(d.max()) * 1000.0,
        within_2sigma=float(np.mean(d <= 2.0 * np.asarray(est.sigma_m))),
        samples=len(d),
    )
