"""The shapes of the realism options (docs/bodies.md section 7), numpy only: a body bent in an arc (a bow), an
abutting part's end cut out of square (a gap that varies along its seams), and a tack weld's bead.

Every function takes and returns bodies in one frame (any; W in :mod:`cell.sim.asbuilt.parts`), metres.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from cell.errors import ScenarioError
from cell.geometry import FloatArray, make_pose
from cell.types import Polyhedron

_KEY_M = 1e-9  # [m] vertices closer than this on a cut are one vertex
_DISTINCT = 1e-6  # principal spreads closer than this (relative) are equal


def principal_frame(body: Polyhedron) -> tuple[FloatArray, FloatArray, FloatArray]:
    """A polyhedron's principal frame in its own frame A: the pose X_AP (4, 4) (origin the volume centroid, axes
    the eigenvectors of the vertices' covariance, largest spread first, each axis's largest component positive,
    right-handed), the vertices' extents (3,) [m] along those axes, and the spreads (eigenvalues, (3,) [m^2]).
    Two equal spreads (a square tube's cross-section) leave the axes in their plane without a direction of their
    own: there the frame A's own axis nearest to that plane is taken (the first of x, y, z on a tie)."""
    c = np.asarray(body.center, dtype=float)
    v = np.asarray(body.vertices, dtype=float) - c
    spread, E = np.linalg.eigh(np.cov(v.T, bias=True))
    order = np.argsort(spread)[::-1]
    spread, E = spread[order], E[:, order]
    E = _snapped(E, spread)
    for i in (0, 1):
        if E[np.argmax(np.abs(E[:, i])), i] < 0:
            E[:, i] = -E[:, i]
    E[:, 2] = np.cross(E[:, 0], E[:, 1])
    v_P = v @ E
    return make_pose(E, c), v_P.max(axis=0) - v_P.min(axis=0), spread


def _snapped(E: FloatArray, spread: FloatArray) -> FloatArray:
    """The eigenvectors E (3, 3) (columns, largest spread first) with a tied pair's axes put along A's axes."""
    E = np.array(E, dtype=float)
    tol = _DISTINCT * max(float(spread[0]), 1e-300)
    if abs(spread[1] - spread[2]) <= tol:
        keep, free = 0, 1  # the cross-section: fix the length axis, snap the second
    elif abs(spread[0] - spread[1]) <= tol:
        keep, free = 2, 0  # a square plate: fix its normal, snap the first
    else:
        return E
    n = E[:, keep]
    cand = np.eye(3) - np.outer(n, n)  # A's axes projected onto the tied plane (rows)
    k = int(np.argmax(np.round(np.linalg.norm(cand, axis=1), 6)))
    E[:, free] = cand[k] / np.linalg.norm(cand[k])
    other = 3 - keep - free
    E[:, other] = np.cross(E[:, (other + 1) % 3], E[:, (other + 2) % 3])
    return E


def _convex(poly: FloatArray, n: FloatArray) -> bool:
    """Whether a planar polygon (m, 3) with normal n turns the same way at every corner."""
    e = np.roll(poly, -1, axis=0) - poly
    turn = np.cross(e, np.roll(e, -1, axis=0)) @ n
    return bool(np.all(turn >= -1e-12) or np.all(turn <= 1e-12))


def _split(poly: FloatArray, s: FloatArray, cut: float) -> tuple[FloatArray, FloatArray]:
    """A convex polygon (m, 3) with coordinates ``s`` (m,) along the cutting axis split at s = cut: the pieces
    below and above (each (k, 3), possibly empty)."""
    lo: list[FloatArray] = []
    hi: list[FloatArray] = []
    m = len(poly)
    for k in range(m):
        p, q, sp, sq = poly[k], poly[(k + 1) % m], s[k], s[(k + 1) % m]
        if sp <= cut:
            lo.append(p)
        if sp >= cut:
            hi.append(p)
        if (sp - cut) * (sq - cut) < 0.0:
            x = p + (q - p) * ((cut - sp) / (sq - sp))
            lo.append(x)
            hi.append(x)
    return np.array(lo).reshape(-1, 3), np.array(hi).reshape(-1, 3)


def sliced(body: Polyhedron, axis: FloatArray, cuts: FloatArray) -> tuple[FloatArray, list[list[int]], list[str]]:
    """The body's faces cut by the planes ``axis . p = c`` for each c in ``cuts`` (increasing): vertices (the
    body's own first, in order, then the new ones), faces and names (a face cut in pieces is named
    ``<name>@<slab>``, slab 0 below the first cut). No face is added: the surface is only subdivided.
    ScenarioError when a non-convex face would have to be cut."""
    verts = [np.asarray(v, dtype=float) for v in body.vertices]
    index: dict[tuple[int, int, int], int] = {}
    for i, v in enumerate(verts):
        index.setdefault(tuple(int(c) for c in np.round(v / _KEY_M)), i)  # type: ignore[arg-type]

    def vid(p: FloatArray) -> int:
        key = tuple(int(c) for c in np.round(p / _KEY_M))
        if key not in index:
            index[key] = len(verts)  # type: ignore[index]
            verts.append(np.asarray(p, dtype=float))
        return index[key]  # type: ignore[index]

    faces: list[list[int]] = []
    names: list[str] = []
    for face, name in zip(body.faces, body.names, strict=True):
        poly = np.asarray(body.vertices[list(face)], dtype=float)
        s = poly @ axis
        inside = [c for c in cuts if s.min() + 1e-9 < c < s.max() - 1e-9]
        if not inside:
            faces.append(list(face))
            names.append(name)
            continue
        if not _convex(poly, body.face_plane(name)[0]):
            raise ScenarioError(f"face {name} is not convex: a bow cannot cut it in segments; valid: convex faces")
        first = int(np.searchsorted(cuts, s.min() + 1e-9))
        rest = poly
        for k, c in enumerate(inside):
            below, rest = _split(rest, rest @ axis, c)
            if len(below) >= 3:
                faces.append([vid(p) for p in below])
                names.append(f"{name}@{first + k}")
        faces.append([vid(p) for p in rest])
        names.append(f"{name}@{first + len(inside)}")
    return np.array(verts), faces, names


def bowed(body: Polyhedron, X_AP: FloatArray, sagitta_m: float, toward: int, segments: int) -> Polyhedron:
    """The body bent in a circular arc of sagitta ``sagitta_m`` [m] (signed: along +/- the axis ``toward``, 1 or 2,
    of the frame P) over its extent along P's x, tessellated in ``segments`` equal pieces along x.

    X_AP : (4, 4) the frame P in the body's frame A (x along the length). The neutral line is the body's middle
    across ``toward``: it keeps its chord (its ends stay where they were); every cross-section is turned with
    the arc, so each face piece stays planar (a piece between two cuts is mirror-symmetric about their bisector).
    """
    ex, ed = X_AP[:3, 0], X_AP[:3, toward]
    x = body.vertices @ ex
    x0, x1 = float(x.min()), float(x.max())
    cuts = np.linspace(x0, x1, segments + 1)[1:-1]
    verts, faces, names = sliced(body, ex, cuts)
    h = abs(float(sagitta_m))
    sign = 1.0 if sagitta_m > 0 else -1.0
    half = (x1 - x0) / 2.0
    xc = (x0 + x1) / 2.0
    R = (half**2 + h**2) / (2.0 * h)
    r = sign * (verts @ ed)
    r0 = (float(r.min()) + float(r.max())) / 2.0
    xv = verts @ ex
    theta = np.arcsin(np.clip((xv - xc) / R, -1.0, 1.0))
    rho = R + (r - r0)
    new_x = xc + rho * np.sin(theta)
    new_r = r0 + h - R + rho * np.cos(theta)
    out = verts + np.outer(new_x - xv, ex) + np.outer(sign * (new_r - r), ed)
    return Polyhedron(out, tuple(tuple(f) for f in faces), tuple(names))


def cut_end(body: Polyhedron, end_face: str, across: FloatArray, max_m: float) -> Polyhedron:
    """The body with its end face ``end_face`` (every vertex in that face's plane) moved back by 0 at its edge
    farthest along ``-across`` to ``max_m`` [m] (along the face's normal) at its edge farthest along ``+across``
    (unit, in the face's plane), linearly: the end cut out of square, so the gap to what it meets opens from 0 to
    ``max_m``. Each end vertex slides along the body's edge that leaves the end face there (:func:`_slide`), so
    the side faces keep their planes, also where they meet the end at an angle (a mitred brace's broad faces);
    square to the end (a box) that is the face's normal. The end's vertices stay in one plane."""
    n, d = body.face_plane(end_face)
    v = np.array(body.vertices, dtype=float)
    on = np.abs(v @ n - d) <= 1e-6
    t = v[on] @ across
    span = float(t.max() - t.min())
    if span <= 0.0:  # pragma: no cover - a face has an extent in its own plane
        return body
    back = max_m * (t - t.min()) / span
    v[on] += back[:, None] * _slide(body, on, n)
    return Polyhedron(v, body.faces, body.names)


def _slide(body: Polyhedron, on: npt.NDArray[np.bool_], n: FloatArray) -> FloatArray:
    """(m, 3) for each vertex ``on`` the end face (outward normal n), the direction it moves back by: along the
    edge that leaves the end face there, scaled so that it moves 1 along -n, when every end vertex has one such edge
    and they are all parallel (a prism: a brace, a box); else (a triangulated mesh's diagonals), or where those
    edges are square to the face or too flat to slide along, -n for all."""
    v = np.asarray(body.vertices, dtype=float)
    edges = []
    for i in (int(k) for k in np.flatnonzero(on)):
        away: set[int] = set()
        for f in body.faces:
            if i in f:
                k = list(f).index(i)
                away |= {j for j in (f[k - 1], f[(k + 1) % len(f)]) if not on[j]}
        if len(away) != 1:
            return np.tile(-n, (int(np.count_nonzero(on)), 1))
        e = v[away.pop()] - v[i]
        edges.append(e / np.linalg.norm(e))
    e = edges[0]
    parallel = all(float(x @ e) >= 1.0 - 1e-9 for x in edges)
    if not parallel or float(e @ n) <= -1.0 + 1e-9 or float(e @ n) >= -0.2:
        return np.tile(-n, (len(edges), 1))
    return np.tile(e / -float(e @ n), (len(edges), 1))


def tack_bead(p0: FloatArray, p1: FloatArray, n_a: FloatArray, n_b: FloatArray, leg_m: float) -> Polyhedron:
    """A fillet bead from p0 to p1 (3,) [m] on the corner line of two faces with outward normals n_a (A's weld face)
    and n_b (B's): a triangular prism, one leg ``leg_m`` along B's face away from A, one up A's face away from B."""
    c = float(n_a @ n_b)
    t_b = n_a - c * n_b
    t_a = n_b - c * n_a
    t_b, t_a = t_b / np.linalg.norm(t_b), t_a / np.linalg.norm(t_a)
    tri = [np.zeros(3), leg_m * t_b, leg_m * t_a]
    v = np.array([p + o for p in (p0, p1) for o in tri])
    faces: list[tuple[int, ...]] = [(0, 2, 1), (3, 4, 5), (0, 1, 4, 3), (1, 2, 5, 4), (2, 0, 3, 5)]
    body = Polyhedron(v, tuple(faces))
    if body.volume < 0.0:
        body = Polyhedron(v, tuple(tuple(reversed(f)) for f in faces))
    return body
