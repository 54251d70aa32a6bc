"""Obstacle bodies grown by a safety margin, numpy and scipy only (the coal shapes are built in
:mod:`cell.motion.collision.shapes`): a box or a convex polyhedron grows each face out by the margin, a body that is
not convex grows along its vertex normals, each face at least the margin out (docs/bodies.md section 2)."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from scipy.spatial import HalfspaceIntersection

from cell.geometry import FloatArray
from cell.types import Polyhedron

CONVEX_TOL = 1e-7  # [m] how far a vertex may lie outside a face's plane for the body still to count as convex
_SHARPEST = 0.1  # a vertex normal closer than this (cosine) to a face's plane moves out at most 10 x the margin


def face_planes(body: Polyhedron) -> FloatArray:
    """(f, 4) every face's outward unit normal and offset (n, d: the face lies in n . p = d) [m]."""
    return np.array([[*n, d] for n, d in (body.face_plane(f) for f in body.face_names())])


def is_convex(body: Polyhedron, tol: float = CONVEX_TOL) -> bool:
    """Whether every vertex lies on the inner side of every face's plane (within ``tol`` [m])."""
    planes = face_planes(body)
    return bool(np.all(np.asarray(body.vertices) @ planes[:, :3].T <= planes[:, 3] + tol))


def grown_convex(body: Polyhedron, margin: float) -> FloatArray:
    """(k, 3) [m] the vertices of a convex body's faces' half-spaces each moved out by ``margin``."""
    planes = face_planes(body)
    if margin == 0.0:
        return np.array(body.vertices, dtype=float)
    halfspaces = np.column_stack([planes[:, :3], -(planes[:, 3] + margin)])  # A x + b <= 0
    hs = HalfspaceIntersection(halfspaces, np.asarray(body.center, dtype=float))
    pts = np.asarray(hs.intersections, dtype=float)
    return np.unique(np.round(pts, 12), axis=0)


def grown_mesh(body: Polyhedron, margin: float) -> tuple[FloatArray, npt.NDArray[np.intp]]:
    """A body of any shape grown along its vertex normals: vertices (k, 3) [m] (same order) and its triangles."""
    v = np.array(body.vertices, dtype=float)
    planes = face_planes(body)
    incident: list[list[int]] = [[] for _ in range(len(v))]
    for f, face in enumerate(body.faces):
        for i in face:
            incident[i].append(f)
    for i, fs in enumerate(incident):
        if not fs or margin == 0.0:
            continue
        normals = planes[sorted(set(fs)), :3]
        mean = normals.sum(axis=0)
        norm = float(np.linalg.norm(mean))
        if norm <= 1e-12:  # opposite faces through one vertex: no outward direction; leave it
            continue
        u = mean / norm
        v[i] += margin / max(float((normals @ u).min()), _SHARPEST) * u
    return v, np.asarray(body.triangles(), dtype=np.intp)


def bounding_box(points: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The axis-aligned box of points (k, 3): rotation (3, 3) (identity), centre (3,), half sizes (3,) [m]."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    return np.eye(3), (lo + hi) / 2.0, (hi - lo) / 2.0
