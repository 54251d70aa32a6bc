"""Oriented boxes from polyhedral bodies, and what is wrong with a body that is not one (no ezdxf here)."""

from __future__ import annotations

import itertools
from collections import Counter
from collections.abc import Sequence

import numpy as np

from cell.errors import MapError
from cell.geometry import FloatArray, make_pose
from cell.types import Box

BOX_TOL = 1e-4  # a body must be a box within this [m] (0.1 mm)
_SAME_DIRECTION = float(np.cos(np.radians(5.0)))  # face normals this close are one axis


def fit_box(vertices: FloatArray, faces: Sequence[Sequence[int]], name: str, tol: float = BOX_TOL) -> Box:
    """The oriented box of a polyhedral body, or MapError if the body is not a box within ``tol``.

    vertices : (n, 3) [m]; faces : vertex index tuples. The axes come from the face normals, ordered to be as
    close as possible to the frame's x, y, z (right-handed); the extents from the vertices.
    """
    vertices = np.asarray(vertices, dtype=float)
    if vertices.ndim != 2 or vertices.shape[1] != 3:
        raise ValueError(f"fit_box: vertices must be (n, 3), got {vertices.shape}")
    normals, areas, used = [], [], []
    for f in faces:
        p = vertices[list(f)]
        n = np.cross(p, np.roll(p, -1, axis=0)).sum(axis=0)  # Newell: |n| = 2 * area
        a = float(np.linalg.norm(n)) / 2.0
        if a > tol * tol:
            normals.append(n / (2.0 * a))
            areas.append(a)
            used.append(f)
    # Group the face normals into directions (up to sign) with a loose angle; the plane test below is strict.
    sums: list[FloatArray] = []  # area-weighted normal sum of each direction
    for n, a in zip(normals, areas, strict=True):
        for i, d in enumerate(sums):
            c = float(n @ d) / float(np.linalg.norm(d))
            if abs(c) > _SAME_DIRECTION:
                sums[i] = d + np.copysign(a, c) * n
                break
        else:
            sums.append(a * n)
    if len(sums) != 3:
        raise MapError(f"part {name} is not a box: its faces point in {len(sums)} directions, a box's in 3")
    D = np.array([d / np.linalg.norm(d) for d in sums])
    if np.max(np.abs(D @ D.T - np.eye(3))) > np.sin(np.radians(5.0)):
        raise MapError(f"part {name} is not a box: its face directions are not perpendicular")
    U, _, Vt = np.linalg.svd(D.T)  # nearest orthonormal set of axes (columns)
    A = U @ Vt
    perm = max(itertools.permutations(range(3)), key=lambda q: sum(abs(A[i, q[i]]) for i in range(3)))
    R = A[:, list(perm)]
    R = R * np.sign(np.where(np.diag(R) == 0.0, 1.0, np.diag(R)))  # each axis towards its M axis
    if np.linalg.det(R) < 0.0:  # make it right-handed: flip the axis furthest from its M axis
        k = int(np.argmin(np.abs(np.diag(R))))
        R[:, k] = -R[:, k]
    q = vertices @ R  # coordinates along the box axes
    lo, hi = q.min(axis=0), q.max(axis=0)
    size = hi - lo
    if np.any(size <= tol):
        raise MapError(f"part {name} is not a box: it is flat ({size.min() * 1000:.3f} mm thick)")
    # Every face must lie on one of the six planes of the box, and the faces must cover its surface once.
    axis_of = [int(np.argmax(np.abs(R.T @ normals[i]))) for i in range(len(used))]
    for f, k in zip(used, axis_of, strict=True):
        c = q[list(f), k]
        if not (np.all(np.abs(c - lo[k]) <= tol) or np.all(np.abs(c - hi[k]) <= tol)):
            raise MapError(f"part {name} is not a box within {tol * 1000:.1f} mm: a face lies inside it")
    surface = 2.0 * (size[0] * size[1] + size[1] * size[2] + size[2] * size[0])
    if abs(sum(areas) - surface) > tol * 4.0 * float(size.sum()):
        raise MapError(
            f"part {name} is not a closed box: its faces cover {sum(areas) * 1e6:.0f} mm^2 "
            f"of a {surface * 1e6:.0f} mm^2 box surface"
        )
    return Box(make_pose(R, R @ ((lo + hi) / 2.0)), size)


def zero_area_faces(vertices: FloatArray, faces: Sequence[Sequence[int]], tol: float = BOX_TOL) -> int:
    """How many faces have an area of at most ``tol`` squared (degenerate: collinear or repeated vertices)."""
    n = 0
    for f in faces:
        p = vertices[list(f)]
        if float(np.linalg.norm(np.cross(p, np.roll(p, -1, axis=0)).sum(axis=0))) / 2.0 <= tol * tol:
            n += 1
    return n


def open_edges(vertices: FloatArray, faces: Sequence[Sequence[int]], tol: float = BOX_TOL) -> int:
    """How many edges belong to one face only (0 for a closed body), vertices within ``tol`` taken as one."""
    key = np.round(np.asarray(vertices, dtype=float) / tol).astype(np.int64)
    _, ids = np.unique(key, axis=0, return_inverse=True)
    ids = ids.reshape(-1)
    count: Counter[tuple[int, int]] = Counter()
    for f in faces:
        v = [int(ids[i]) for i in f]
        for a, b in zip(v, v[1:] + v[:1], strict=True):
            if a != b:
                count[(min(a, b), max(a, b))] += 1
    return sum(1 for c in count.values() if c == 1)


def bounding_box(vertices: FloatArray) -> Box:
    """The box along the frame's axes holding every vertex (a fixture's obstacle when it is not a box)."""
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    return Box(make_pose(p=(lo + hi) / 2.0), np.maximum(hi - lo, BOX_TOL))
