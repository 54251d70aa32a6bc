"""Where a sampled density ends: the empirical CDF extrapolated, and a blurred-step likelihood (frame R, metres).

What our locator reads an end of a face's support from (:func:`cdf_extent`, refined by :func:`edge_ml`) and what
places a face no camera sees from the edge of an adjacent one (:func:`edge_fit`, :mod:`cell.seams._edge`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cell.geometry import FloatArray


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


def _log_normaliser(b: FloatArray, lo: float, hi: float, stray: float, n: int) -> FloatArray:
    """n times the log of the edge model's normalisation for edges at b (k,) [m] in the window [lo, hi]: +inf for an
    edge so far below the window that nothing of the model is left in it (its likelihood is then -inf, never NaN)."""
    mass = (b - lo) + stray * (hi - lo)
    return np.where(mass > 0.0, n * np.log(np.maximum(mass, 1e-300)), np.inf)


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
    ll_c -= _log_normaliser(coarse, lo, hi, stray, len(x))
    centre = float(coarse[int(np.argmax(ll_c.max(axis=0)))])
    b = np.asarray(centre + step * np.arange(-6, 7), np.float64)  # (13,)
    # Points more than 6 blurs inside (outside) every b add log(1 + stray) (log(stray)) whatever b, to within
    # 1e-7: only those nearer are evaluated, for each blur (x is sorted).
    ll = np.empty((len(sig), len(b)))
    norm = _log_normaliser(b, lo, hi, stray, len(x))
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
        if np.isfinite(c2) and c2 < 0.0:  # a neighbour below the window (-inf) leaves the grid's step as it is
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
