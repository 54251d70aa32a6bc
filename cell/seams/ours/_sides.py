"""The points on A's side faces at a seam's ends that a pass fits with the weld faces (frame R, metres): A's own
side face where it is seen, or, where it lies hidden against another part, the face of that part beside A."""

from __future__ import annotations

import numpy as np

from cell.geometry import FloatArray
from cell.seams.ours._geometry import JointGeometry, within
from cell.seams.ours._planes import END_KEYS, End, Face, Selection, thin
from cell.seams.ours._points import BoolArray, IntArray, Points
from cell.seams.ours.options import OursOptions

# How far into another part a point on its face is taken to test that it lies on that face, not beside it [m].
_INTO_M = 0.001


def side_selections(
    ends: tuple[End, End],
    pts: Points,
    r_a: FloatArray,
    r_b: FloatArray,
    face_b: Face,
    geo: JointGeometry,
    first: bool,
    slack: float,
    o: OursOptions,
    n_a: FloatArray,
) -> list[Selection]:
    """The points on A's side faces at the seam's ends (where they are seen well enough to place an end),
    to be fitted with the weld faces (``n_a``: face A's unit normal (3,))."""
    if not geo.has_sides:
        return []
    # The bands across the side face, no wider than a share of a thin plate's extent (its depth, its height).
    band_b = within(max(o.corner_band_m, 3.0 * face_b.scale) + slack, geo.length_a)
    eb_d, eb_h = within(o.edge_band_m + slack, geo.depth_a), within(o.edge_band_m + slack, geo.length_a)
    side = (r_a < -eb_d) & (r_a > -(geo.depth_a - eb_d)) & (r_b >= band_b) & (r_b <= geo.length_a - eb_h) & pts.ok
    # A side face seen at all shows a good part of the points its patch would hold seen well; a few
    # dozen flying pixels off an edge (a face seen at grazing incidence drops out) must not pass for it.
    patch = (min(geo.depth_a, o.tube_radius_m) - 2.0 * within(o.edge_band_m, geo.depth_a)) * (
        min(geo.length_a, o.tube_radius_m) - band_b - within(o.edge_band_m, geo.length_a)
    )
    need = max(o.min_end_points, int(o.min_end_fill * max(patch, 0.0) / pts.pitch**2))
    # A side face against another part's face is hidden: that face's points beside A place it (in front of
    # face A, as far from B as A's own side would be); they belong to another part, so ``pts.ok`` cannot hold them.
    beside = (r_a > eb_d) & (r_a < o.tube_radius_m) & (r_b >= band_b) & (r_b <= geo.length_a - eb_h)
    out = []
    for key, end in zip(END_KEYS, ends, strict=True):
        if end.on_table:
            continue
        r_l = pts.along(end.n) - end.d
        gate = (o.map_tolerance_m + 3.0 * o.sensor_sigma_m) if first else o.gate_sigmas * end.scale
        near = np.abs(r_l) < gate
        # On the other part's face, never as deep as its far side (an upright's other face, 12 mm behind).
        if end.touching:
            sel = np.flatnonzero(beside & near & (r_l < 0.5 * end.touching) & pts.facing(-end.n, -end.d))
            sel = sel[on_face(end, pts, sel, r_l, n_a, o.edge_band_m)]
            if len(sel) >= need:
                out.append(_side(key, end, r_l, sel, need, r_a, r_b, o))
            continue
        near &= pts.facing(end.n, end.d)  # seen from in front: a hollow tube's inner wall is not its side face
        if end.inset:  # a tube's side flat begins past its corner radius, below face A and above its far side
            sel = np.flatnonzero(side & near & (r_a < -eb_d - end.inset) & (r_a > end.inset - (geo.depth_a - eb_d)))
        else:
            sel = np.flatnonzero(side & near)
        if len(sel) >= need:
            out.append(_side(key, end, r_l, sel, need, r_a, r_b, o))
    return out


def _side(
    key: str, end: End, r_l: FloatArray, sel: IntArray, need: int, r_a: FloatArray, r_b: FloatArray, o: OursOptions
) -> Selection:
    """The selection of a side face's points ``sel`` (heights ``r_l`` over its plane), with where its fitted points
    lie over faces A and B (``r_a``, ``r_b`` [m]): the plane's turn is read from them (:class:`Selection`)."""
    fit = thin(sel, o.max_fit_points)
    return Selection(key, end, r_l, sel, fit, need, np.stack([r_a[fit], r_b[fit]]))


def on_face(end: End, pts: Points, sel: IntArray, r_l: FloatArray, n_a: FloatArray, band: float) -> BoolArray:
    """(len(sel),) which of the points ``sel`` (``r_l``: their height over the end's plane [m]) lie on the face of
    the part a hidden side face is against, not on that part's faces at an angle to it seen beside A (a box's side,
    which runs back from the face at the distance it reaches in front of A): each point taken onto the plane and
    just into the part must lie inside it there and still ``band`` [m] further from A (``n_a``: face A's unit
    normal (3,)). A hollow part (a tube) counts only where its wall is."""
    if end.against is None or not len(sel):
        return np.ones(len(sel), bool)
    q = pts.xyz[:, sel].T + np.outer(min(0.5 * end.touching, _INTO_M) - r_l[sel], end.n)
    inside = np.asarray(end.against.contains(np.vstack([q, q + band * np.asarray(n_a)])), bool)  # one pass of the body
    return inside[: len(sel)] & inside[len(sel) :]
