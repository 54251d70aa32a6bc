"""What our locator asks of a joint's bodies when they are not boxes (frame R, metres): how thick and how long the
abutting part is, its side faces across the seam's ends, and which points lie over the receiving face (with the
faces coplanar with it: one plane a drawing split into several faces).

A box answers these from its axes (:class:`cell.seams.ours._geometry.JointGeometry`); any closed planar-faced body
(:class:`cell.types.Polyhedron`) answers them from its vertices and face polygons here, the same quantities by
their definitions: the depth of A is its extent behind its weld face, its length its extent away from B (behind
its end face), a side face one of A's faces that crosses the seam line (its normal within :data:`SIDE_MAX_ANGLE_DEG`
of the line) where the map puts an end of the seam.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.types import Part, Polyhedron

BoolArray = npt.NDArray[np.bool_]
_PAIRS = 1_000_000  # point-edge pairs tested at once in over_region() (bounds the memory)
SIDE_MAX_ANGLE_DEG = (
    75.0  # a face of A ends the seam when its normal is this close to the seam's direction (a brace at 15 deg)
)
_SIDE_COS = math.cos(math.radians(SIDE_MAX_ANGLE_DEG))
_ACROSS_TIE = 1e-3  # faces whose normals' components along the line differ by less are as much across it


_ADJACENT_M = 5e-4  # a face holds the map's end when its polygon passes this near it [m] (a drawing's rounding)


def side_planes(
    part_a: Part, skip: tuple[str, ...], p0: FloatArray, t: FloatArray, s_map: tuple[float, float], reach_m: float
) -> tuple[tuple[FloatArray, float], tuple[FloatArray, float]] | None:
    """A's faces that end the seam line p0 + s t at its start and its end: ((n, d) at the start, (n, d) at the
    end), outward unit normals; None unless both ends have one.

    A face ends the line at the start when its outward normal points back along t (n . t <= -cos 60 deg), at the
    end when it points along t; of those whose plane meets the line within ``reach_m`` of the map's end ``s_map``,
    the one most across the line (a tube's side flat, not the facets of the corner radius before it: the seam
    ends short of that flat, :meth:`~cell.seams.ours._geometry.JointGeometry.end_planes`), the nearest of those as
    much across it (within :data:`_ACROSS_TIE`). Where some of them hold the map's end on their polygon (within
    :data:`_ADJACENT_M`), only those: a mitred brace's foot, flat on the base beside its cheek's lower end, is
    more across that cheek's line than the underside that ends it, but lies elsewhere. ``skip``: A's faces that
    hold the seam (the weld face and the end face)."""
    N, D = face_planes(part_a)
    c_all = N @ t
    names = part_a.face_names()
    crossing = np.array([name not in skip for name in names]) & (np.abs(c_all) >= _SIDE_COS)
    with np.errstate(divide="ignore", invalid="ignore"):
        s_all = (D - N @ p0) / c_all
    body = part_a.body
    adjacent = np.zeros(len(names), bool)
    if isinstance(body, Polyhedron):
        for i in np.flatnonzero(crossing):
            at = p0 + s_map[1 if c_all[i] > 0.0 else 0] * t
            adjacent[i] = float(body.face_distance(names[i], at)[0]) <= _ADJACENT_M
    held = [bool(adjacent[crossing & (c_all <= 0.0)].any()), bool(adjacent[crossing & (c_all > 0.0)].any())]
    best: list[tuple[float, float, int] | None] = [None, None]
    for i in np.flatnonzero(crossing):  # in the faces' order: the tie rule depends on it
        c = float(c_all[i])
        end = 1 if c > 0.0 else 0
        off = abs(float(s_all[i]) - s_map[end])
        current = best[end]
        if off > reach_m or (held[end] and not adjacent[i]):
            continue
        if (
            current is None
            or abs(c) > current[0] + _ACROSS_TIE
            or (abs(c) > current[0] - _ACROSS_TIE and off < current[1])
        ):
            best[end] = (abs(c), off, int(i))
    start, stop = best
    if start is None or stop is None:
        return None
    return (np.array(N[start[2]]), float(D[start[2]])), (np.array(N[stop[2]]), float(D[stop[2]]))


def face_planes(part: Part) -> tuple[FloatArray, FloatArray]:
    """Outward unit normals (f, 3) and offsets (f,) [m] of every face of ``part``, in :meth:`Part.face_names`
    order: a polyhedron's at once (no lookup by name per face), a box's six from its axes."""
    body = part.body
    if isinstance(body, Polyhedron):
        planes = body.face_planes()
        return planes[:, :3], planes[:, 3]
    rows = [part.face_plane(name) for name in part.face_names()]
    return np.array([n for n, _ in rows]).reshape(-1, 3), np.array([d for _, d in rows])


def _coplanar(part: Part, face: str, tol_m: float) -> list[int]:
    """Indices of ``part``'s faces in the plane of ``face`` (same outward normal, offsets within ``tol_m``)."""
    N, D = face_planes(part)
    n, d = part.face_plane(face)
    return [int(i) for i in np.flatnonzero((N @ n >= 1.0 - 1e-9) & (np.abs(D - d) <= tol_m))]


def coplanar_boundary(part: Part, face: str, tol_m: float = 1e-6) -> FloatArray:
    """(k, 2, 3) the boundary edges of the region ``face`` makes with every face of ``part`` in its plane (a
    drawing may split a plane into several faces: a plate's top around its hole is four quads). Edges two of
    those faces share lie inside the region and are left out; a hole's edges stay (its own loop)."""
    body = part.body
    assert isinstance(body, Polyhedron)
    count: dict[tuple[int, int], int] = {}
    for loop in (body.faces[i] for i in _coplanar(part, face, tol_m)):
        for a, b in zip(loop, loop[1:] + loop[:1], strict=True):
            key = (min(a, b), max(a, b))
            count[key] = count.get(key, 0) + 1
    ends = np.array([key for key, k in count.items() if k == 1], dtype=np.intp).reshape(-1, 2)
    return np.array(body.vertices[ends], dtype=float).reshape(-1, 2, 3)


def over_region(P: FloatArray, edges: FloatArray, n: FloatArray, inset_m: float) -> BoolArray:
    """(k,) which points P (k, 3) project inside the planar region bounded by ``edges`` (m, 2, 3) (closed loops;
    holes are loops too), of normal n, shrunk by ``inset_m`` [m] (every point at least that far from each edge).
    Convex or not, with holes or not (even-odd rule)."""
    q, a, b = _projected(P, edges, n)
    inside = _parity(q, a, b)
    if inset_m <= 0.0:
        return inside
    idx = np.flatnonzero(inside)  # the distance to the edges only where it can matter
    inside[idx] = _nearest2(q[idx], a, b) >= inset_m * inset_m
    return inside


class Region:
    """:func:`over_region` of one set of points P (k, 3) and one region (``edges`` (m, 2, 3), normal n), asked
    again and again (each pass of a seam, with another inset and other points): each point's side of the region
    and its distance to the nearest edge are computed once, on first demand; an inset is then one comparison."""

    def __init__(self, P: FloatArray, edges: FloatArray, n: FloatArray) -> None:
        self._q, self._a, self._b = _projected(P, edges, n)
        self._done = np.zeros(len(P), dtype=bool)
        self._inside = np.zeros(len(P), dtype=bool)
        self._near2 = np.full(len(P), np.inf)  # squared distance to the nearest edge [m^2] (of the points inside)

    def over(self, inset_m: float, where: BoolArray | None = None) -> BoolArray:
        """(k,) :func:`over_region` ``(P, edges, n, inset_m)``, on the points ``where`` says (the others: False)."""
        todo = np.flatnonzero(~self._done if where is None else where & ~self._done)
        if len(todo):
            self._done[todo] = True
            inside = _parity(self._q[todo], self._a, self._b)
            self._inside[todo] = inside
            mine = todo[inside]
            self._near2[mine] = _nearest2(self._q[mine], self._a, self._b)
        out = self._inside & (self._near2 >= inset_m * inset_m) if inset_m > 0.0 else self._inside.copy()
        return out if where is None else out & where


def _projected(P: FloatArray, edges: FloatArray, n: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Points P (k, 3) and the edges' ends (m, 2, 3) in the region's plane: q (k, 2), a (m, 2), b (m, 2) [m]."""
    u = edges[0, 1] - edges[0, 0]
    u = u - (u @ n) * n
    u /= max(float(np.linalg.norm(u)), 1e-300)
    v = np.cross(n, u)
    q = np.stack([P @ u, P @ v], axis=1)
    a = np.stack([edges[:, 0] @ u, edges[:, 0] @ v], axis=1)
    b = np.stack([edges[:, 1] @ u, edges[:, 1] @ v], axis=1)
    return q, a, b


def _parity(q: FloatArray, a: FloatArray, b: FloatArray) -> BoolArray:
    """(k,) whether a ray along +u from each point q (k, 2) crosses the edges a-b (m, 2) an odd number of times."""
    inside = np.zeros(len(q), dtype=bool)
    step = max(1, _PAIRS // max(1, len(a)))
    for i in range(0, len(q), step):  # every edge at once, for a chunk of the points
        qx, qy = q[i : i + step, 0, None], q[i : i + step, 1, None]
        crosses = (a[None, :, 1] > qy) != (b[None, :, 1] > qy)
        with np.errstate(divide="ignore", invalid="ignore"):
            x = a[None, :, 0] + (qy - a[None, :, 1]) * (b[:, 0] - a[:, 0])[None] / (b[:, 1] - a[:, 1])[None]
        inside[i : i + step] = np.logical_xor.reduce(crosses & (qx < x), axis=1)
    return inside


def _nearest2(q: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """(k,) the squared distance [m^2] from each point q (k, 2) to the nearest of the segments a-b (m, 2) (x and y
    apart: several times faster than einsum over a last axis of two)."""
    ex, ey = b[:, 0] - a[:, 0], b[:, 1] - a[:, 1]
    ll = np.maximum(ex * ex + ey * ey, 1e-300)
    out = np.empty(len(q))
    step = max(1, _PAIRS // max(1, len(a)))
    for i in range(0, len(q), step):
        wx, wy = q[i : i + step, 0, None] - a[None, :, 0], q[i : i + step, 1, None] - a[None, :, 1]
        s = np.clip((wx * ex + wy * ey) / ll, 0.0, 1.0)
        gx, gy = wx - s * ex, wy - s * ey
        out[i : i + step] = (gx * gx + gy * gy).min(axis=1, initial=np.inf)
    return out


def over_polygon(P: FloatArray, polygon: FloatArray, n: FloatArray, inset_m: float) -> BoolArray:
    """(k,) which points P (k, 3) project inside ``polygon`` (m, 3), a planar face of outward normal n, shrunk by
    ``inset_m`` [m] (:func:`over_region` of its edges)."""
    return over_region(P, np.stack([polygon, np.roll(polygon, -1, axis=0)], axis=1), n, inset_m)


TOUCH_M = 0.002  # a face lies on another body's face when their planes are this close [m] (opposite normals)


def touch_gap(part: Part, n: FloatArray, d: float, at: FloatArray) -> float | None:
    """How far [m] ``part``'s face lies beyond the plane n . p = d (n outward of the other body, so the face's own
    normal is -n), when one does within :data:`TOUCH_M` and the point ``at`` (3,) lies on the part (within
    :data:`TOUCH_M`): the other body's face lies on this part there, with this drawn gap (a brace drawn 1 mm over
    a rail). None when no face of ``part`` touches the plane there (a rail's end on a post's face far from ``at``)."""
    N, D = face_planes(part)
    gaps = -(D[(N @ n < -0.999) & (np.abs(D + d) <= TOUCH_M)] + d)
    if not len(gaps) or not bool(part.contains(at[None, :], margin=TOUCH_M)[0]):
        return None
    return float(gaps[np.argmin(np.abs(gaps))])  # the first of the nearest, in the faces' order


def fills_rectangle(part: Part, face: str, t: FloatArray, tol: float = 1e-3) -> bool:
    """Whether the region ``face`` makes with ``part``'s faces in its plane is (within ``tol`` of its area) the
    rectangle of its extents along ``t`` (the seam) and across it in the plane: then a face's extents bound it, as
    a box's do (a gusset's triangle, a plate's top around its hole do not fill theirs)."""
    body = part.body
    assert isinstance(body, Polyhedron)
    n, _ = part.face_plane(face)
    u = t - (t @ n) * n
    u /= max(float(np.linalg.norm(u)), 1e-300)
    v = np.cross(n, u)
    area, pts = 0.0, []
    for i in _coplanar(part, face, 1e-6):
        poly = body.vertices[list(body.faces[i])]
        q = np.stack([poly @ u, poly @ v], axis=1)
        area += 0.5 * abs(float(np.sum(q[:, 0] * np.roll(q[:, 1], -1) - np.roll(q[:, 0], -1) * q[:, 1])))
        pts.append(q)
    q = np.concatenate(pts)
    box = float(np.prod(q.max(axis=0) - q.min(axis=0)))
    return area >= (1.0 - tol) * box
