"""The planar polygon faces of a :class:`~cell.types.solid.polyhedron.Polyhedron`: each face's plane (Newell's normal)
and its triangles (ear clipping in the face's own plane; a triangle or a strictly convex quad, a mesh's faces, is
the fan of its first corner, computed for all of them at once).

Frames: whatever frame the vertices are given in [m]."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray


def _newell(poly: FloatArray) -> FloatArray:
    """Area-weighted normal (3,) of a planar polygon (m, 3) (Newell's method): 2 x area along the normal."""
    nxt = np.roll(poly, -1, axis=0)
    return np.asarray(np.cross(poly, nxt).sum(axis=0))


def _ear_clip(uv: FloatArray) -> list[tuple[int, int, int]]:
    """Triangles (local indices) of a simple counter-clockwise 2D polygon (m, 2), convex or not (ear clipping).

    A convex polygon comes out as the fan from its first vertex; degenerate leftovers fall back to a fan.
    """
    idx = list(range(len(uv)))
    out: list[tuple[int, int, int]] = []
    guard = 0
    while len(idx) > 3 and guard < 4 * len(uv) * len(uv):
        guard += 1
        m = len(idx)
        for k in range(m):
            i, j, l_ = idx[k], idx[(k + 1) % m], idx[(k + 2) % m]
            a, b, c = uv[i], uv[j], uv[l_]
            cross = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
            if cross <= 1e-15:
                continue  # reflex or flat corner: not an ear
            others = [q for q in idx if q not in (i, j, l_)]
            if others and _any_in_triangle(uv[others], a, b, c):
                continue
            out.append((i, j, l_))
            idx.pop((k + 1) % m)
            break
        else:
            break
    for k in range(1, len(idx) - 1):  # what is left (a triangle, or a degenerate rest): a fan
        out.append((idx[0], idx[k], idx[k + 1]))
    return out


def _any_in_triangle(p: FloatArray, a: FloatArray, b: FloatArray, c: FloatArray) -> bool:
    def side(u: FloatArray, v: FloatArray) -> FloatArray:
        return np.asarray((v[0] - u[0]) * (p[:, 1] - u[1]) - (v[1] - u[1]) * (p[:, 0] - u[0]))

    s1, s2, s3 = side(a, b), side(b, c), side(c, a)
    return bool(np.any((s1 >= -1e-15) & (s2 >= -1e-15) & (s3 >= -1e-15)))


def face_plane_triangles(poly: FloatArray, f: tuple[int, ...], name: str) -> tuple[FloatArray, float, list]:
    """One face's outward unit normal (3,), offset [m] and triangles (vertex indices): its Newell normal, the
    plane through its vertices' mean, its polygon ear-clipped in its own plane."""
    nw = _newell(poly)
    norm = float(np.linalg.norm(nw))
    if norm <= 1e-18:
        raise ValueError(f"Polyhedron face {name} has zero area")
    n = nw / norm
    u = poly[1] - poly[0] if len(poly) > 1 else np.array([1.0, 0.0, 0.0])
    u = u - (u @ n) * n
    u = u / max(float(np.linalg.norm(u)), 1e-300)
    v = np.cross(n, u)
    uv = np.stack([poly @ u, poly @ v], axis=1)
    return n, float(n @ poly.mean(axis=0)), [(f[a], f[b], f[c]) for a, b, c in _ear_clip(uv)]


def faces_planes_triangles(
    vertices: FloatArray, faces: tuple[tuple[int, ...], ...], names: tuple[str, ...]
) -> tuple[FloatArray, npt.NDArray[np.intp]]:
    """Every face's plane (F, 4) (outward unit normal, offset [m]) and the body's triangles (t, 3), face by face
    in order: what :func:`face_plane_triangles` gives each, the triangles and strictly convex quads (a mesh's
    faces) computed all at once (a fan from the first vertex, as ear clipping cuts them), any other face alone."""
    planes = np.zeros((len(faces), 4))
    per_face: list[list[tuple[int, int, int]]] = [[] for _ in faces]
    small = [i for i, f in enumerate(faces) if len(f) in (3, 4)]
    rest = [i for i, f in enumerate(faces) if len(f) not in (3, 4)]
    for m in (3, 4):
        idx = np.array([i for i in small if len(faces[i]) == m], dtype=np.intp)
        if not len(idx):
            continue
        F = np.array([faces[i] for i in idx], dtype=np.intp)  # (k, m)
        P = vertices[F]  # (k, m, 3)
        nw = np.cross(P, np.roll(P, -1, axis=1)).sum(axis=1)  # Newell, summed in vertex order as _newell does
        norm = np.sqrt([float(x @ x) for x in nw])  # as np.linalg.norm takes a vector's, to the bit
        E = np.roll(P, -1, axis=1) - P  # each edge
        turn = np.einsum("kmj,kj->km", np.cross(E, np.roll(E, -1, axis=1)), nw)  # > 0: a convex corner
        scale = np.einsum("kmj,kmj->km", E, E).max(axis=1) * np.maximum(norm, 1e-300)
        fan = (norm > 1e-18) & np.all(turn > 1e-9 * scale[:, None], axis=1) if m == 4 else norm > 1e-18
        for i in idx[~fan]:
            rest.append(int(i))
        idx, F, P, nw, norm = idx[fan], F[fan], P[fan], nw[fan], norm[fan]
        n = nw / norm[:, None]
        planes[idx, :3] = n
        planes[idx, 3] = [float(a @ b) for a, b in zip(n, P.mean(axis=1), strict=True)]
        for i, f in zip(idx, F.tolist(), strict=True):
            per_face[i] = [(f[0], f[1], f[2])] if m == 3 else [(f[0], f[1], f[2]), (f[0], f[2], f[3])]
    for i in rest:
        n1, d, t = face_plane_triangles(vertices[list(faces[i])], faces[i], names[i])
        planes[i, :3], planes[i, 3], per_face[i] = n1, d, t
    tris = [t for ts in per_face for t in ts]
    return planes, np.array(tris, dtype=np.intp).reshape(-1, 3)
