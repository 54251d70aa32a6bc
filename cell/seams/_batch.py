"""Robust offsets of several planes at once: one vectorised fit (histogram mode, per-camera robust scale,
Tukey-biweight IRLS, sandwich standard error) for every face the seams of a scene measure, and the weld faces'
tilt steps batched the same way. Residuals are signed distances [m] from each plane's current estimate."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray

IntArray = npt.NDArray[np.intp]

TUKEY_C = 4.685  # biweight tuning constant: 95 % efficiency under Gaussian noise
MAD_TO_SIGMA = 1.4826


@dataclass(frozen=True)
class BatchFit:
    """Result of :func:`fit_offsets` for L planes.

    offset : (L,) move of each plane along its normal [m].
    se : (L,) standard error of each offset (sandwich) [m] (inf when no point keeps a weight).
    scale : (L,) robust noise scale of each plane's points, all cameras pooled [m].
    count : (L,) points with a non-zero weight.
    weights : (n,) final combined weight of each point (biweight / sigma^2 of its camera) [1/m^2].
    """

    offset: FloatArray
    se: FloatArray
    scale: FloatArray
    count: IntArray
    weights: FloatArray


def group_medians(a: FloatArray, group: IntArray, n_groups: int) -> tuple[FloatArray, IntArray]:
    """Median (the upper one) of the non-negative values ``a`` (n,) within each group (n,) in [0, n_groups):
    one sort of ``group + a / span`` for all groups. Returns (medians (n_groups,), 0 for an empty group;
    counts (n_groups,))."""
    counts = np.bincount(group, minlength=n_groups)
    if len(a) == 0:
        return np.zeros(n_groups), counts
    span = float(a.max()) * 1.000001 + 1e-12
    srt = np.sort(group + a / span)
    ends = np.cumsum(counts)
    idx = np.minimum(ends - counts + counts // 2, len(a) - 1)
    med = (srt[idx] - np.arange(n_groups)) * span
    med[counts == 0] = 0.0
    return med, counts


def histogram_modes(r: FloatArray, label: IntArray, n_labels: int, half_width: float, bin_m: float) -> FloatArray:
    """Per label, the mean of the values r (n,) [m] in the densest ``bin_m``-wide window (two half bins) of
    [-half_width, half_width]: a robust start for a fit, 0 for a label without values."""
    h = 0.5 * bin_m
    nb = int(np.ceil(2.0 * half_width / h)) + 2
    b = np.clip(((r + half_width) / h).astype(np.intp), 0, nb - 1)
    key = label * nb + b
    counts = np.bincount(key, minlength=n_labels * nb).reshape(n_labels, nb)
    sums = np.bincount(key, r, minlength=n_labels * nb).reshape(n_labels, nb)
    window = counts[:, :-1] + counts[:, 1:]
    i = np.argmax(window, axis=1)
    rows = np.arange(n_labels)
    n = window[rows, i]
    return (sums[rows, i] + sums[rows, i + 1]) / np.maximum(n, 1)


def camera_scales(
    res: FloatArray, label: IntArray, cam: IntArray, n_labels: int, n_cams: int, min_group: int, min_scale: float
) -> tuple[FloatArray, FloatArray]:
    """Robust noise scale (MAD) of each point's (plane, camera) group [m] (n,), and each plane's pooled one
    (n_labels,: the groups' in quadrature, weighted by their points); a camera with fewer than ``min_group``
    points on a plane takes the plane's pooled scale."""
    g = label * n_cams + cam
    own, counts = group_medians(np.abs(res), g, n_labels * n_cams)
    per_group = np.maximum(MAD_TO_SIGMA * own, min_scale)
    # Pooled: the cameras' scales in quadrature, weighted by their points (a sort fewer than a pooled MAD).
    c = counts.reshape(n_labels, n_cams)
    pooled = np.sqrt((c * per_group.reshape(n_labels, n_cams) ** 2).sum(axis=1) / np.maximum(c.sum(axis=1), 1))
    pooled = np.maximum(pooled, min_scale)
    small = counts < min_group
    per_group[small] = np.repeat(pooled, n_cams)[small]
    return per_group[g], pooled


def fit_offsets(
    r: FloatArray,
    lengths: list[int],
    cam: IntArray,
    n_cams: int,
    *,
    start: FloatArray | None = None,
    mode_half_width: float = 0.0,
    mode_bin: float = 0.002,
    min_group: int = 40,
    min_scale: float = 1e-4,
    iterations: int = 8,
    rescale_after: int = 0,
    tol: float = 1e-6,
) -> BatchFit:
    """Tukey-biweight IRLS offsets of ``len(lengths)`` planes from their points' residuals r (n,) [m] (one
    segment of ``lengths[j] > 0`` points per plane, in order), each point weighted by the robust scale of its
    camera (``cam`` (n,) in [0, n_cams)) on its plane.

    start : (L,) initial offsets [m]; None: each plane's :func:`histogram_modes` within ``mode_half_width``
        [m] (wide gates let other surfaces in: start at the densest layer, not at the mean).
    rescale_after : > 0: the scales, measured about the start, are measured again after this many iterations
        (once the offsets have settled), then held fixed so that the iteration converges.
    """
    n_planes = len(lengths)
    label = np.repeat(np.arange(n_planes), lengths)
    starts = np.concatenate(([0], np.cumsum(lengths)[:-1]))
    if start is None:
        coef = histogram_modes(r, label, n_planes, mode_half_width, mode_bin)
    else:
        coef = np.asarray(start, np.float64).copy()
    sig, pooled = camera_scales(r - coef[label], label, cam, n_planes, n_cams, min_group, min_scale)
    inv_s2 = 1.0 / (sig * sig)
    inv_c2 = inv_s2 * (1.0 / (TUKEY_C * TUKEY_C))
    sums = np.empty((2, len(r)))
    for it in range(1, iterations + 1):
        res = r - coef[label]
        if it == rescale_after + 1 and rescale_after:
            sig, pooled = camera_scales(res, label, cam, n_planes, n_cams, min_group, min_scale)
            inv_s2 = 1.0 / (sig * sig)
            inv_c2 = inv_s2 * (1.0 / (TUKEY_C * TUKEY_C))
        w = 1.0 - res * res * inv_c2
        np.maximum(w, 0.0, out=w)
        np.multiply(w, w, out=w)
        np.multiply(w, inv_s2, out=sums[0])
        np.multiply(sums[0], r, out=sums[1])
        s0, s1 = np.add.reduceat(sums, starts, axis=1)
        new = np.where(s0 > 0.0, s1 / np.maximum(s0, 1e-300), coef)
        step = float(np.abs(new - coef).max())
        coef = new
        if step < tol and it > rescale_after:
            break
    ww = sums[0]
    res = r - coef[label]
    wr = ww * res
    h, num, count = np.add.reduceat(np.stack([ww, wr * wr, (ww > 0.0).astype(np.float64)]), starts, axis=1)
    n_eff = np.maximum(count, 2.0)
    se = np.sqrt(num / np.maximum(h * h, 1e-300) * n_eff / (n_eff - 1.0))
    se[h <= 0.0] = np.inf
    return BatchFit(coef, se, pooled, count.astype(np.intp), ww.copy())


@dataclass(frozen=True)
class TiltFit:
    """Result of :func:`tilt_fits` for J planes: each fitted as r = c0 + a (u - uc) + b (v - vc).

    c0, a, b : (J,) offset [m] and slopes [-]; uc, vc : (J,) weighted centroids [m].
    se0 : (J,) standard error of the plane's value at u = 0, v = vc [m] (sandwich).
    bias0 : (J,) how far [m] the plane the prior holds lies, at u = 0 and the points' far ends along v, from the
        plane the points alone fit, beyond twice that difference's own standard error: a face tilted more than the
        prior lets it (an as-built part tilted by its neighbour), whose line the offset's error does not cover.
    tilt0 : (J,) the standard deviation [m] of the plane's value at u = 0 and the points' far ends along v from
        the slopes alone, as far as the points leave them unknown: each slope's posterior from the points and
        the parts' angular tolerance (``tolerance_sd``), carried from the centroid.
    """

    c0: FloatArray
    a: FloatArray
    b: FloatArray
    uc: FloatArray
    vc: FloatArray
    se0: FloatArray
    bias0: FloatArray
    tilt0: FloatArray


def tilt_fits(
    r: FloatArray,
    u: FloatArray,
    v: FloatArray,
    w: FloatArray,
    lengths: list[int],
    prior_sd: float,
    tolerance_sd: float = 0.0,
) -> TiltFit:
    """Weighted least squares of the residuals r (n,) [m] of J planes (one segment of ``lengths[j] >= 4``
    points per plane, in order) as r = c0 + a (u - uc) + b (v - vc) in each plane's coordinates u, v (n,) [m]
    with weights w (n,), the slopes held near 0 by a Gaussian prior of ``prior_sd``; about each plane's
    weighted centroid (uc, vc), so that the offset and the slopes are uncorrelated. The covariance is the
    sandwich (robust to weights that are not inverse variances), scaled by n / (n - 3). ``tolerance_sd``: the
    standard deviation of the slopes as built [-] (0: not counted), for :attr:`TiltFit.tilt0`."""
    n_planes = len(lengths)
    starts = np.concatenate(([0], np.cumsum(lengths)[:-1]))
    label = np.repeat(np.arange(n_planes), lengths)
    sw, swu, swv = np.add.reduceat(np.stack([w, w * u, w * v]), starts, axis=1)
    uc, vc = swu / sw, swv / sw
    X = np.stack([np.ones(len(r)), u - uc[label], v - vc[label]])  # (3, n)

    def outer_sums(m: FloatArray, k: FloatArray) -> FloatArray:
        """Per plane, the sum over its points of m k^T: (J, 3, 3) from m, k (3, n)."""
        prods = (m[:, None, :] * k[None, :, :]).reshape(9, len(r))
        return np.add.reduceat(prods, starts, axis=1).reshape(3, 3, n_planes).transpose(2, 0, 1)

    wX = X * w
    H = outer_sums(wX, X)
    H[:, 1, 1] += prior_sd**-2
    H[:, 2, 2] += prior_sd**-2
    H_inv = np.linalg.inv(H)
    coef = np.einsum("jik,kj->ji", H_inv, np.add.reduceat(wX * r, starts, axis=1))  # (J, 3)
    res = r - np.einsum("in,ni->n", X, coef[label])
    m = X * (w * res)
    n = np.asarray(lengths, np.float64)
    cov = H_inv @ outer_sums(m, m) @ H_inv * (n / np.maximum(n - 3.0, 1.0))[:, None, None]
    J = np.stack([np.ones(n_planes), -uc, np.zeros(n_planes)], axis=1)
    se0 = np.sqrt(np.maximum(np.einsum("ji,jik,jk->j", J, cov, J), 0.0))
    # The points alone (no prior on the slopes), and how far that plane lies from the prior's at the ends.
    H_free = outer_sums(wX, X)
    bias0, tilt0 = np.zeros(n_planes), np.zeros(n_planes)
    ok = np.abs(np.linalg.det(H_free)) > 1e-30
    if ok.any():
        H_free_inv = np.zeros_like(H_free)
        H_free_inv[ok] = np.linalg.inv(H_free[ok])
        coef_free = np.einsum("jik,kj->ji", H_free_inv, np.add.reduceat(wX * r, starts, axis=1))
        m_free = X * (w * (r - np.einsum("in,ni->n", X, coef_free[label])))
        cov_free = H_free_inv @ outer_sums(m_free, m_free) @ H_free_inv * (n / np.maximum(n - 3.0, 1.0))[:, None, None]
        v_lo, v_hi = np.minimum.reduceat(v, starts), np.maximum.reduceat(v, starts)
        for v_end in (v_lo, v_hi):
            J_end = np.stack([np.ones(n_planes), -uc, v_end - vc], axis=1)
            gap = np.einsum("ji,ji->j", J_end, coef_free - coef)
            var = np.einsum("ji,jik,jk->j", J_end, cov_free, J_end)
            bias0 = np.maximum(bias0, np.sqrt(np.maximum(gap**2 - 4.0 * var, 0.0)))
            if tolerance_sd > 0.0:
                # Each slope as the points and the tolerance know it together (the points' information added).
                slopes = 1.0 / (tolerance_sd**-2 + 1.0 / np.maximum(cov_free[:, (1, 2), (1, 2)], 1e-30))
                tilt0 = np.maximum(tilt0, np.sqrt(slopes[:, 0] * uc**2 + slopes[:, 1] * (v_end - vc) ** 2))
        bias0[~ok] = 0.0
        tilt0[~ok] = 0.0
    return TiltFit(coef[:, 0], coef[:, 1], coef[:, 2], uc, vc, se0, bias0, tilt0)
