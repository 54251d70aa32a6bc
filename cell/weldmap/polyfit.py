"""Closed polyhedral bodies from drawn meshes (a body that is not a box): closed, consistently oriented, not
self-intersecting, enclosing a volume; coplanar neighbouring triangles merged into faces (docs/maps.md). No ezdxf."""

from __future__ import annotations

from collections import deque
from collections.abc import Sequence

import numpy as np

from cell.errors import MapError
from cell.geometry import FloatArray
from cell.types import Polyhedron

MERGE_DEG = 0.5  # neighbouring triangles within this angle of the region's first one share a face
_WELD_REL = 1e-9  # vertices closer than this (relative to the body's size) are one
_MAX_PAIRS = 20_000_000  # edge-triangle pairs the self-intersection check looks at (larger meshes: skipped)
_CHUNK = 100_000  # edge-triangle pairs at once (bounds the memory)


def _fail(name: str, why: str) -> MapError:
    return MapError(f"part {name} {why}")


def _triangulate(faces: Sequence[Sequence[int]], ids: np.ndarray) -> list[tuple[int, int, int, int]]:
    """Each drawn face as a fan of triangles of welded vertex ids: (a, b, c, index of the drawn face)."""
    out = []
    for k, f in enumerate(faces):
        v = [int(ids[i]) for i in f]
        v = [x for i, x in enumerate(v) if x != v[i - 1]] if len(v) > 1 else v  # repeated corners dropped
        out += [(v[0], v[j], v[j + 1], k) for j in range(1, len(v) - 1)]
    return out


def _orient(tris: np.ndarray, name: str) -> np.ndarray:
    """Triangles (t, 3) of a closed manifold mesh, each edge on two triangles, oriented alike (by flood fill)."""
    owners: dict[tuple[int, int], list[int]] = {}
    for t, (a, b, c) in enumerate(tris):
        for u, v in ((a, b), (b, c), (c, a)):
            owners.setdefault((min(u, v), max(u, v)), []).append(t)
    single = sum(1 for o in owners.values() if len(o) == 1)
    if single:
        raise _fail(name, f"is not closed: {single} edges on one face only (a closed body is needed)")
    if any(len(o) > 2 for o in owners.values()):
        raise _fail(name, "is not a closed body: an edge is shared by more than two faces")
    tris = tris.copy()
    seen = np.zeros(len(tris), dtype=bool)
    for start in range(len(tris)):
        if seen[start]:
            continue
        seen[start] = True
        todo = deque([start])
        while todo:
            t = todo.popleft()
            a, b, c = tris[t]
            for u, v in ((a, b), (b, c), (c, a)):
                for o in owners[(min(u, v), max(u, v))]:
                    if o == t or seen[o]:
                        continue
                    x, y, z = tris[o]
                    if (u, v) in ((x, y), (y, z), (z, x)):  # same direction: the neighbour is flipped
                        tris[o] = (x, z, y)
                    seen[o] = True
                    todo.append(o)
    return tris


def _self_intersecting(V: FloatArray, tris: np.ndarray) -> bool:
    """Whether an edge of the mesh crosses the inside of a triangle it does not share a vertex with."""
    edges = np.unique(np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1), axis=0)
    if len(edges) * len(tris) > _MAX_PAIRS:
        return False
    step = max(1, _CHUNK // len(tris))
    return any(_crossings(V, tris, edges[s : s + step]) for s in range(0, len(edges), step))


def _crossings(V: FloatArray, tris: np.ndarray, edges: np.ndarray) -> bool:
    a, b, c = V[tris[:, 0]], V[tris[:, 1]], V[tris[:, 2]]
    p, q = V[edges[:, 0]], V[edges[:, 1]]
    d = q - p
    e1, e2 = b - a, c - a
    h = np.cross(d[:, None, :], e2[None])  # Moller-Trumbore, each edge against every triangle
    det = np.einsum("etk,tk->et", h, e1)
    ok = np.abs(det) > 1e-18
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    s = p[:, None, :] - a[None]
    u = np.einsum("etk,etk->et", s, h) * inv
    qv = np.cross(s, e1[None])
    v = np.einsum("etk,ek->et", qv, d) * inv
    t = np.einsum("etk,tk->et", qv, e2) * inv
    eps = 1e-9
    hit = ok & (u > eps) & (v > eps) & (u + v < 1 - eps) & (t > eps) & (t < 1 - eps)
    touches = ((tris[None] == edges[:, 0, None, None]) | (tris[None] == edges[:, 1, None, None])).any(axis=2)
    return bool(np.any(hit & ~touches))


def _loop(region: list[int], tris: np.ndarray) -> list[int] | None:
    """The outline of a set of triangles as one vertex loop (their outward winding), or None (a hole, a pinch)."""
    directed = {(int(u), int(v)) for t in region for u, v in zip(tris[t], np.roll(tris[t], -1), strict=True)}
    border = {u: v for u, v in directed if (v, u) not in directed}
    if len(border) != sum(1 for u, v in directed if (v, u) not in directed):
        return None  # a vertex where the outline touches itself
    if not border:
        return None
    start = next(iter(border))
    loop, at = [start], border[start]
    while at != start and len(loop) <= len(border):
        loop.append(at)
        at = border.get(at, start)
    return loop if len(loop) == len(border) else None


def _drop_collinear(V: FloatArray, loop: list[int]) -> list[int]:
    keep = []
    for i, k in enumerate(loop):
        a, b, c = V[loop[i - 1]], V[k], V[loop[(i + 1) % len(loop)]]
        ab, bc = b - a, c - b
        if np.linalg.norm(np.cross(ab, bc)) > 1e-9 * max(float(np.linalg.norm(ab) * np.linalg.norm(bc)), 1e-300):
            keep.append(k)
    return keep if len(keep) >= 3 else loop


def _faces(V: FloatArray, tris: np.ndarray, drawn: list[int]) -> list[tuple[int, ...]]:
    """Neighbouring coplanar triangles grouped into faces (outward winding), in the order of their first triangle."""
    nrm = np.cross(V[tris[:, 1]] - V[tris[:, 0]], V[tris[:, 2]] - V[tris[:, 0]])
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    owners: dict[tuple[int, int], list[int]] = {}
    for t, (a, b, c) in enumerate(tris):
        for u, v in ((a, b), (b, c), (c, a)):
            owners.setdefault((min(u, v), max(u, v)), []).append(t)
    cos_merge = float(np.cos(np.radians(MERGE_DEG)))
    region_of = np.full(len(tris), -1)
    faces: list[tuple[int, ...]] = []
    for seed in range(len(tris)):
        if region_of[seed] >= 0:
            continue
        region, todo = [seed], deque([seed])
        region_of[seed] = seed
        while todo:
            t = todo.popleft()
            a, b, c = tris[t]
            for u, v in ((a, b), (b, c), (c, a)):
                for o in owners[(min(u, v), max(u, v))]:
                    if region_of[o] < 0 and float(nrm[o] @ nrm[seed]) >= cos_merge:
                        region_of[o] = seed
                        region.append(o)
                        todo.append(o)
        loop = _loop(region, tris)
        if loop is not None:
            faces.append(tuple(_drop_collinear(V, loop)))
            continue
        by_drawn: dict[int, list[int]] = {}  # a face with a hole: its drawn faces stay apart
        for t in region:
            by_drawn.setdefault(drawn[t], []).append(t)
        for group in by_drawn.values():
            sub = _loop(group, tris)
            faces += [tuple(_drop_collinear(V, sub))] if sub is not None else [tuple(tris[t]) for t in group]
    return faces


def fit_polyhedron(vertices: FloatArray, faces: Sequence[Sequence[int]], name: str, tol: float) -> Polyhedron:
    """The closed body of a drawn mesh as a :class:`Polyhedron` [m], or MapError naming what is wrong.

    vertices : (n, 3) [m]; faces : vertex index tuples (any orientation, convex polygons); tol : vertices closer
    than this [m] are one, faces with an area of at most ``tol`` squared are dropped.
    """
    v = np.asarray(vertices, dtype=float)
    if v.ndim != 2 or v.shape[1] != 3 or not np.all(np.isfinite(v)):
        raise _fail(name, "has vertices that are not finite 3D points")
    if any(len(f) and (min(f) < 0 or max(f) >= len(v)) for f in faces):
        raise _fail(name, f"has a face naming a vertex it does not have (valid: 0 to {len(v) - 1})")
    key = np.round(v / max(tol, _WELD_REL)).astype(np.int64)
    _, first, ids = np.unique(key, axis=0, return_index=True, return_inverse=True)
    V = v[first]
    raw = _triangulate(faces, ids.reshape(-1))
    tri = np.array([t[:3] for t in raw], dtype=np.intp).reshape(-1, 3)
    area = 0.5 * np.linalg.norm(np.cross(V[tri[:, 1]] - V[tri[:, 0]], V[tri[:, 2]] - V[tri[:, 0]]), axis=1)
    keep = area > tol * tol
    tri, drawn = tri[keep], [t[3] for t, k in zip(raw, keep, strict=True) if k]
    if len(tri) < 4:
        raise _fail(name, "has fewer than four faces of non-zero area (a closed body is needed)")
    tri = _orient(tri, name)
    vol6 = float(np.einsum("ij,ij->i", V[tri[:, 0]], np.cross(V[tri[:, 1]], V[tri[:, 2]])).sum())
    if abs(vol6) / 6.0 <= tol**3:
        raise _fail(name, "encloses no volume (flat)")
    if vol6 < 0:
        tri = tri[:, ::-1]
    if _self_intersecting(V, tri):
        raise _fail(name, "is self-intersecting: an edge crosses one of its faces (a closed body is needed)")
    polys = _faces(V, tri, drawn)
    used = sorted({i for f in polys for i in f})
    local = {g: k for k, g in enumerate(used)}
    try:
        return Polyhedron(V[used], tuple(tuple(local[i] for i in f) for f in polys))
    except ValueError as exc:
        raise _fail(name, f"cannot be read as a closed body ({exc})") from None
