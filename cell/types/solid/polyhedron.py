"""A closed body bounded by planar polygon faces: the general part model (a box is its fast special case).

Frames: the body is given in a frame ``A`` (``M`` as drawn, ``R`` or ``W`` once moved). Metres.
Faces are lists of vertex indices, counter-clockwise seen from outside; each face has a stable name (``"f0"``, ...).
Numpy only (the types package imports no stage).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray, readonly, transform_points
from cell.types.solid.faces import faces_planes_triangles
from cell.types.solid.near import pair_distance, within

_CHUNK = 200_000  # point-triangle pairs evaluated at once in contains() (bounds the memory)


def _point_triangle_distance(p: FloatArray, a: FloatArray, b: FloatArray, c: FloatArray) -> FloatArray:
    """Distances (n, t) from points p (n, 3) to triangles given by corners a, b, c (t, 3) each: every pair's
    :func:`cell.types.solid.near.pair_distance`."""
    i, j = np.divmod(np.arange(len(p) * len(a)), max(len(a), 1))
    return pair_distance(p[i], a[j], b[j], c[j]).reshape(len(p), len(a))


@dataclass(frozen=True)
class Polyhedron:
    """A closed body bounded by planar polygon faces, in the frame A it is given in [m].

    vertices : (k, 3) vertex positions in A [m].
    faces : each face a planar polygon, vertex indices counter-clockwise seen from outside.
    names : one stable name per face (``"f0"``, ``"f1"``, ...; coplanar triangles of a MESH merged into one face).
    """

    vertices: FloatArray
    faces: tuple[tuple[int, ...], ...]
    names: tuple[str, ...] = ()
    _planes: FloatArray = field(init=False, repr=False, compare=False)
    _tris: npt.NDArray[np.intp] = field(init=False, repr=False, compare=False)
    _mass: tuple[float, FloatArray, float] = field(init=False, repr=False, compare=False)  # volume, centre, radius
    _bounds: FloatArray = field(init=False, repr=False, compare=False)  # (2, 3) the vertices' lowest and highest

    def __post_init__(self) -> None:
        object.__setattr__(self, "vertices", readonly(self.vertices))
        faces = tuple(tuple(int(i) for i in f) for f in self.faces)
        object.__setattr__(self, "faces", faces)
        if not self.names:
            object.__setattr__(self, "names", tuple(f"f{i}" for i in range(len(faces))))
        k = len(self.vertices)
        if self.vertices.ndim != 2 or self.vertices.shape[1] != 3 or not np.all(np.isfinite(self.vertices)):
            raise ValueError("Polyhedron needs finite (k, 3) vertices")
        if len(faces) < 4 or len(self.names) != len(faces) or len(set(self.names)) != len(faces):
            raise ValueError("Polyhedron needs at least 4 faces, each with its own name")
        if any(len(f) < 3 or min(f) < 0 or max(f) >= k for f in faces):
            raise ValueError(f"Polyhedron faces need 3 or more vertex indices in 0..{k - 1}")
        planes, tris = faces_planes_triangles(self.vertices, faces, self.names)
        object.__setattr__(self, "_planes", readonly(planes))
        object.__setattr__(self, "_tris", readonly(tris, np.intp))
        vol, c = self._volume_centroid()
        object.__setattr__(self, "_mass", (vol, readonly(c), float(np.max(np.linalg.norm(self.vertices - c, axis=1)))))
        object.__setattr__(self, "_bounds", readonly(np.array([self.vertices.min(axis=0), self.vertices.max(axis=0)])))

    def _index(self, face: str) -> int:
        try:
            return self.names.index(face)
        except ValueError:
            raise ValueError(f"unknown face {face!r}; valid: {', '.join(self.names)}") from None

    def face_names(self) -> tuple[str, ...]:
        """The faces' names, in order."""
        return self.names

    def face_plane(self, face: str) -> tuple[FloatArray, float]:
        """Outward unit normal n (3,) and offset d [m] of a face, so that the face lies in n . p = d."""
        row = self._planes[self._index(face)]
        return np.array(row[:3]), float(row[3])

    def face_planes(self) -> FloatArray:
        """(f, 4) read-only: each face's outward unit normal and offset (n, d) in :attr:`names` order, the rows of
        :meth:`face_plane` at once."""
        return self._planes

    def face_polygon(self, face: str) -> FloatArray:
        """(m, 3) the face's vertices in order (counter-clockwise seen from outside) [m]."""
        return np.array(self.vertices[list(self.faces[self._index(face)])])

    def face_distance(self, face: str, p_A: npt.ArrayLike) -> FloatArray:
        """Distances (n,) [m] from points (n, 3) to the face (its polygon, not its plane)."""
        p = np.asarray(p_A, dtype=float).reshape(-1, 3)
        f = self.faces[self._index(face)]
        tri = self._tris[np.all(np.isin(self._tris, f), axis=1)]
        v = self.vertices[tri]
        return np.asarray(_point_triangle_distance(p, v[:, 0], v[:, 1], v[:, 2]).min(axis=1))

    @property
    def is_convex(self) -> bool:
        """Whether every vertex lies behind every face's plane (within 1 um)."""
        return bool(np.all(self.vertices @ self._planes[:, :3].T - self._planes[:, 3] <= 1e-6))

    def segments_hit(self, p0: npt.ArrayLike, p1: npt.ArrayLike, margin: float = 0.0) -> npt.NDArray[np.bool_]:
        """(m,) whether each segment p0 (3,) -> p1 (m, 3) meets the body [m].

        A convex body is clipped by its faces' half-spaces, each moved out by ``margin``; any other body is met
        when a segment crosses one of its triangles or starts inside it (``margin`` then not applied).
        """
        a = np.asarray(p0, dtype=float).reshape(3)
        b = np.asarray(p1, dtype=float).reshape(-1, 3)
        if not self.is_convex:
            d = b - a
            tri = self.vertices[self._tris]
            e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
            h = np.cross(d[:, None, :], e2[None])
            det = np.einsum("mtk,tk->mt", h, e1)
            ok = np.abs(det) > 1e-18
            inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
            s = a - tri[:, 0]
            u = np.einsum("tk,mtk->mt", s, h) * inv
            q = np.cross(s, e1)
            v = np.einsum("tk,mk->mt", q, d) * inv
            t = np.einsum("tk,tk->t", q, e2)[None] * inv
            hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t >= 0) & (t <= 1)
            return np.asarray(hit.any(axis=1) | bool(self.contains(a[None])[0]))
        n, off = self._planes[:, :3], self._planes[:, 3] + margin
        f0 = n @ a - off  # (F,) > 0: the start is outside that face
        f1 = b @ n.T - off  # (m, F)
        den = f1 - f0
        with np.errstate(divide="ignore", invalid="ignore"):
            t = -f0 / den
        enter = np.where(den < 0, t, -np.inf).max(axis=1, initial=0.0)
        leave = np.where(den > 0, t, np.inf).min(axis=1, initial=1.0)
        parallel_out = np.any((den == 0) & (f0 > 0), axis=1)
        return np.asarray((enter <= leave) & ~parallel_out)

    def triangles(self) -> npt.NDArray[np.intp]:
        """(t, 3) vertex indices of a triangulation of the faces, outward winding (a fan for a convex face)."""
        return self._tris

    def contains(self, p_A: npt.ArrayLike, margin: float = 0.0) -> npt.NDArray[np.bool_]:
        """Which points (n, 3) lie inside the closed body (convex or not), grown by ``margin`` [m] (shrunk if < 0).

        Inside means a winding number above one half (the solid angles of the triangles summed); the margin adds
        (or removes) the points within ``|margin|`` of the surface.
        """
        p = np.asarray(p_A, dtype=float)
        single = p.ndim == 1
        p = p.reshape(-1, 3)
        out = np.zeros(len(p), dtype=bool)
        # Only points within the body's bounds (grown by the margin) can be inside: most that a stage asks are not.
        grow = max(margin, 0.0)
        near = np.flatnonzero(np.all((p >= self._bounds[0] - grow) & (p <= self._bounds[1] + grow), axis=1))
        if len(near) == 0:
            return out[0] if single else out
        tri = self.vertices[self._tris]
        a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
        step = max(1, _CHUNK // max(1, len(tri)))
        for s in range(0, len(near), step):
            q = p[near[s : s + step]]
            if margin > 0.0:
                # Within the margin of a triangle: in, whatever the winding number says; the others' winding alone.
                inside = within(q, a, b, c, margin)
                rest = np.flatnonzero(~inside)
                inside[rest] = self._winding(q[rest], a, b, c) > 0.5
                out[near[s : s + step]] = inside
                continue
            inside = self._winding(q, a, b, c) > 0.5
            if margin != 0.0:  # shrunk: of the points inside, those at least |margin| from the surface
                k = np.flatnonzero(inside)
                inside[k] = _point_triangle_distance(q[k], a, b, c).min(axis=1) >= -margin
            out[near[s : s + step]] = inside
        return out[0] if single else out

    @staticmethod
    def _winding(q: FloatArray, a: FloatArray, b: FloatArray, c: FloatArray) -> FloatArray:
        """Generalised winding numbers (n,) of points q about the triangles (Van Oosterom and Strackee's angle)."""
        ra, rb, rc = a[None] - q[:, None], b[None] - q[:, None], c[None] - q[:, None]
        la, lb, lc = (np.linalg.norm(r, axis=-1) for r in (ra, rb, rc))
        num = np.einsum("ntk,ntk->nt", ra, np.cross(rb, rc))
        den = (
            la * lb * lc
            + np.einsum("ntk,ntk->nt", ra, rb) * lc
            + np.einsum("ntk,ntk->nt", rb, rc) * la
            + np.einsum("ntk,ntk->nt", rc, ra) * lb
        )
        return np.asarray(np.arctan2(num, den).sum(axis=1) / (2.0 * np.pi))

    def transformed(self, X_CA: FloatArray) -> Polyhedron:
        """The same body expressed in frame C, given the pose X_CA of its frame A in C (its faces triangulated
        again in C: what the simulator renders, so a scene's noise does not hang on how the body was moved)."""
        return Polyhedron(transform_points(X_CA, self.vertices), self.faces, self.names)

    def moved(self, X_CA: FloatArray) -> Polyhedron:
        """:meth:`transformed` for a body moved rigidly many times (a part turning on a positioner): the faces'
        triangulation kept, the planes and the centre moved (no face triangulated again); a motion that is not
        rigid is :meth:`transformed`."""
        X = np.asarray(X_CA, dtype=float)
        R, t = X[:3, :3], X[:3, 3]
        if not np.allclose(R.T @ R, np.eye(3), atol=1e-9) or np.linalg.det(R) < 0.0:
            return self.transformed(X)
        out = object.__new__(Polyhedron)
        n = self._planes[:, :3] @ R.T
        vol, c, radius = self._mass
        V = transform_points(X, self.vertices)
        for k, v in (
            ("vertices", readonly(V)),
            ("faces", self.faces),
            ("names", self.names),
            ("_planes", readonly(np.column_stack([n, self._planes[:, 3] + n @ t]))),
            ("_tris", self._tris),
            ("_mass", (vol, readonly(R @ c + t), radius)),
            ("_bounds", readonly(np.array([V.min(axis=0), V.max(axis=0)]))),
        ):
            object.__setattr__(out, k, v)
        return out

    @property
    def volume(self) -> float:
        """The enclosed volume [m^3]."""
        return self._mass[0]

    def _volume_centroid(self) -> tuple[float, FloatArray]:
        o = self.vertices.mean(axis=0)
        tri = self.vertices[self._tris] - o
        v6 = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2]))  # 6 x signed tetrahedron volumes
        vol = float(v6.sum()) / 6.0
        if abs(vol) <= 1e-300:
            return 0.0, np.asarray(o)
        c = (v6[:, None] * tri.sum(axis=1)).sum(axis=0) / (4.0 * v6.sum())
        return vol, np.asarray(c + o)

    @property
    def center(self) -> FloatArray:
        """(3,) the centroid of the body's volume [m]."""
        return self._mass[1]

    @property
    def radius(self) -> float:
        """The radius [m] of a sphere about :attr:`center` that holds the whole body."""
        return self._mass[2]

    def edges(self) -> FloatArray:
        """(m, 2, 3) the body's feature edges (where two faces of different planes meet, or an open border) [m]."""
        owners: dict[tuple[int, int], list[int]] = {}
        for i, f in enumerate(self.faces):
            for a, b in zip(f, f[1:] + f[:1], strict=True):
                if a != b:
                    owners.setdefault((min(a, b), max(a, b)), []).append(i)
        out = []
        for (a, b), fs in owners.items():
            planes = self._planes[fs]
            if len(fs) == 2 and np.allclose(planes[0], planes[1], atol=1e-9):
                continue  # an edge inside one plane (a face split in two)
            out.append((self.vertices[a], self.vertices[b]))
        return np.array(out, dtype=float).reshape(-1, 2, 3)
