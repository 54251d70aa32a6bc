"""How a rigid body comes to rest on a level table: on the facet of its convex hull under its centre of mass.

Used both to plan the turn of a part (on the drawn boxes: :mod:`cell.planning.turnover`) and by the simulator to set the
turned as-built part down (its boxes and the beads on it). Pure geometry: numpy and scipy; metres, radians; any
frame whose +z is up.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial import ConvexHull

from cell.geometry import FloatArray, make_pose


def axis_rotation(axis: FloatArray, angle: float) -> FloatArray:
    """(3, 3) the rotation by ``angle`` [rad] about the unit ``axis`` (3,) (Rodrigues)."""
    k = np.asarray(axis, dtype=float) / float(np.linalg.norm(axis))
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + math.sin(angle) * K + (1.0 - math.cos(angle)) * (K @ K)


def _levelling(n_down: FloatArray) -> FloatArray:
    """(3, 3) the smallest rotation taking the unit outward facet normal ``n_down`` onto -z."""
    target = np.array([0.0, 0.0, -1.0])
    v = np.cross(n_down, target)
    s = float(np.linalg.norm(v))
    if s < 1e-12:
        return np.eye(3)
    return axis_rotation(v / s, math.atan2(s, float(n_down @ target)))


def rest_facet(points: FloatArray, com: FloatArray) -> tuple[FloatArray, float]:
    """The hull facet the body falls onto from where it is: the facet crossed by the vertical line down from its
    centre of mass. points : (n, 3) the body's vertices; com : (3,) its centre of mass.

    Returns the facet's outward unit normal (3,) and the margin [m] by which the centre of mass, projected along
    that normal, lies inside the facet's polygon (negative: outside, the body would tip over).
    """
    hull = ConvexHull(points)
    best: tuple[float, FloatArray] | None = None
    for eq, simplex in zip(hull.equations, hull.simplices, strict=True):
        n = eq[:3]
        if n[2] >= -1e-9:  # only facets facing down can meet the table
            continue
        # Where the vertical through the centre of mass meets this facet's plane; a convex body's lower boundary
        # is crossed once, so the facet that holds that point is the one it rests on.
        t = -(float(n @ com) + eq[3]) / float(n[2])
        inside = _inside(points[simplex], com + np.array([0.0, 0.0, t]), n)
        if best is None or inside > best[0]:
            best = (inside, n)
    if best is None:
        raise ValueError("rest_facet: the body has no downward hull facet")
    n = best[1]
    return n, _support_margin(points, com, n)


def _inside(tri: FloatArray, p: FloatArray, n: FloatArray) -> float:
    """Signed distance [m] of p inside the triangle ``tri`` (3, 3) seen along n (negative: outside)."""
    d = []
    for i in range(3):
        a, b = tri[i], tri[(i + 1) % 3]
        e = np.cross(n, b - a)  # points into the triangle for a consistent winding, or out: fixed below
        e /= max(float(np.linalg.norm(e)), 1e-15)
        d.append(float(e @ (p - a)))
    inside_sign = 1.0 if float(np.cross(n, tri[1] - tri[0]) @ (tri[2] - tri[0])) > 0 else -1.0
    return min(inside_sign * x for x in d)


def _support_margin(points: FloatArray, com: FloatArray, n: FloatArray, tol_m: float = 1e-4) -> float:
    """How far [m] the centre of mass, projected along n, lies inside the polygon of the points on the facet
    plane (the support polygon; negative: outside)."""
    h = points @ n
    on = points[h >= h.max() - tol_m]
    u = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(n, u)
    q = np.column_stack([on @ u, on @ v])
    c = np.array([com @ u, com @ v])
    if len(q) < 3:
        return -float(np.min(np.linalg.norm(q - c, axis=1)))
    hull = ConvexHull(q)
    return float(np.min(-(hull.equations[:, :2] @ c + hull.equations[:, 2])))


def set_down(
    points: FloatArray, com: FloatArray, R_turn: FloatArray, pivot: FloatArray, table_z: float
) -> tuple[FloatArray, float, float]:
    """Turn a body by R_turn (3, 3) about ``pivot`` (3,), let it settle on the hull facet under its centre of mass,
    and set it down on the table at height ``table_z`` with the pivot over the same place.

    points : (n, 3) the body's vertices; com : (3,) its centre of mass (same frame).
    Returns X (4, 4) the rigid motion from the body's pose now to its resting pose, the tilt [rad] of the rest
    (0: the facet was level after the turn) and the support margin [m] (negative: it would tip over).
    """
    X_turn = make_pose(R_turn, pivot - R_turn @ pivot)
    p = points @ X_turn[:3, :3].T + X_turn[:3, 3]
    c = X_turn[:3, :3] @ com + X_turn[:3, 3]
    n, margin = rest_facet(p, c)
    R_lev = _levelling(n)
    tilt = math.acos(max(-1.0, min(1.0, -float(n[2]))))
    X_lev = make_pose(R_lev, c - R_lev @ c)
    X = X_lev @ X_turn
    moved_pivot = X[:3, :3] @ pivot + X[:3, 3]
    low = float((points @ X[:3, :3].T + X[:3, 3])[:, 2].min())
    shift = np.array([pivot[0] - moved_pivot[0], pivot[1] - moved_pivot[1], table_z - low])
    X[:3, 3] += shift
    # To 1e-12 (a picometre; a millionth of a milliradian): the hull and the products above may differ in their
    # last bits between processes (BLAS kernels by memory alignment), and a start that differs there can end an
    # ICP elsewhere within its tolerance. Rounded, the same body rests at the same pose in every process.
    return np.round(X, 12), tilt, margin
