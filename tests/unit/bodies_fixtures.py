"""Small polyhedral bodies for the tests of general bodies (docs/bodies.md): a tetrahedron, a wedge, an L-shaped
prism (not convex) and a 35 degree mitred brace standing on a rail."""

from __future__ import annotations

import math

import numpy as np

from cell.geometry import FloatArray
from cell.types import Polyhedron


def prism(profile_xz: FloatArray, y0: float, y1: float) -> Polyhedron:
    """A prism along y from y0 to y1 over a polygon (m, 2) in the x-z plane, counter-clockwise seen from -y.

    Faces: ``f0`` the -y end, ``f1`` the +y end, then one side per profile edge (``f2`` from vertex 0 to 1, ...).
    """
    p = np.asarray(profile_xz, dtype=float)
    m = len(p)
    lo = np.column_stack([p[:, 0], np.full(m, y0), p[:, 1]])
    hi = np.column_stack([p[:, 0], np.full(m, y1), p[:, 1]])
    v = np.vstack([lo, hi])
    # seen from -y, x right and z up is counter-clockwise: the -y end keeps the order, the +y end reverses it
    faces = [tuple(range(m)), tuple(range(2 * m - 1, m - 1, -1))]
    faces += [(i, m + i, m + (i + 1) % m, (i + 1) % m) for i in range(m)]
    return Polyhedron(v, tuple(faces))


def tetrahedron(scale: float = 0.1) -> Polyhedron:
    v = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]) * scale
    return Polyhedron(v, ((0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)))


def wedge(length: float = 0.2, base: float = 0.1, height: float = 0.05) -> Polyhedron:
    """A wedge along y: a right triangle in x-z (legs ``base`` along x, ``height`` along z at x = 0), z from 0."""
    return prism(np.array([[0.0, 0.0], [base, 0.0], [0.0, height]]), -length / 2.0, length / 2.0)


def l_prism(size: float = 0.1, wall: float = 0.02, length: float = 0.2) -> Polyhedron:
    """An L-shaped (angle) profile along y: not convex."""
    s, w = size, wall
    return prism(np.array([[0.0, 0.0], [s, 0.0], [s, w], [w, w], [w, s], [0.0, s]]), -length / 2.0, length / 2.0)


BRACE_DEG = 35.0


def brace(width: float = 0.04, depth: float = 0.04, length: float = 0.3, x0: float = 0.0) -> Polyhedron:
    """A square tube at ``BRACE_DEG`` to the plane z = 0, its lower end cut by that plane (a mitre), depth along y.

    The profile (x-z) is a parallelogram: its lower edge on z = 0 from x0 to x0 + width / sin(angle), its long sides
    along the brace's axis. Faces: ``f0``/``f1`` the -y/+y sides, ``f2`` the cut end on z = 0 (normal -z), ``f3``
    the long side facing +x and down (the acute 35 degree fillet with z = 0), ``f4`` the upper end, ``f5`` the long
    side facing up (the 145 degree one).
    """
    a = math.radians(BRACE_DEG)
    axis = np.array([math.cos(a), math.sin(a)])
    foot = width / math.sin(a)
    p0, p1 = np.array([x0, 0.0]), np.array([x0 + foot, 0.0])
    profile = np.array([p0, p1, p1 + length * axis, p0 + length * axis])
    return prism(profile, -depth / 2.0, depth / 2.0)
