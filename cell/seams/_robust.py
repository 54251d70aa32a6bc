"""A robust offset of one plane: the scalar IRLS (Tukey biweight, per-camera noise) that places a face from an
adjacent face's edge, kept apart from the batched fit (docs/bodies.md section 8, "A face placed from an edge").
Residuals ``r`` are signed distances [m] of points from the plane's reference (its map estimate)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.seams._batch import MAD_TO_SIGMA, TUKEY_C

IntArray = npt.NDArray[np.intp]


def histogram_mode(r: FloatArray, bin_m: float) -> float:
    """Centre of the densest ``bin_m``-wide window of the values r (n,) [m] (a robust start for a fit)."""
    if len(r) == 0:
        return 0.0
    lo = float(r.min())
    nbins = max(1, int(np.ceil((float(r.max()) - lo) / (0.5 * bin_m))) + 1)
    counts = np.bincount(((r - lo) / (0.5 * bin_m)).astype(np.intp), minlength=nbins)
    smooth = counts[:-1] + counts[1:] if nbins > 1 else counts  # two half-bins: one full-width window
    i = int(np.argmax(smooth))
    sel = (r >= lo + i * 0.5 * bin_m) & (r <= lo + (i + 2) * 0.5 * bin_m)
    return float(np.median(r[sel]))


@dataclass(frozen=True)
class OffsetFit:
    """Result of :func:`robust_offset`: the plane's offset from its reference [m] and the robust scale of its
    inliers' residuals, all cameras pooled [m] (inf when none keeps a weight)."""

    offset: float
    scale: float


def _mad(a: FloatArray, cap: int = 1500) -> float:
    """Median of |residuals| a (n,) >= 0, from an evenly strided subsample of at most about ``cap`` values
    (the scale only sets weights: a subsample's median is plenty)."""
    if len(a) > 2 * cap:
        a = a[:: len(a) // cap]
    if len(a) == 0:
        return float("nan")
    k = len(a) // 2
    return float(np.partition(a, k)[k])  # the upper median: np.median's overhead is most of its cost here


def _group_scales(res: FloatArray, labels: IntArray, n_groups: int, min_scale: float) -> FloatArray:
    """Robust scale (MAD) [m] per point (n,): each group's own, the pooled one for points of small groups
    (``labels`` -1) or when there are fewer than two groups."""
    a = np.abs(res)
    pooled = max(MAD_TO_SIGMA * _mad(a), min_scale)
    out = np.full(len(res), pooled)
    for g in range(n_groups if n_groups > 1 else 0):
        m = labels == g
        out[m] = max(MAD_TO_SIGMA * _mad(a[m]), min_scale)
    return out


def robust_offset(
    r: FloatArray,
    groups: IntArray,
    start: float,
    min_scale: float = 1e-4,
    iterations: int = 10,
    min_group: int = 40,
    rescale_at: tuple[int, ...] = (0, 3),
) -> OffsetFit:
    """Iteratively reweighted mean of the residuals r (n,) [m] with Tukey's biweight and per-group noise weighting.

    groups : (n,) non-negative group (camera) index of each point; when at least two groups hold ``min_group``
        points, each of those gets its own robust scale (the others the pooled one); points weigh 1/scale^2.
    start : initial offset [m] (e.g. :func:`histogram_mode`).
    min_scale : floor on the robust scale [m] (noise-free data).
    rescale_at : the iterations at which the scales are measured (a MAD per group): about the start, and again once
        the offset has settled; then held fixed so that the iteration converges.
    """
    n = len(r)
    coef = start
    labels = np.full(n, -1, np.intp)
    n_groups = 0
    if n:
        counts = np.bincount(groups)
        big = np.flatnonzero(counts >= min_group)
        if len(big) > 1:
            lut = np.full(len(counts), -1, np.intp)
            lut[big] = np.arange(len(big))
            labels = lut[groups]
            n_groups = len(big)
    w = np.ones(n)
    sig = np.full(n, min_scale)
    inv_sig2 = 1.0 / (sig * sig)
    inv_cut2 = inv_sig2 / (TUKEY_C * TUKEY_C)
    for it in range(iterations):
        res = r - coef
        if it in rescale_at:
            sig = _group_scales(res, labels, n_groups, min_scale)
            inv_sig2 = 1.0 / (sig * sig)
            inv_cut2 = inv_sig2 / (TUKEY_C * TUKEY_C)
        w = 1.0 - res * res * inv_cut2
        np.maximum(w, 0.0, out=w)
        w *= w
        ww = w * inv_sig2
        sw = float(ww.sum())
        if sw <= 0.0:
            break
        new = float(ww @ r) / sw
        done = abs(new - coef) < 1e-6
        coef = new
        if done and it >= max(rescale_at):
            break
    inl = w > 0
    scale = MAD_TO_SIGMA * _mad(np.abs((r - coef)[inl])) if np.any(inl) else float("inf")
    return OffsetFit(float(coef), scale)
