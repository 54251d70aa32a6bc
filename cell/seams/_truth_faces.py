"""The true seam of a joint between any two bodies (boxes or polyhedra), numpy only: the line where the planes of the
two as-built weld faces meet, clipped to the faces' common extent along it (docs/bodies.md section 3)."""

from __future__ import annotations

import numpy as np

from cell.errors import MapError
from cell.geometry import FloatArray, transform_points
from cell.types import Joint, MapSeam, Part

CLIP_TOL_M = 1e-4  # [m] how far past a face's polygon the seam may still reach (numerical slack)
_MIN_SIN = 1e-6  # faces more nearly parallel than this meet in no line
_SAME_PLANE_M = 1e-6  # [m] faces of one body whose planes lie this close (and parallel) are one plane


def best_rigid(p_from: FloatArray, p_to: FloatArray) -> FloatArray:
    """(4, 4) the rigid motion that best maps points p_from (n, 3) onto p_to (n, 3) (least squares, Kabsch)."""
    a, b = np.asarray(p_from, dtype=float), np.asarray(p_to, dtype=float)
    ca, cb = a.mean(axis=0), b.mean(axis=0)
    U, _, Vt = np.linalg.svd((a - ca).T @ (b - cb))
    D = np.diag([1.0, 1.0, float(np.sign(np.linalg.det(Vt.T @ U.T))) or 1.0])
    R = Vt.T @ D @ U.T
    X = np.eye(4)
    X[:3, :3], X[:3, 3] = R, cb - R @ ca
    return X


def plane_line(
    n_a: FloatArray, d_a: float, n_b: FloatArray, d_b: float, near: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """The line where the planes n_a . p = d_a and n_b . p = d_b meet: its point nearest to ``near`` (3,) and its
    unit direction n_a x n_b (3,). The planes must not be parallel (the caller checks)."""
    u = np.cross(n_a, n_b)
    u = u / np.linalg.norm(u)
    G = np.array([[n_a @ n_a, n_a @ n_b], [n_b @ n_a, n_b @ n_b]])
    alpha, beta = np.linalg.solve(G, [d_a - n_a @ near, d_b - n_b @ near])
    p = near + alpha * n_a + beta * n_b
    return np.asarray(p), np.asarray(u)


def resolve_face(part: Part, face: str, near: FloatArray) -> tuple[str, tuple[str, ...]]:
    """The as-built face that stands for the drawn face ``face`` near the point ``near`` (3,) [m], and the faces of
    its family: ``face`` itself when the body has it; else, for a body cut in segments (a bow,
    :mod:`cell.asbuilt_shapes`: faces ``<face>@<k>``), the segment nearest to ``near`` (the one holding the seam's
    middle), and all the segments. ValueError naming the valid faces when there is neither."""
    names = part.face_names()
    if face in names:
        return face, (face,)
    family = tuple(n for n in names if n.startswith(face + "@"))
    if not family:
        raise ValueError(f"unknown face {face!r}; valid: {', '.join(names)}")
    p = np.asarray(near, dtype=float)

    def gap(name: str) -> float:
        poly = part.face_polygon(name)
        n, d = part.face_plane(name)
        rel = p - poly.mean(axis=0)
        inplane = rel - (rel @ n) * n
        return abs(float(p @ n) - d) + max(0.0, float(np.linalg.norm(inplane)) - _half_extent(poly, inplane))

    return min(family, key=gap), family


def _half_extent(poly: FloatArray, direction: FloatArray) -> float:
    """How far a polygon (m, 3) reaches from its vertex mean along ``direction`` (3,) (any length)."""
    norm = float(np.linalg.norm(direction))
    if norm <= 0.0:
        return 0.0
    return float(np.max((poly - poly.mean(axis=0)) @ (direction / norm)))


def edge_vertices(part: Part, face_1: str, face_2: str) -> FloatArray:
    """(m, 3) the part's vertices that lie on both faces' planes (within ``_SAME_PLANE_M``): the ends of the edge
    where the two faces meet, and of its pieces when the drawing split a face in several; and the corners both
    faces' polygons share (a face warped as built, its corners off its fitted plane: a brace's end face moved to
    open a gap twists the faces beside it)."""
    v = np.asarray(part.vertices(), dtype=float)
    n_1, d_1 = part.face_plane(face_1)
    n_2, d_2 = part.face_plane(face_2)
    on_both = (np.abs(v @ n_1 - d_1) <= _SAME_PLANE_M) & (np.abs(v @ n_2 - d_2) <= _SAME_PLANE_M)
    p_1, p_2 = part.face_polygon(face_1), part.face_polygon(face_2)
    shared = np.all(p_1[:, None, :] == p_2[None, :, :], axis=2).any(axis=1)
    corners = p_1[shared]
    if not len(corners):
        return v[on_both]
    new = ~np.all(corners[:, None, :] == v[on_both][None, :, :], axis=2).any(axis=1)
    return np.concatenate([v[on_both], corners[new]])


def _clip(uv: FloatArray, lo: float, hi: float) -> FloatArray:
    """The 2D polygon (m, 2) (t along L, s across it) clipped to lo <= s <= hi (Sutherland-Hodgman)."""
    pts = uv
    for sign, bound in ((1.0, hi), (-1.0, -lo)):
        if len(pts) == 0:
            break
        out = []
        for k in range(len(pts)):
            p, q = pts[k - 1], pts[k]
            fp, fq = sign * p[1] - bound, sign * q[1] - bound
            if fq <= 0.0:
                if fp > 0.0:
                    out.append(p + (q - p) * (fp / (fp - fq)))
                out.append(q)
            elif fp <= 0.0:
                out.append(p + (q - p) * (fp / (fp - fq)))
        pts = np.array(out).reshape(-1, 2)
    return pts


def polygon_extent(poly: FloatArray, n: FloatArray, p0: FloatArray, u: FloatArray, tol: float) -> tuple[float, float]:
    """(t0, t1) [m] along the line p0 + t u of the part of a planar polygon (m, 3) (normal n) nearest to the line:
    the polygon within ``tol`` of the line where it crosses it, else within ``tol`` of its nearest point's
    distance; projected onto the line and grown by ``tol``."""
    w = np.cross(n, u)
    rel = poly - p0
    uv = np.column_stack([rel @ u, rel @ w])
    s = uv[:, 1]
    c = 0.0 if s.min() <= 0.0 <= s.max() else float(s[np.argmin(np.abs(s))])
    near = _clip(uv, c - tol, c + tol)
    if len(near) == 0:  # pragma: no cover - the nearest vertex is always inside its own band
        near = uv[np.argmin(np.abs(s - c))][None]
    return float(near[:, 0].min()) - tol, float(near[:, 0].max()) + tol


def plane_extent(
    part: Part, face: str, p0: FloatArray, u: FloatArray, tol: float, family: tuple[str, ...] = ()
) -> tuple[float, float]:
    """(t0, t1) [m] along the line p0 + t u (in ``face``'s plane) of the region the body's faces in that plane
    make together (a drawing may split one plane into several faces: a plate's top as four quads around its
    hole): the hull of the chords of those the line crosses, each grown by ``tol``; the face's own
    :func:`polygon_extent` when the line crosses none of them. ``family``: the segments of a bowed face
    (:func:`resolve_face`), which count with it when they come within ``tol`` of the line (a seam may cross from one
    segment to the next)."""
    n, d = part.face_plane(face)
    w = np.cross(n, u)
    lo, hi = np.inf, -np.inf
    for other in part.face_names():
        n_o, d_o = part.face_plane(other)
        coplanar = float(n_o @ n) >= 1.0 - 1e-9 and abs(d_o - d) <= _SAME_PLANE_M
        if not coplanar and other not in family:
            continue
        rel = part.face_polygon(other) - p0
        uv = np.column_stack([rel @ u, rel @ w])
        if uv[:, 1].min() > tol or uv[:, 1].max() < -tol:
            continue  # the line passes by this one
        chord = _clip(uv, -tol, tol)
        if len(chord):
            lo, hi = min(lo, float(chord[:, 0].min()) - tol), max(hi, float(chord[:, 0].max()) + tol)
    if not np.isfinite(lo):
        return polygon_extent(part.face_polygon(face), n, p0, u, tol)
    return lo, hi


def general_seam_W(
    seam: MapSeam, joint: Joint, design_a: Part, a: Part, b: Part, tol: float = CLIP_TOL_M
) -> tuple[FloatArray, FloatArray]:
    """The true seam (p_start_W, p_end_W) (3,) each [m] of ``joint`` between the as-built parts ``a`` (abutting) and
    ``b`` (receiving) in W; ``seam`` and ``design_a`` are the map's seam and part A in one frame (any)."""
    drawn = design_a.vertices()
    # The design of A onto A as built (a bowed A keeps its drawn vertices first, cut-in vertices after them).
    X = best_rigid(drawn, a.vertices()[: len(drawn)])
    ends = transform_points(X, np.stack([seam.p_start, seam.p_end]))
    middle = ends.mean(axis=0)
    face_a, _ = resolve_face(a, joint.face_abutting, middle)
    end_a, _ = resolve_face(a, joint.end_face, middle)
    face_b, family_b = resolve_face(b, joint.face_receiving, middle)
    n_a, d_a = a.face_plane(face_a)
    n_b, d_b = b.face_plane(face_b)
    if np.linalg.norm(np.cross(n_a, n_b)) < _MIN_SIN:
        raise MapError(
            f"seam {joint.seam_id!r}: faces {joint.abutting}.{joint.face_abutting} and "
            f"{joint.receiving}.{joint.face_receiving} are parallel as built; valid: weld faces that meet in a line"
        )
    p0, u = plane_line(n_a, d_a, n_b, d_b, middle)
    edge = edge_vertices(a, face_a, end_a)
    if len(edge) >= 2:
        t_edge = (edge - p0) @ u  # exact: A's edge ends the seam where it is the shorter
        ta = (float(t_edge.min()), float(t_edge.max()))
    else:
        ta = polygon_extent(a.face_polygon(face_a), n_a, p0, u, tol)
    tb = plane_extent(b, face_b, p0, u, tol, family_b if len(family_b) > 1 else ())
    t0, t1 = max(ta[0], tb[0]), min(ta[1], tb[1])
    if t1 <= t0:
        raise MapError(
            f"seam {joint.seam_id!r}: faces {joint.abutting}.{joint.face_abutting} and "
            f"{joint.receiving}.{joint.face_receiving} do not overlap along the line where they meet as built"
        )
    if (ends[1] - ends[0]) @ u < 0.0:
        t0, t1 = t1, t0
    return np.asarray(p0 + t0 * u), np.asarray(p0 + t1 * u)
