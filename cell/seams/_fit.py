"""Numeric helpers shared by the plane-based seam locators (numpy and scipy only, no open3d).

Everything is in the robot frame R, metres. Planes are ``n . p = d`` with a unit normal ``n`` (3,) and offset
``d``.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy.spatial import cKDTree

from cell.geometry import FloatArray
from cell.seams.base import SeamScene

_TREE_KEY = "cell.seams._fit.dense_tree"
_SPACING_KEY = "cell.seams._fit.dense_spacing"
_TUKEY_C = 4.685  # biweight tuning constant: 95 % efficiency under Gaussian noise
_MAD_TO_SIGMA = 1.4826

IntArray = npt.NDArray[np.intp]


def dense_tree(scene: SeamScene) -> cKDTree:
    """A KD-tree over ``scene.dense.points``, built once per scene and kept in ``scene.cache``."""
    tree = scene.cache.get(_TREE_KEY)
    if tree is None:
        # An unbalanced, non-compact tree builds several times faster; queries are local and small anyway.
        tree = cKDTree(scene.dense.points, balanced_tree=False, compact_nodes=False)
        scene.cache[_TREE_KEY] = tree
    return tree


def dense_spacing(scene: SeamScene, sample: int = 2000) -> float:
    """Median nearest-neighbour distance of the dense cloud [m] (a deterministic sample), cached per scene."""
    spacing = scene.cache.get(_SPACING_KEY)
    if spacing is None:
        n = len(scene.dense)
        if n < 2:
            spacing = float("nan")
        else:
            idx = np.linspace(0, n - 1, min(n, sample)).astype(np.intp)
            dist, _ = dense_tree(scene).query(scene.dense.points[idx], k=2)
            spacing = float(np.median(dist[:, 1]))
        scene.cache[_SPACING_KEY] = spacing
    return float(spacing)


def tube_indices(
    scene: SeamScene, p_start: FloatArray, p_end: FloatArray, radius: float, extend: float
) -> IntArray:
    """Indices into ``scene.dense`` of the points within ``radius`` [m] of the segment p_start-p_end (3,) [m]
    extended by ``extend`` [m] at both ends (a capsule-free cylinder), sorted."""
    pts = scene.dense.points
    if len(pts) == 0:
        return np.zeros(0, np.intp)
    axis = p_end - p_start
    length = float(np.linalg.norm(axis))
    t = axis / length
    a = p_start - extend * t
    span = length + 2.0 * extend
    k = max(1, int(np.ceil(span / radius)))
    step = span / k
    centres = a + np.outer((np.arange(k) + 0.5) * step, t)
    hits = dense_tree(scene).query_ball_point(centres, np.hypot(radius, 0.5 * step), return_sorted=False)
    idx = np.sort(np.fromiter(itertools.chain.from_iterable(hits), np.intp))
    if len(idx) > 1:  # drop the duplicates of overlapping balls (np.unique's hashing is slower here)
        idx = idx[np.concatenate(([True], idx[1:] != idx[:-1]))]
    q = pts[idx] - a
    s = q @ t
    perp = q - np.outer(s, t)
    keep = (s >= 0.0) & (s <= span) & (np.einsum("ij,ij->i", perp, perp) <= radius * radius)
    return np.asarray(idx[keep], np.intp)


def plane_intersection(
    n_a: FloatArray, d_a: float, n_b: FloatArray, d_b: float, p_near: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Line where two planes meet: the point (3,) of it nearest ``p_near`` and its unit direction n_a x n_b
    (3,).

    Raises ValueError when the planes are (nearly) parallel.
    """
    t = np.cross(n_a, n_b)
    norm = float(np.linalg.norm(t))
    if norm < 1e-6:
        raise ValueError("planes are parallel: they do not meet in a line")
    t = t / norm
    A = np.vstack([n_a, n_b, t])
    p0 = np.linalg.solve(A, np.array([d_a, d_b, float(t @ p_near)]))
    return p0, t


def line_plane_parameter(p0: FloatArray, t: FloatArray, n: FloatArray, d: float) -> float:
    """Parameter s [m] where the line p0 + s t meets the plane n . p = d (inf when parallel)."""
    nt = float(n @ t)
    if abs(nt) < 1e-9:
        return float("inf")
    return float((d - n @ p0) / nt)


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
class PlaneFit:
    """Result of :func:`robust_plane_fit`.

    coef : (k,) fitted coefficients of the design columns (coef[0] the offset where the other columns are 0)
        [m, -].
    cov : (k, k) sandwich covariance of coef.
    scale : robust residual scale pooled over groups [m].
    weights : (n,) final biweight weights in [0, 1] (0: rejected).
    """

    coef: FloatArray
    cov: FloatArray
    scale: float
    weights: FloatArray

    @property
    def offset(self) -> float:
        return float(self.coef[0])

    @property
    def se(self) -> float:
        """Standard error of the offset [m]."""
        return float(np.sqrt(max(self.cov[0, 0], 0.0)))

    @property
    def n_inliers(self) -> int:
        return int(np.count_nonzero(self.weights > 0.0))


def _scales(res: FloatArray, members: list[IntArray], min_scale: float) -> FloatArray | float:
    """Robust scale (MAD) of the residuals: one per group (camera) when there are several, else pooled."""
    pooled = max(_MAD_TO_SIGMA * float(np.median(np.abs(res))), min_scale)
    if not members:
        return pooled
    out = np.full(len(res), pooled)
    for m in members:
        out[m] = max(_MAD_TO_SIGMA * float(np.median(np.abs(res[m]))), min_scale)
    return out


def robust_plane_fit(
    r: FloatArray,
    X: FloatArray,
    groups: IntArray,
    start: float,
    min_scale: float = 1e-4,
    iterations: int = 10,
    min_group: int = 40,
) -> PlaneFit:
    """Iteratively reweighted least squares with Tukey's biweight and per-group noise weighting.

    r : (n,) signed distances of the points from a reference plane [m].
    X : (n, k) design matrix; column 0 must be ones (the offset), others e.g. in-plane coordinates (tilts).
    groups : (n,) non-negative group (camera) index of each point; groups of at least ``min_group`` points get
        their own robust scale (the others the pooled one) and points weigh 1/scale^2.
    start : initial offset [m] (e.g. a histogram mode).
    min_scale : floor on the robust scale [m] (noise-free data).
    """
    k = X.shape[1]
    coef = np.zeros(k)
    coef[0] = start
    labels = groups - groups.min() if len(groups) else groups
    big = np.flatnonzero(np.bincount(labels) >= min_group) if len(groups) else np.zeros(0, np.intp)
    members = [np.flatnonzero(labels == g) for g in big] if len(big) > 1 else []
    w = np.ones(len(r))
    sig: FloatArray | float = min_scale
    for it in range(iterations):
        res = r - X @ coef
        if it < 3:  # settle the scales first, then keep them fixed so the iteration converges
            sig = _scales(res, members, min_scale)
        u = res / (_TUKEY_C * sig)
        w = np.where(np.abs(u) < 1.0, (1.0 - u * u) ** 2, 0.0)
        if np.count_nonzero(w) < k + 1:
            break
        ww = w / (sig * sig)
        XtW = X.T * ww
        try:
            new: FloatArray = np.asarray(np.linalg.solve(XtW @ X, XtW @ r), dtype=np.float64)
        except np.linalg.LinAlgError:
            break
        done = float(np.max(np.abs(new - coef))) < 1e-7
        coef = new
        if done and it >= 3:
            break
    res = r - X @ coef
    ww = w / (sig * sig)
    XtW = X.T * ww
    try:
        Hinv = np.linalg.inv(XtW @ X)
        meat = (X.T * (ww * res) ** 2) @ X
        n_eff = max(np.count_nonzero(w), k + 1)
        cov = Hinv @ meat @ Hinv * n_eff / (n_eff - k)
    except np.linalg.LinAlgError:
        cov = np.full((k, k), np.inf)
    inl = w > 0
    scale = _MAD_TO_SIGMA * float(np.median(np.abs(res[inl]))) if np.any(inl) else float("inf")
    return PlaneFit(coef=coef, cov=cov, scale=scale, weights=w)


def cdf_extent(s: FloatArray, q_lo: float = 0.15, q_hi: float = 0.85) -> tuple[float, float, float]:
    """Ends [a, b] [m] of a density sampled at s (n,), uniform or with a linear gradient (a face seen
    obliquely), blurred by noise; and the standard error of each end [m].

    The empirical CDF between the quantiles q_lo and q_hi (where the blur of the edges does not reach) is
    fitted with a quadratic (a straight line when the quadratic does not stay increasing) and extrapolated to
    0 and 1: robust to blur and to a few strays beyond the edges, and far less noisy than the extreme values.
    """
    n = len(s)
    ss = np.sort(s)
    i0, i1 = int(q_lo * n), max(int(q_hi * n), int(q_lo * n) + 3)
    x = ss[i0:i1]
    F = (np.arange(i0, i1) + 0.5) / n
    c, h = float(np.mean(x)), max(float(np.ptp(x)), 1e-9)  # centre and scale for a well-conditioned fit
    xn = (x - c) / h
    c1, c0 = np.polyfit(xn, F, 1)
    lin = ((0.0 - c0) / c1, (1.0 - c0) / c1)
    ends = list(lin)
    q2, q1, q0 = np.polyfit(xn, F, 2)
    for i, level in enumerate((0.0, 1.0)):
        disc = q1 * q1 - 4.0 * q2 * (q0 - level)
        if abs(q2) < 1e-12 or disc < 0.0:
            continue
        roots = ((-q1 - np.sqrt(disc)) / (2.0 * q2), (-q1 + np.sqrt(disc)) / (2.0 * q2))
        root = min(roots, key=lambda r: abs(r - lin[i]))
        lo, hi = sorted((root, xn[0] if i == 0 else xn[-1]))
        if min(q1 + 2.0 * q2 * lo, q1 + 2.0 * q2 * hi) > 0.0:  # the density stays positive out to the edge
            ends[i] = root
    a, b = c + h * ends[0], c + h * ends[1]
    # A uniform sample's order statistics scatter by about L * sqrt(q (1 - q) / n) at quantile q; the
    # extrapolation
    # to the edge adds about the same again.
    se = float((b - a) * np.sqrt(q_lo * (1.0 - q_lo) / max(n, 1)) * 1.5)
    return float(a), float(b), se


def edge_ml(
    s: FloatArray,
    guess: float,
    inner: float = 0.01,
    search: float = 0.003,
    step: float = 1e-4,
    blurs: tuple[float, ...] = (2e-4, 5e-4, 1e-3, 1.5e-3, 2.5e-3),
    stray: float = 0.01,
) -> tuple[float, float]:
    """Maximum-likelihood upper edge b [m] of a locally uniform density sampled at s (n,) blurred by Gaussian
    noise, and its standard error [m]; for a lower edge pass -s and -guess, and negate the result.

    Only the points beyond ``guess - inner`` are used. There the density is proportional to Phi((b - s) /
    sigma) (plus a small ``stray`` floor for points far beyond the edge), normalised over the window, so
    neither the density nor the count needs to be known. b is searched on a grid of ``step`` within ``guess +-
    search``, the blur sigma over ``blurs``; the standard error comes from the curvature of the profile
    log-likelihood.
    """
    from scipy.special import log_ndtr

    lo, hi = guess - inner, guess + inner
    x = s[(s > lo) & (s < hi)]
    if len(x) < 5:
        return guess, float("inf")
    b = np.arange(guess - search, guess + search + 0.5 * step, step)  # (m,)
    best = np.full(len(b), -np.inf)
    for sig in blurs:
        z = (b[:, None] - x[None, :]) / sig
        ll = np.logaddexp(log_ndtr(z), np.log(stray)).sum(axis=1) - len(x) * np.log(
            (b - lo) + stray * (hi - lo)
        )
        best = np.maximum(best, ll)
    i = int(np.argmax(best))
    if 0 < i < len(b) - 1:
        c2 = best[i - 1] - 2.0 * best[i] + best[i + 1]
        off = 0.5 * (best[i - 1] - best[i + 1]) / c2 if c2 < 0.0 else 0.0
        se = float(step / np.sqrt(-c2)) if c2 < 0.0 else float("inf")
        return float(b[i] + off * step), se
    return float(b[i]), float("inf")
