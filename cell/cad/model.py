"""A part's CAD as the seam proposer reads it: bodies with their faces (exact surfaces where the file has them) and
their sharp edges (lines, circular arcs, other curves), in the CAD's frame ``M``, metres. Numpy only: the adapters
(:mod:`cell.cad._ocp`, :mod:`cell.cad._trimesh`) fill these from a STEP file or a mesh."""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field

import numpy as np

from cell.geometry import FloatArray, readonly


class SurfaceKind(enum.StrEnum):
    PLANE = "plane"
    CYLINDER = "cylinder"
    OTHER = "other"  # any other surface: its normal is read off the body's triangles


class CurveKind(enum.StrEnum):
    LINE = "line"
    ARC = "arc"  # a circular arc; a full circle has a sweep of 2 pi
    CURVE = "curve"  # any other curve, as a polyline


@dataclass(frozen=True)
class Face:
    """One face of a body: its surface and which of the body's triangles tessellate it.

    plane: ``normal`` the outward unit normal (3,), ``offset`` with normal . p = offset [m];
    cylinder: ``origin`` a point of the axis, ``axis`` its unit direction, ``radius`` [m], ``sign`` +1 when the
    outward normal points away from the axis (a tube's outer wall), -1 towards it (a hole's wall).
    """

    kind: SurfaceKind
    normal: FloatArray = field(default_factory=lambda: readonly(np.zeros(3)))
    offset: float = 0.0
    origin: FloatArray = field(default_factory=lambda: readonly(np.zeros(3)))
    axis: FloatArray = field(default_factory=lambda: readonly(np.zeros(3)))
    radius: float = 0.0
    sign: float = 1.0

    def __post_init__(self) -> None:
        for name in ("normal", "origin", "axis"):
            object.__setattr__(self, name, readonly(getattr(self, name)))


@dataclass(frozen=True)
class Edge:
    """A sharp edge of a body, between two of its faces, in ``M`` [m].

    line: ``points`` its two ends; arc: ``centre``, unit ``axis`` (the arc turns counter-clockwise about it),
    ``radius``, unit ``start`` (from the centre to the first end) and ``sweep`` [rad]; curve: ``points`` (n, 3).
    ``breaks`` (k + 1,) the parameters t in [0, 1] where the faces beside the edge change and ``faces`` (k, 2) the
    two faces' indices on each piece (one piece for an exact edge; a mesh's edge runs along many triangles).
    """

    kind: CurveKind
    points: FloatArray
    faces: tuple[tuple[int, int], ...]
    breaks: FloatArray = field(default_factory=lambda: readonly(np.array([0.0, 1.0])))
    centre: FloatArray = field(default_factory=lambda: readonly(np.zeros(3)))
    axis: FloatArray = field(default_factory=lambda: readonly(np.zeros(3)))
    radius: float = 0.0
    start: FloatArray = field(default_factory=lambda: readonly(np.zeros(3)))
    sweep: float = 0.0

    def __post_init__(self) -> None:
        for name in ("points", "breaks", "centre", "axis", "start"):
            object.__setattr__(self, name, readonly(getattr(self, name)))
        if len(self.faces) != len(self.breaks) - 1:
            raise ValueError("Edge needs one (face, face) pair per piece between its breaks")

    @property
    def length(self) -> float:
        if self.kind == CurveKind.ARC:
            return self.radius * self.sweep
        return float(np.linalg.norm(np.diff(self.points, axis=0), axis=1).sum())

    @property
    def closed(self) -> bool:
        return self.kind == CurveKind.ARC and self.sweep >= 2.0 * math.pi - 1e-9

    def at(self, t: FloatArray) -> FloatArray:
        """Points (n, 3) at parameters ``t`` (n,) in [0, 1] (by length along the edge)."""
        t = np.asarray(t, dtype=float)
        if self.kind == CurveKind.ARC:
            a = t * self.sweep
            v = np.cross(self.axis, self.start)
            return np.asarray(self.centre + self.radius * (np.outer(np.cos(a), self.start) + np.outer(np.sin(a), v)))
        seg = np.linalg.norm(np.diff(self.points, axis=0), axis=1)
        s = np.concatenate([[0.0], np.cumsum(seg)]) / max(float(seg.sum()), 1e-300)
        return np.stack([np.interp(t, s, self.points[:, k]) for k in range(3)], axis=1)

    def tangent(self, t: FloatArray) -> FloatArray:
        """Unit tangents (n, 3) at parameters ``t``, in the direction of increasing t."""
        t = np.asarray(t, dtype=float)
        if self.kind == CurveKind.ARC:
            a = t * self.sweep
            v = np.cross(self.axis, self.start)
            return np.asarray(np.outer(-np.sin(a), self.start) + np.outer(np.cos(a), v))
        h = 1e-4
        d = self.at(np.clip(t + h, 0, 1)) - self.at(np.clip(t - h, 0, 1))
        return np.asarray(d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-300))

    def piece(self, t: FloatArray) -> np.ndarray:
        """The index of the piece (into ``faces``) each parameter of ``t`` lies on."""
        return np.clip(np.searchsorted(self.breaks, t, side="right") - 1, 0, len(self.faces) - 1)


@dataclass(frozen=True)
class Body:
    """A solid of the CAD: its name (the assembly's, or the file's and a number), its layers, its faces and sharp
    edges, and its tessellation (``vertices`` (k, 3) [m], ``triangles`` (t, 3) counter-clockwise seen from
    outside, ``triangle_face`` (t,) the face each triangle belongs to)."""

    name: str
    faces: tuple[Face, ...]
    edges: tuple[Edge, ...]
    vertices: FloatArray
    triangles: np.ndarray
    triangle_face: np.ndarray
    layers: tuple[str, ...] = ()  # the CAD's layers the body is on (a STEP's; a mesh has none)

    def __post_init__(self) -> None:
        object.__setattr__(self, "vertices", readonly(self.vertices))
        object.__setattr__(self, "triangles", readonly(self.triangles, np.intp))
        object.__setattr__(self, "triangle_face", readonly(self.triangle_face, np.intp))

    @property
    def volume(self) -> float:
        a, b, c = (self.vertices[self.triangles[:, k]] for k in range(3))
        return abs(float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum()) / 6.0)

    @property
    def extent(self) -> FloatArray:
        return np.asarray(np.ptp(self.vertices, axis=0))

    def normal_at(self, face: int, p: FloatArray) -> FloatArray:
        """Outward unit normals (n, 3) of face ``face`` at points ``p`` (n, 3) on it."""
        f = self.faces[face]
        p = np.atleast_2d(p)
        if f.kind == SurfaceKind.PLANE:
            return np.tile(f.normal, (len(p), 1))
        if f.kind == SurfaceKind.CYLINDER:
            r = p - f.origin
            r = r - np.outer(r @ f.axis, f.axis)
            return np.asarray(f.sign * r / np.maximum(np.linalg.norm(r, axis=1, keepdims=True), 1e-300))
        tris = self.triangles[self.triangle_face == face]
        a, b, c = (self.vertices[tris[:, k]] for k in range(3))
        n = np.cross(b - a, c - a)
        n = n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
        centres = (a + b + c) / 3.0
        nearest = np.argmin(((p[:, None, :] - centres[None]) ** 2).sum(axis=2), axis=1)
        return np.asarray(n[nearest])


@dataclass(frozen=True)
class CadModel:
    """What one CAD file holds: its bodies in ``M`` [m], the units it was read in, what was doubted (warnings)."""

    bodies: tuple[Body, ...]
    source: str
    units: str
    warnings: tuple[str, ...] = ()
