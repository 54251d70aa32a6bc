"""The ends of a seam our locator finds (frame R, metres): where the fitted line meets A's side face across it
(fitted with the weld faces), the table, or the extent of face A's points along it (an empirical CDF extrapolated,
refined as a blurred edge, :mod:`cell.seams._extent`). On a rounded tube the end lies short of the side face (or
the table) by the map's inset, the corner radius; an end whose side is not seen lies the drawn width from the
other, or, with no side seen, at the tangent line where face A's points bend away round the radius (docs/bodies.md
section 8)."""

from __future__ import annotations

import functools
from collections.abc import Callable

import numpy as np

from cell.geometry import FloatArray
from cell.seams._extent import EDGE_WINDOW_M, EdgeFit, cdf_extent, edge_fit
from cell.seams._lines import line_plane_parameter
from cell.seams.ours._geometry import within
from cell.seams.ours._planes import End, Face
from cell.seams.ours._points import Points
from cell.seams.ours._shear import end_shear
from cell.seams.ours.options import OursOptions
from cell.types import EndSource

# How far a hollow section's flat may be wider or narrower than drawn [m] (docs/reference.md: EN 10219-2's
# outer-size tolerance, 1 % of a 60 mm side, at least 0.5 mm).
SECTION_TOLERANCE_M = 5e-4


# How each way find_ends places an end is reported (End.source -> EndSource): A's side face fitted where it meets
# face A is an edge seen; face A's points ending (their extent, an edge's likelihood, the tangent line into a
# radius) a face seen ending; the table, or another part's face a hidden side face lies on, another part; the map's
# end, or the drawn width from the other end, the drawn length.
_SOURCES = {
    "side face": EndSource.EDGE,
    "extent": EndSource.FACE_END,
    "tangent": EndSource.FACE_END,
    "table": EndSource.OTHER_PART,
    "width": EndSource.DRAWN,
    "map": EndSource.DRAWN,
}


def end_source(end: End) -> EndSource:
    """How ``end`` was placed, as an :class:`EndSource` (a side face against another part's face: that part)."""
    if end.source == "side face" and end.touching:
        return EndSource.OTHER_PART
    return _SOURCES[end.source]


EDGE_SEARCH_M = 0.003  # how far from the extent's guess an end's edge is searched [m] (as edge_ml's)
TANGENT_WINDOW_M = 0.008  # points this far along the line about the extent's guess place a tangent end [m]
_TANGENT_STEP_M = 5e-5  # the grid the tangent line is searched on [m]


def tangent_end(s: FloatArray, r: FloatArray, guess: float, radius: float, scale: float) -> tuple[float, float]:
    """Where a flat ends into a corner of ``radius`` [m] (the upper end along s; pass -s for a lower end):
    (s0 [m], its standard error [m]; inf when the data do not define it), from points at s (n,) with offsets r
    (n,) from the flat's plane (outward positive) [m], ``scale`` their noise [m].

    Profile: r = 0 up to s0, then -(radius - sqrt(radius^2 - (s - s0)^2)) round the corner. s0 is searched within
    ``[guess - radius, guess + radius / 2]`` (the extent of the points near the plane runs past the tangent line);
    the points deeper than a third of the radius (the side beyond the corner) are left out, and each residual is
    capped at 3 scales (strays, a tack). The standard error comes from the curvature of the profile likelihood."""
    sigma = max(scale, 5e-5)
    keep = (r > -radius / 3.0) & (s > guess - 2.0 * radius) & (s < guess + radius)
    s, r = s[keep], r[keep]
    if len(s) < 20:
        return guess, float("inf")
    grid = np.arange(guess - radius, guess + 0.5 * radius, _TANGENT_STEP_M)
    h = np.clip(s[None, :] - grid[:, None], 0.0, radius)
    model = -(radius - np.sqrt(radius * radius - h * h))
    cost = np.minimum(np.square((r[None, :] - model) / sigma), 9.0).sum(axis=1)
    i = int(np.argmin(cost))
    if not 0 < i < len(grid) - 1:
        return guess, float("inf")
    c2 = 0.5 * (cost[i - 1] - 2.0 * cost[i] + cost[i + 1])  # -log-likelihood's second difference
    if c2 <= 0.0:
        return float(grid[i]), float("inf")
    shift = 0.25 * (cost[i - 1] - cost[i + 1]) / c2
    # The curvature understates it (the residuals are capped, the points not independent, a drawn radius is
    # facets): no better than the points' noise, which is what a close-up's ends scatter by on rhs.
    return float(grid[i] + shift * _TANGENT_STEP_M), float(max(_TANGENT_STEP_M / np.sqrt(c2), sigma))


def edge_bias(pitch: float, scale: float) -> float:
    """What an end read where face A's points stop may be off by that no fit sees [m]: what a sampled edge cannot
    resolve (it lies anywhere within a ``pitch`` [m] of the last sample: pitch / sqrt 12, one camera's rows sharing
    their phase) and the edge's blur ``scale`` [m] (the points' noise, or the blur fitted across the edge when
    wider: a blurred edge's bias, the end face's points within face A's gate, a face seen at grazing incidence
    smeared along it, points thinning out towards a corner), in quadrature."""
    return float(np.sqrt(pitch * pitch / 12.0 + scale * scale))


# A side face's points scattering about their fitted plane more than this many times the sensor's noise are not one
# face: a 6 mm brace's side, a strip narrower than the noise seen from 1.5 m, mixes its neighbours' points and read
# its end 7-12 mm off (random cells; well-seen side faces scatter 0.5-1 times the noise). Its end comes from the
# extent of face A's points instead.
SIDE_SCATTER_LIMIT = 1.5


def find_ends(
    ends: tuple[End, End],
    sides_se: dict[int, float],
    pts: Points,
    dense: Callable[[FloatArray, FloatArray], Points] | None,
    face_a: Face,
    face_b: Face,
    p0: FloatArray,
    t: FloatArray,
    s_map: list[float],
    face_a_height: float,
    o: OursOptions,
    end_face: tuple[FloatArray, float],
) -> tuple[End, End]:
    """Both ends placed on the fitted line p0 + s t: the table where A rests on it, A's side face where it was
    fitted (``sides_se``: the standard error of each fitted side face's offset, by end index), else the extent of
    face A's support along the seam: the quantiles of its points in ``pts`` extrapolated, then refined as an edge
    in the ``dense`` points of a short tube about it (None: not refined, as in a pass before the last). An end
    short of its plane by an inset (a rounded tube) and not seen lies the drawn width from an end on A's side face,
    else at the tangent line fitted in the ``dense`` points (:func:`tangent_end`).
    ``face_a_height``: face A's extent away from B [m] (a thin plate's side keeps a window above the corner band);
    ``end_face``: A's end face's plane (n, d) from the aligned map (where a skewed side line ends, :class:`Shear`)."""
    placed = list(ends)
    known = [False, False]
    shear = end_shear(ends, face_a.n, face_b.n, t, p0, end_face)
    # A side face at an angle meets the seam's line past A's edge on its end face (by the gap seen across it): the
    # end is where it meets the line through that edge (the edge projected on the seam), as for a square one.
    at_edge = p0 + shear.h0 * shear.w if shear.c or shear.ends else p0
    for k, end in enumerate(ends):
        if end.on_table:
            placed[k] = end.at(line_plane_parameter(at_edge, t, end.n, end.d - end.inset), 2e-4, "table")
            known[k] = True
        elif k in sides_se and end.scale <= SIDE_SCATTER_LIMIT * o.sensor_sigma_m:
            s = line_plane_parameter(at_edge, t, end.n, end.d - end.short_of)
            placed[k] = end.at(s, sides_se[k] / max(abs(float(end.n @ t)), 1e-3), "side face")
            known[k] = True
    for k, end in enumerate(ends):
        # A tube's flat ends into its radius, no edge to find: beside an end from A's own side face, the other end
        # lies the drawn flat's width away (to within the section's size tolerance).
        other = placed[1 - k]
        if not known[k] and end.inset and known[1 - k] and other.source == "side face" and not other.touching:
            width = s_map[1] - s_map[0]
            s = other.s + (width if k == 1 else -width)
            placed[k] = end.at(s, other.se, "width", other.sigma, float(np.hypot(other.bias, SECTION_TOLERANCE_M)))
            known[k] = True
    for k, end in enumerate(ends):
        # A hidden side face whose other part's face was not seen: face A's points stop short of that part (points
        # near another part are not used), so where they stop is no end: the map's, the tolerance its sigma (the
        # seam is found across, its end waits for a close-up: the confidence reads only what the points placed).
        if not known[k] and end.touching:
            placed[k] = end.at(s_map[k], 0.0, "map", sigma=o.map_tolerance_m)
            known[k] = True
    if all(known) or face_a.source != "points":
        for k, end in enumerate(ends):
            if not known[k]:
                placed[k] = end.at(s_map[k], o.map_tolerance_m, "map")
        return placed[0], placed[1]
    # Face A's support along t; a known end's neighbourhood is cut away (A's side face shows up there),
    # which only shifts the CDF by a constant and leaves the other end's extrapolation unbiased.
    band_b = within(max(o.corner_band_m, 3.0 * face_b.scale), face_a_height)
    cut = o.edge_band_m + 3.0 * face_a.scale
    s_known = [end.s for end in placed]

    def along_a(pts: Points, k: int | None = None) -> FloatArray:
        """The parameters along the line of the points of face A's support among ``pts``, carried along end k's
        side lines (None: the mean slope's)."""
        r_a = pts.along(face_a.n) - face_a.d
        r_b = pts.along(face_b.n) - face_b.d
        s = shear.s(pts, p0, t, k)
        near_a = (np.abs(r_a) < 2.5 * face_a.scale) & (r_b >= band_b) & (r_b <= o.tube_radius_m) & pts.ok
        if k is not None:  # only where end k's own side face ends A
            near_a &= shear.beside(pts, p0, k, 0.0)
        near_a &= pts.facing(face_a.n, face_a.d)
        if known[0]:
            near_a &= s > s_known[0] + cut
        if known[1]:
            near_a &= s < s_known[1] - cut
        return s[near_a]

    def profile_a(pts: Points, k: int) -> tuple[FloatArray, FloatArray]:
        """Parameters along the line (end k's side lines) and offsets from face A of the points of A's flat and of
        the corner radius it ends into (down to a third of the radius below the plane) among ``pts``."""
        r_a = pts.along(face_a.n) - face_a.d
        r_b = pts.along(face_b.n) - face_b.d
        s = shear.s(pts, p0, t, k)
        on = (r_a < 3.0 * face_a.scale) & (r_b >= band_b) & (r_b <= o.tube_radius_m) & pts.ok
        return s[on], r_a[on]

    extents: dict[float, tuple[FloatArray, tuple[float, float, float] | None]] = {}
    for k, end in enumerate(ends):
        if known[k]:
            continue
        # Each end's extent along its own side lines (a gusset's snipe and its square toe lean differently).
        c = shear.slope(k)
        if c not in extents:
            s_c = along_a(pts, k)
            extents[c] = (s_c, cdf_extent(s_c) if len(s_c) >= pts.least(o.min_face_points) else None)
        s_a, extent = extents[c]
        if extent is None:
            placed[k] = end.at(s_map[k], o.map_tolerance_m, "map")
            continue
        # Where no edge confirms it, the extrapolated end is only as good as the density is uniform out to it: a
        # face partly hidden or out of view thins its points unevenly, and the extrapolation then lands well away
        # from where they stop. That disagreement joins the end's sigma as a bias.
        unconfirmed = end.at(extent[k], extent[2], "extent", bias=abs(extent[k] - (s_a.min(), s_a.max())[k]))
        if dense is None:
            placed[k] = unconfirmed
        elif end.inset:
            # A flat that ends into a corner radius has no edge: its points bend away from the plane past the tangent
            # line, and the extent of those near the plane runs on into the radius. Fit the radius's profile.
            sign = 1.0 if k == 1 else -1.0
            wide = TANGENT_WINDOW_M + abs(c) * o.tube_radius_m
            d = dense(p0 + (extent[k] - wide) * t, p0 + (extent[k] + wide) * t)
            s_d, r_d = profile_a(d, k)
            s0, se = tangent_end(sign * s_d, r_d, sign * extent[k], end.inset, face_a.scale)
            placed[k] = end.at(sign * s0, se, "tangent") if np.isfinite(se) else unconfirmed
        else:
            # Refine the CDF's extrapolation by the edge's own sharpness (blurred-step likelihood), on every
            # point of the dense cloud within the likelihood's window about it.
            sign = 1.0 if k == 1 else -1.0
            reach = EDGE_WINDOW_M + o.edge_band_m + abs(c) * o.tube_radius_m  # the whole side line's points
            mine = functools.partial(along_a, k=k)
            d, s_d, fit = _edge_in(dense, mine, p0, t, sign, extent[k], reach)
            if fit.at_limit:
                # The best edge at the end of the range searched: the extrapolation was that far off (a face thinned
                # out unevenly). Searched again about the face's last point; at the limit again, no edge was found
                # (a density that falls off over millimetres, a face seen ever more edge-on, strays far past it):
                # the extrapolation stands, with its miss.
                d, s_d, fit = _edge_in(dense, mine, p0, t, sign, (s_a.min(), s_a.max())[k], reach)
            if fit.ok:
                # The curvature understates the scatter of a blurred edge: the confidence reads it no better than
                # 3 spacings; the end's sigma is the likelihood's standard error and what the sample cannot resolve
                # (edge_bias).
                inside = np.count_nonzero(np.abs(s_d - fit.b) < EDGE_WINDOW_M)
                density = inside / (2.0 * EDGE_WINDOW_M)  # [1/m]
                bias = edge_bias(d.pitch, max(face_a.scale, fit.blur))
                placed[k] = end.at(sign * fit.b, max(fit.se, 3.0 / max(density, 1.0)), "extent", fit.se, bias)
            else:
                placed[k] = unconfirmed
    return placed[0], placed[1]


def _edge_in(
    dense: Callable[[FloatArray, FloatArray], Points],
    along: Callable[[Points], FloatArray],
    p0: FloatArray,
    t: FloatArray,
    sign: float,
    guess: float,
    reach: float,
) -> tuple[Points, FloatArray, EdgeFit]:
    """The dense points within ``reach`` [m] of ``guess`` (a parameter along p0 + s t [m]), the face's points'
    parameters among them times ``sign``, and the edge likelihood's fit of the face's end there, in its window about
    the guess, searched within :data:`EDGE_SEARCH_M` of it: the upper end for ``sign`` +1, the lower for -1 (the
    parameters and the fit's ``b`` are then negated). ``along``: the parameters of the face's points among dense
    points."""
    d = dense(p0 + (guess - reach) * t, p0 + (guess + reach) * t)
    s, g = sign * along(d), sign * guess
    return d, s, edge_fit(s, g - EDGE_WINDOW_M, g + EDGE_WINDOW_M, g - EDGE_SEARCH_M, g + EDGE_SEARCH_M)


def within_receiving(ends: tuple[End, End], s_b: tuple[float, float], margin: float) -> tuple[End, End]:
    """The ends, one placed past where B's face stops along the line (``s_b``: the drawn face's extent [m], by more
    than ``margin``) brought back to that edge, the map's: a fillet lies only where both faces are (a plate
    standing over a gap ends a brace's cheek fillet at its lower edge, above the brace's foot on the base). Where
    B's face does not hold the seam's middle (the line misses the drawn face: no chord of it), nothing is moved."""
    if not s_b[0] < 0.5 * (ends[0].s + ends[1].s) < s_b[1]:
        return ends
    start = ends[0].at(s_b[0], 0.0, "map") if ends[0].s < s_b[0] - margin else ends[0]
    stop = ends[1].at(s_b[1], 0.0, "map") if ends[1].s > s_b[1] + margin else ends[1]
    return start, stop
