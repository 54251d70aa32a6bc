"""How well a curved seam was welded: the executed tool path against the true curve (how far the TCP strays across
it, RMS and max; how much of it the bead leaves unwelded, how far it runs past an open curve's ends) and the
travel speed along it. Frames: R; metres inside, millimetres in the :class:`WeldQuality` it returns."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from scipy.spatial import cKDTree

from cell.geometry import FloatArray
from cell.process.quality import continuous, quality_figures
from cell.types.execution import WeldQuality

_MM = 1000.0
_BIN_M = 0.001  # [m] a closed curve's coverage is counted in bins this long


def _segments(truth_R: FloatArray, closed: bool) -> tuple[FloatArray, FloatArray, FloatArray]:
    """(a, b, s_a): the curve's segments from a (m, 3) to b (m, 3) and the length along the curve at each a (m,)."""
    p = np.asarray(truth_R, dtype=float)
    b = np.roll(p, -1, axis=0) if closed else p[1:]
    a = p if closed else p[:-1]
    s_a = np.concatenate([[0.0], np.cumsum(np.linalg.norm(b - a, axis=1))[:-1]])
    return a, b, s_a


def nearest_on_curve(p_R: npt.ArrayLike, truth_R: npt.ArrayLike, closed: bool) -> tuple[FloatArray, FloatArray]:
    """(distance (n,) [m], s (n,) [m]): each point's distance to the polyline truth_R (m, 3) (a closed one joins its
    last point to its first) and the length along it of the nearest point. Exact on the polyline: the nearest
    vertex's two segments are measured (the truth's samples are dense, 0.5 mm)."""
    p = np.asarray(p_R, dtype=float).reshape(-1, 3)
    a, b, s_a = _segments(np.asarray(truth_R, dtype=float), closed)
    m = len(a)
    _, k = cKDTree(a).query(p)
    best_d = np.full(len(p), np.inf)
    best_s = np.zeros(len(p))
    for j in (np.mod(k - 1, m) if closed else np.clip(k - 1, 0, m - 1), k):
        ab = b[j] - a[j]
        ll = np.maximum(np.sum(ab * ab, axis=1), 1e-30)
        t = np.clip(np.sum((p - a[j]) * ab, axis=1) / ll, 0.0, 1.0)
        d = np.linalg.norm(p - (a[j] + t[:, None] * ab), axis=1)
        better = d < best_d
        best_d[better] = d[better]
        best_s[better] = (s_a[j] + t * np.sqrt(ll))[better]
    return best_d, best_s


def curve_weld_quality(times: npt.ArrayLike, tcp_R: npt.ArrayLike, truth_R: npt.ArrayLike, closed: bool) -> WeldQuality:
    """Quality of one weld along a curve from the records taken while its arc burned.

    times : (n,) [s]; tcp_R : (n, 3) tool positions in R [m] (n >= 2); truth_R : (m, 3) the true curve in R [m]
    (a closed one without its first point repeated). The TCP error is each record's distance to the true curve.
    An open curve: short_start / short_end how much of it at each end the bead leaves unwelded, past_start /
    past_end how far it runs beyond (along the end tangent). A closed curve: short_start the length of the loop
    no record reaches (counted in 1 mm bins), the others 0.
    """
    t = np.asarray(times, dtype=float)
    p = np.asarray(tcp_R, dtype=float)
    truth = np.asarray(truth_R, dtype=float)
    if len(t) < 2:
        raise ValueError("a weld needs at least two tool records")
    d, s = nearest_on_curve(p, truth, closed)
    a, b, s_a = _segments(truth, closed)
    total = float(s_a[-1] + np.linalg.norm(b[-1] - a[-1]))
    if closed:
        bins = np.zeros(max(1, int(np.ceil(total / _BIN_M))), dtype=bool)
        bins[np.minimum((s / _BIN_M).astype(int), len(bins) - 1)] = True
        gaps = (float(np.sum(~bins)) * _BIN_M, 0.0, 0.0, 0.0)
    else:
        t0 = (truth[1] - truth[0]) / np.linalg.norm(truth[1] - truth[0])
        t1 = (truth[-1] - truth[-2]) / np.linalg.norm(truth[-1] - truth[-2])
        past_start = max(float(np.max((truth[0] - p) @ t0)), 0.0)
        past_end = max(float(np.max((p - truth[-1]) @ t1)), 0.0)
        gaps = (float(s.min()), total - float(s.max()), past_start, past_end)
    length_m = float(np.linalg.norm(np.diff(p, axis=0), axis=1)[continuous(t)].sum())  # the arcs, not the air
    return quality_figures(t, p, d * _MM, gaps, length_m)


def pass_truth(truth_R: npt.ArrayLike, p_R: npt.ArrayLike, n_a_R: npt.ArrayLike, n_b_R: npt.ArrayLike,
               lateral_m: float, lift_m: float) -> FloatArray:  # fmt: skip
    """The true curve truth_R (m, 3) moved where a pass offset ``lateral_m`` across the local bisector towards face
    A and ``lift_m`` along it out of the root is meant to run: the cross-section at each true sample from the
    located curve's nearest sample p_R (k, 3) and its faces' normals n_a_R, n_b_R (k, 3) (as the planner lays the
    pass, :mod:`cell.planning.curves.weave`)."""
    truth = np.asarray(truth_R, dtype=float)
    if lateral_m == 0.0 and lift_m == 0.0:
        return truth
    _, k = cKDTree(np.asarray(p_R, dtype=float)).query(truth)
    na, nb = np.asarray(n_a_R, dtype=float)[k], np.asarray(n_b_R, dtype=float)[k]
    d = np.gradient(truth, axis=0)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    b = na + nb
    b -= np.sum(b * d, axis=1, keepdims=True) * d
    b /= np.linalg.norm(b, axis=1, keepdims=True)
    e = nb - na
    e -= np.sum(e * d, axis=1, keepdims=True) * d + np.sum(e * b, axis=1, keepdims=True) * b
    e /= np.linalg.norm(e, axis=1, keepdims=True)
    return np.asarray(truth + lateral_m * e + lift_m * b)


def unwelded_stretches(
    tcp_R: npt.ArrayLike, truth_R: npt.ArrayLike, closed: bool, min_m: float = 0.002
) -> list[tuple[float, float]]:
    """The stretches (from, to) [m] along the true curve truth_R (m, 3) in R that no record of tcp_R (n, 3) in R
    reaches (its nearest point on the curve, in 1 mm bins), each at least ``min_m`` [m] long, in order along the
    curve (a closed curve's stretch across its start: from before its length to past it)."""
    a, b, s_a = _segments(np.asarray(truth_R, dtype=float), closed)
    total = float(s_a[-1] + np.linalg.norm(b[-1] - a[-1]))
    _, s = nearest_on_curve(tcp_R, truth_R, closed)
    bins = np.zeros(max(1, int(np.ceil(total / _BIN_M))), dtype=bool)
    bins[np.minimum((s / _BIN_M).astype(int), len(bins) - 1)] = True
    if bins.all():
        return []
    shift = int(np.argmax(bins)) if closed else 0  # a closed curve scanned from a welded bin
    free = np.roll(~bins, -shift)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], free.astype(int), [0]])))
    out = [
        ((i + shift) * _BIN_M, min((j + shift) * _BIN_M, total + shift * _BIN_M))
        for i, j in zip(edges[::2], edges[1::2], strict=True)
    ]
    out = [(lo, hi) for lo, hi in out if hi - lo >= min_m]
    return sorted(((lo - total, hi - total) if lo >= total else (lo, hi) for lo, hi in out), key=lambda g: g[0])
