"""Where the cloud shows a part's face running on past the edge the drawing gives it near a seam: the part does not
lie as drawn relative to the others (a tube butted 17 mm off the middle of its cross tube), which no rigid fit of the
whole map absorbs. It turns "this face is not seen" into what it is, a deviation from the drawing, with its size
(docs/locate.md, "Clouds without a table"). Frame R, metres."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cell.geometry import FloatArray
from cell.types import MapSeam, WeldMap

RADIUS_M = 0.06  # the points looked at: this close to the drawn seam's line
MIN_POINTS = 8  # fewer points past the edge than this tell nothing
PAST_SHARE = 95.0  # how far past the edge: this percentile of the points' distances beyond it (noise aside)


@dataclass(frozen=True)
class PastEdge:
    """A face of the aligned map that the cloud continues past its drawn edge near a seam.

    part, face : the part's name and face (``"-x"``...). points : how many points lie in the face's plane beyond the
    drawn face, near the seam. past_m : how far beyond its edge they run [m] (the PAST_SHARE percentile).
    """

    part: str
    face: str
    points: int
    past_m: float

    def describe(self) -> str:
        """One clause for a seam's reason."""
        return (
            f"{self.points} points lie in the plane of face {self.part} {self.face} up to {self.past_m * 1e3:.0f} mm "
            "past the edge the drawing gives it: the part does not lie as drawn (a deviation from the drawing)"
        )


def _outside_m(uv: FloatArray, poly: FloatArray) -> FloatArray:
    """(n,) distance [m] of 2D points (n, 2) outside the convex polygon (m, 2) (0 inside): the largest
    distance beyond any of its edges' lines (its corners counted as their edges meeting)."""
    c = poly.mean(axis=0)
    a, b = poly, np.roll(poly, -1, axis=0)
    e = b - a
    out = np.column_stack([e[:, 1], -e[:, 0]]) / np.linalg.norm(e, axis=1)[:, None]
    out *= np.sign(np.einsum("ij,ij->i", out, a - c))[:, None]  # outward whichever way the polygon turns
    beyond = np.einsum("nmk,mk->nm", uv[:, None, :] - a[None, :, :], out)
    return np.maximum(beyond.max(axis=1), 0.0)


def past_drawn_edge(
    weldmap_R: WeldMap, part_name: str, face: str, seam: MapSeam, points_R: FloatArray, band_m: float
) -> PastEdge | None:
    """How the cloud ``points_R`` (n, 3) continues face ``face`` of part ``part_name`` past its drawn edge near
    ``seam`` (within RADIUS_M of its line): the points within ``band_m`` [m] of the face's plane, outside every
    other part (by ``band_m``), beyond the drawn face by more than ``band_m``; None when fewer than MIN_POINTS, or
    for a part that is not a box (a polyhedron's face need not be convex)."""
    part = weldmap_R.part(part_name)
    if not part.is_box:
        return None
    n, d = part.face_plane(face)
    P = np.asarray(points_R, dtype=np.float64)
    t = seam.direction
    rel = P - seam.p_start
    s = np.clip(rel @ t, 0.0, float(np.linalg.norm(seam.p_end - seam.p_start)))
    near = np.linalg.norm(rel - np.outer(s, t), axis=1) < RADIUS_M
    near &= np.abs(P @ n - d) < band_m
    for other in weldmap_R.parts:
        if other.name != part_name and near.any():
            idx = np.flatnonzero(near)
            near[idx[other.contains(P[idx], band_m)]] = False
    if np.count_nonzero(near) < MIN_POINTS:
        return None
    poly = part.face_polygon(face)
    u = poly[1] - poly[0]
    u = u - (u @ n) * n
    u /= np.linalg.norm(u)
    v = np.cross(n, u)
    basis = np.stack([u, v], axis=1)
    beyond = _outside_m(P[near] @ basis, poly @ basis)
    past = beyond[beyond > band_m]
    if len(past) < MIN_POINTS:
        return None
    return PastEdge(part_name, face, len(past), float(np.percentile(past, PAST_SHARE)))
