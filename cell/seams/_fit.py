"""Numeric helpers shared by the plane-based seam locators (numpy and scipy only, no open3d).

Everything is in the robot frame R, metres. Planes are ``n . p = d`` with a unit normal ``n`` (3,) and offset
``d``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray, make_pose
from cell.seams._batch import MAD_TO_SIGMA, TUKEY_C
from cell.seams.base import SeamScene
from cell.types import Box, Cloud
from cell.voxels import VoxelTable, voxel_order

_BOX_KEY = "cell.seams._fit.cloud_box"
_INDEX_KEY = "cell.seams._fit.dense_index"
INDEX_SHARES = (0.25, 0.5, 1.0)  # shares of the dense cloud a query may ask for (1 / k: every k-th point)
INDEX_VOXEL_M = 0.01  # voxel of an index built here (perception hands on its own, ``PerceptionSpec.voxel_m``)

IntArray = npt.NDArray[np.intp]


@dataclass(frozen=True)
class CloudIndex:
    """The dense cloud in voxel order (:func:`cell.voxels.voxel_order`) for tube queries, in layers: a query
    asks for a share of the points, so that a locator needing thousands, not tens of thousands, of points per
    seam gathers only those. The layer of share 1/k is every k-th point of the ordered cloud: each voxel keeps
    its share of its points (a stratified thinning, spread like the dense cloud: a fit on it only sees fewer
    points) and the layers are nested. A query gathers a few runs of the ordered cloud: no search, no sort,
    no copy of the cloud.

    points : (n, 3) the cloud's coordinates in voxel order [m]; camera : (n,) camera index (-1: unknown);
    voxels : where each voxel's points lie.
    """

    points: FloatArray
    camera: npt.NDArray[np.integer[Any]]
    voxels: VoxelTable
    shares: tuple[float, ...] = INDEX_SHARES
    _density: dict[int, float] = field(default_factory=dict, compare=False, repr=False)

    def __post_init__(self) -> None:
        if any(abs(1.0 / s - round(1.0 / s)) > 1e-9 for s in self.shares) or max(self.shares, default=0.0) != 1.0:
            raise ValueError(f"index shares must be 1 / k for whole k and include 1, got {self.shares}")

    @property
    def density(self) -> float:
        """Points per square metre of a well-seen surface [1/m^2]: the 90th percentile of the points per voxel
        over a voxel's face (a surface crossing a voxel square holds one face's area of it; most voxels hold
        less: edges, corners, surfaces seen obliquely or by fewer cameras); computed on first use."""
        out = self._density.get(0)
        if out is None:
            counts = self.voxels.counts
            out = float(np.percentile(counts, 90.0)) / self.voxels.voxel_m**2 if len(counts) else 0.0
            self._density[0] = out
        return out

    def pitch(self, share: float) -> float:
        """Point pitch [m] of ``share`` of the points on a well-seen surface (``1 / sqrt(density)``)."""
        density = self.density
        return float(1.0 / np.sqrt(density * share)) if density > 0.0 else float("nan")

    def tube(
        self, p_start: FloatArray, p_end: FloatArray, radius: float, extend: float, share: float
    ) -> tuple[FloatArray, IntArray]:
        """The points (3, k) [m] and their cameras (k,) within ``radius`` [m] of the segment p_start-p_end (3,)
        [m] extended by ``extend`` [m] at both ends (a capsule-free cylinder), from the layer of ``share`` (one
        of :attr:`shares`), in a fixed order.

        The candidates come from the voxels inside the tube's bounding box: one run of the ordered cloud per
        (x, y) column of voxels, so the cost does not grow with the size of the cloud.
        """
        if share not in self.shares:
            raise ValueError(f"share {share} is not one of the index's layers {self.shares}")
        vox = self.voxels
        a0, b0 = [float(v) for v in p_start], [float(v) for v in p_end]
        axis = [b0[k] - a0[k] for k in range(3)]
        length = math.sqrt(sum(v * v for v in axis))
        t = [v / length for v in axis]
        a = [a0[k] - extend * t[k] for k in range(3)]
        span = length + 2.0 * extend
        b = [a[k] + span * t[k] for k in range(3)]
        # Bounding box of the cylinder: per axis, the ends' range grown by radius * sqrt(1 - t_k^2).
        lo, hi = [], []
        for k in range(3):
            grow = radius * math.sqrt(max(1.0 - t[k] * t[k], 0.0))
            lo.append(max(math.floor((min(a[k], b[k]) - grow) / vox.voxel_m) - vox.origin[k], 0))
            hi.append(min(math.floor((max(a[k], b[k]) + grow) / vox.voxel_m) - vox.origin[k], vox.dims[k] - 1))
        empty = np.zeros((3, 0)), np.zeros(0, np.intp)
        if any(h < lo_ for lo_, h in zip(lo, hi, strict=True)):
            return empty
        cols = np.add.outer(np.arange(lo[0], hi[0] + 1) * vox.dims[1], np.arange(lo[1], hi[1] + 1)).ravel()
        cols *= vox.dims[2]
        k = round(1.0 / share)  # the layer: every k-th point of the ordered cloud
        starts = (vox.starts + (k - 1)) // k if k > 1 else vox.starts  # the first multiple of k from each start
        first = starts[np.searchsorted(vox.keys, cols + lo[2], side="left")]
        last = starts[np.searchsorted(vox.keys, cols + hi[2], side="right")]
        counts = last - first
        nz = counts > 0
        first, last, counts = first[nz], last[nz], counts[nz]
        total = int(counts.sum())
        if total == 0:
            return empty
        # Concatenate the runs [first, last) without a Python loop: a run of ones, jumping at each run.
        steps = np.ones(total, np.intp)
        steps[0] = first[0]
        steps[np.cumsum(counts[:-1])] = first[1:] - last[:-1] + 1
        idx = np.cumsum(steps) * k
        xyz = np.ascontiguousarray(np.take(self.points, idx, axis=0).T)  # (3, m): column reductions are faster
        x, y, z = xyz[0] - a[0], xyz[1] - a[1], xyz[2] - a[2]
        s = x * t[0] + y * t[1] + z * t[2]
        d2 = x * x + y * y + z * z - s * s
        keep = np.flatnonzero((s >= 0.0) & (s <= span) & (d2 <= radius * radius))
        return np.take(xyz, keep, axis=1), np.asarray(self.camera[idx[keep]], np.intp)


def index_of(cloud: Cloud, voxels: VoxelTable | None = None, voxel_m: float = INDEX_VOXEL_M) -> CloudIndex:
    """:class:`CloudIndex` of ``cloud``: in voxel order with its table ``voxels`` when given, else ordered
    here on a grid of ``voxel_m`` [m]."""
    if voxels is None:
        cloud, voxels = voxel_order(cloud, voxel_m)
    return CloudIndex(np.asarray(cloud.points), cloud.camera, voxels)


def dense_index(scene: SeamScene) -> CloudIndex:
    """:func:`index_of` ``scene.dense`` (with ``scene.dense_voxels`` when perception ordered it), built once per
    scene and kept in ``scene.cache``."""
    index = scene.cache.get(_INDEX_KEY)
    if index is None:
        index = scene.cache[_INDEX_KEY] = index_of(scene.dense, scene.dense_voxels)
    return index


def plane_intersection(
    n_a: FloatArray, d_a: float, n_b: FloatArray, d_b: float, p_near: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Line where two planes meet: the point (3,) of it nearest ``p_near`` and its unit direction n_a x n_b
    (3,).

    Raises ValueError when the planes are (nearly) parallel.
    """
    ax, ay, az = (float(v) for v in n_a)
    bx, by, bz = (float(v) for v in n_b)
    t = np.array([ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx])
    norm2 = float(t @ t)  # = 1 - c^2 for unit normals
    if norm2 < 1e-12:
        raise ValueError("planes are parallel: they do not meet in a line")
    t = t / np.sqrt(norm2)
    c = ax * bx + ay * by + az * bz
    # The point of the line nearest the origin is a n_a + b n_b; then slide along t to the one nearest p_near.
    a = (d_a - d_b * c) / norm2
    b = (d_b - d_a * c) / norm2
    p0 = a * np.asarray(n_a, float) + b * np.asarray(n_b, float)
    p0 = p0 + float(t @ (np.asarray(p_near, float) - p0)) * t
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
    sigmas : (n,) the per-group noise scale each point was weighted by [m].
    """

    coef: FloatArray
    cov: FloatArray
    scale: float
    weights: FloatArray
    sigmas: FloatArray  # (n,) the noise scale each point was weighted by [m]

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


def robust_plane_fit(
    r: FloatArray,
    X: FloatArray,
    groups: IntArray,
    start: float,
    min_scale: float = 1e-4,
    iterations: int = 10,
    min_group: int = 40,
    prior_precision: FloatArray | None = None,
    sigmas: FloatArray | None = None,
    rescale_at: tuple[int, ...] = (0, 3),
) -> PlaneFit:
    """Iteratively reweighted least squares with Tukey's biweight and per-group noise weighting.

    r : (n,) signed distances of the points from a reference plane [m].
    X : (n, k) design matrix; column 0 must be ones (the offset), others e.g. in-plane coordinates (tilts).
    groups : (n,) non-negative group (camera) index of each point; groups of at least ``min_group`` points get
        their own robust scale (the others the pooled one) and points weigh 1/scale^2.
    start : initial offset [m] (e.g. a histogram mode).
    min_scale : floor on the robust scale [m] (noise-free data).
    prior_precision : (k,) precision of a zero-mean Gaussian prior on each coefficient (0: none), in the units
        of the weighted normal equations (1 / coefficient^2): a ridge that keeps tilts small unless the data
        demand them. None: no prior.
    sigmas : (n,) noise scale of each point [m] when already known (e.g. from an earlier fit of the same
        points): used as is. Otherwise the scales are measured (a robust MAD per group) at the iterations
        ``rescale_at`` (about the start, and again once the offset has settled), then held fixed so that the
        iteration converges.
    """
    n, k = X.shape
    coef = np.zeros(k)
    coef[0] = start
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
    lam = np.zeros(k) if prior_precision is None else np.asarray(prior_precision, float)
    w = np.ones(n)
    sig = np.full(n, min_scale) if sigmas is None else np.maximum(np.asarray(sigmas, float), min_scale)
    inv_sig2 = 1.0 / (sig * sig)
    inv_cut2 = inv_sig2 / (TUKEY_C * TUKEY_C)
    for it in range(iterations):
        res = r - coef[0] if k == 1 else r - X @ coef
        if sigmas is None and it in rescale_at:
            sig = _group_scales(res, labels, n_groups, min_scale)
            inv_sig2 = 1.0 / (sig * sig)
            inv_cut2 = inv_sig2 / (TUKEY_C * TUKEY_C)
        w = 1.0 - res * res * inv_cut2
        np.maximum(w, 0.0, out=w)
        w *= w
        ww = w * inv_sig2
        if k == 1:
            sw = float(ww.sum())
            if sw <= 0.0:
                break
            new = np.array([float(ww @ r) / (sw + lam[0])])
        else:
            if np.count_nonzero(w) < k + 1:
                break
            XtW = X.T * ww
            try:
                new = np.asarray(np.linalg.solve(XtW @ X + np.diag(lam), XtW @ r), dtype=np.float64)
            except np.linalg.LinAlgError:
                break
        done = float(np.max(np.abs(new - coef))) < 1e-6
        coef = new
        if done and it >= max(rescale_at if sigmas is None else (0,)):
            break
    res = r - coef[0] if k == 1 else r - X @ coef
    ww = w * inv_sig2
    inl = w > 0
    n_eff = max(int(np.count_nonzero(inl)), k + 1)
    if k == 1:  # the sandwich in scalars
        h = float(ww.sum()) + lam[0]
        wr = ww * res
        cov = np.array([[float(wr @ wr) / (h * h) * n_eff / (n_eff - 1)]]) if h > 0.0 else np.full((1, 1), np.inf)
    else:
        XtW = X.T * ww
        try:
            Hinv = np.linalg.inv(XtW @ X + np.diag(lam))
            meat = (X.T * (ww * res) ** 2) @ X
            cov = Hinv @ meat @ Hinv * n_eff / (n_eff - k)
        except np.linalg.LinAlgError:
            cov = np.full((k, k), np.inf)
    scale = MAD_TO_SIGMA * _mad(np.abs(res[inl])) if np.any(inl) else float("inf")
    return PlaneFit(coef=coef, cov=cov, scale=scale, weights=w, sigmas=sig)


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


@dataclass(frozen=True)
class EdgeFit:
    """Result of :func:`edge_fit`: where a locally uniform density sampled along s ends, and how well the sample
    defines it.

    b : the edge [m] (NaN when the window holds fewer than 5 points).
    se : its standard error from the curvature of the profile likelihood [m] (statistical only; inf when the
        likelihood has no interior maximum).
    blur : the Gaussian blur of the best fit [m] (the noise across the edge: depth noise seen along the
        surface, which grows with the incidence).
    n_edge : points within ``max(3 blur, 2 mm)`` inside the edge (how many points define it).
    strays : density of the points beyond ``b + 3 blur`` relative to the density inside the edge (flying
        pixels, a second surface); 0 when no room is left beyond.
    pitch : mean spacing of the points along s inside the edge, ``1 / density`` [m] (with the edge's length,
        the caller turns it into a point pitch on the surface).
    at_limit : the edge lies within a coarse step (``5 step``) of the searched range's ends, or within ``2 blur``
        of the window's upper end: the sample's own cut-off (a crop, a selection), not an edge.
    """

    b: float
    se: float
    blur: float
    n_edge: int
    strays: float
    pitch: float
    at_limit: bool

    @property
    def ok(self) -> bool:
        """A maximum inside the searched range with a finite standard error."""
        return bool(np.isfinite(self.b) and np.isfinite(self.se) and not self.at_limit)


EDGE_BLURS = (2e-4, 5e-4, 1e-3, 1.5e-3, 2.5e-3)  # [m]
EDGE_WINDOW_M = 0.01  # half-width of the window about a guess that :func:`edge_ml` reads [m]


def edge_fit(
    s: FloatArray,
    lo: float,
    hi: float,
    b_lo: float,
    b_hi: float,
    step: float = 1e-4,
    blurs: tuple[float, ...] = EDGE_BLURS,
    stray: float = 0.01,
    max_points: int = 400,
) -> EdgeFit:
    """Maximum-likelihood upper edge b [m] of a locally uniform density sampled at s (n,) blurred by Gaussian
    noise, searched in [b_lo, b_hi] from the points inside the window (lo, hi) [m]; for a lower edge pass -s
    (and the negated, swapped bounds) and negate the result.

    The caller must pass every point of the window: a selection that stops inside it is a cut-off that looks
    like an edge (:attr:`EdgeFit.at_limit` flags an edge found there). Within the window the density is
    proportional to Phi((b - s) / sigma) (plus a small ``stray`` floor for points far beyond the edge),
    normalised over the window, so neither the density nor the count needs to be known. b is searched on a grid
    of ``step`` (coarse to fine), the blur sigma over ``blurs``; the standard error comes from the curvature of
    the profile log-likelihood. Above ``2 max_points`` points in the window, an even stride of the sorted
    sample is used for the likelihood (the counts of :class:`EdgeFit` use them all).
    """
    from scipy.special import ndtr

    nan = float("nan")
    x_all = np.sort(s[(s > lo) & (s < hi)])
    if len(x_all) < 5:
        return EdgeFit(nan, float("inf"), nan, len(x_all), 0.0, nan, True)
    x = x_all[:: len(x_all) // max_points] if len(x_all) > 2 * max_points else x_all
    sig = np.asarray(blurs, np.float64)

    # Coarse to fine: a grid of 5 steps over [b_lo, b_hi], on the points binned by 5 steps and for every other
    # blur (the best edge only has to fall within the fine grid), then of one step around the coarse best, on
    # the points themselves and for every blur.
    coarse = np.asarray(np.arange(b_lo, b_hi + 2.5 * step, 5.0 * step), np.float64)
    width = 5.0 * step
    bins = np.bincount(((x - lo) / width).astype(np.intp))
    filled = np.flatnonzero(bins)
    at = np.asarray(lo + (filled + 0.5) * width, np.float64)
    sig_c = sig[::2]
    z = (coarse[None, :, None] - at[None, None, :]) / sig_c[:, None, None]
    ll_c = (np.log(ndtr(z) + stray) * bins[filled]).sum(axis=2)  # the normalisation is the same for every blur
    ll_c -= len(x) * np.log((coarse - lo) + stray * (hi - lo))
    centre = float(coarse[int(np.argmax(ll_c.max(axis=0)))])
    b = np.asarray(centre + step * np.arange(-6, 7), np.float64)  # (13,)
    # Points more than 6 blurs inside (outside) every b add log(1 + stray) (log(stray)) whatever b, to within
    # 1e-7: only those nearer are evaluated, for each blur (x is sorted).
    ll = np.empty((len(sig), len(b)))
    norm = len(x) * np.log((b - lo) + stray * (hi - lo))
    for j, sj in enumerate(blurs):
        i0, i1 = np.searchsorted(x, (b[0] - 6.0 * sj, b[-1] + 6.0 * sj))
        z = (b[:, None] - x[None, i0:i1]) / sj
        far = i0 * np.log1p(stray) + (len(x) - i1) * np.log(stray)
        ll[j] = np.log(ndtr(z) + stray).sum(axis=1) + far - norm
    best = ll.max(axis=0)
    i = int(np.argmax(best))
    pos, se = float(b[i]), float("inf")
    if 0 < i < len(b) - 1:
        c2 = best[i - 1] - 2.0 * best[i] + best[i + 1]
        if c2 < 0.0:
            pos += float(0.5 * (best[i - 1] - best[i + 1]) / c2) * step
            se = float(step / np.sqrt(-c2))
    blur = float(sig[int(np.argmax(ll[:, i]))])
    inside = max(3.0 * blur, 0.002)
    n_edge = int(np.count_nonzero((x_all > pos - inside) & (x_all <= pos)))
    core = x_all[x_all < pos - 3.0 * blur]
    density = len(core) / max(pos - 3.0 * blur - lo, step)  # [1/m]
    room = hi - (pos + 3.0 * blur)
    beyond = int(np.count_nonzero(x_all > pos + 3.0 * blur))
    strays = beyond / (density * room) if room > step and density > 0.0 else 0.0
    pitch = 1.0 / density if density > 0.0 else float("inf")
    at_limit = pos - b_lo < 5.0 * step or b_hi - pos < 5.0 * step or hi - pos < 2.0 * blur
    return EdgeFit(pos, se, blur, n_edge, float(strays), float(pitch), bool(at_limit))


def edge_ml(
    s: FloatArray,
    guess: float,
    inner: float = EDGE_WINDOW_M,
    search: float = 0.003,
    step: float = 1e-4,
    blurs: tuple[float, ...] = EDGE_BLURS,
    stray: float = 0.01,
    max_points: int = 400,
) -> tuple[float, float]:
    """:func:`edge_fit` of the points within ``guess +- inner`` [m], the edge searched within ``guess +-
    search`` [m]: (edge [m], its standard error [m]); inf when the likelihood has no interior maximum."""
    f = edge_fit(s, guess - inner, guess + inner, guess - search, guess + search, step, blurs, stray, max_points)
    if not np.isfinite(f.b):
        return guess, float("inf")
    return f.b, f.se


def line_box_span(p0: FloatArray, t: FloatArray, box: Box) -> tuple[float, float]:
    """Parameters (s_in, s_out) [m] where the line p0 + s t (3,) (frame of ``box``) enters and leaves ``box``;
    (inf, -inf) when it misses it."""
    R, c = box.X_AB[:3, :3], box.center
    o, d = R.T @ (np.asarray(p0, float) - c), R.T @ np.asarray(t, float)
    h = 0.5 * np.asarray(box.size, float)
    s_in, s_out = -np.inf, np.inf
    for k in range(3):
        if abs(d[k]) < 1e-12:
            if abs(o[k]) > h[k]:
                return float("inf"), float("-inf")
            continue
        a, b = (-h[k] - o[k]) / d[k], (h[k] - o[k]) / d[k]
        s_in, s_out = max(s_in, min(a, b)), min(s_out, max(a, b))
    return (float(s_in), float(s_out)) if s_in <= s_out else (float("inf"), float("-inf"))


def cloud_box(scene: SeamScene) -> Box:
    """The bounds of ``scene.dense`` along the axes of R (a box in R), cached per scene: where a passthrough
    crop of the workspace cut the cloud, when the workspace is axis-aligned in R."""
    box = scene.cache.get(_BOX_KEY)
    if box is None:
        vox = dense_index(scene).voxels
        lo, hi = (vox.lo, vox.hi) if len(vox) else (np.zeros(3), np.ones(3))
        box = Box(make_pose(p=0.5 * (lo + hi)), np.maximum(hi - lo, 1e-9))
        scene.cache[_BOX_KEY] = box
    return box
