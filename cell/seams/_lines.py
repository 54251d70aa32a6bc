"""Lines and planes: where two planes meet, where a line meets a plane or a box (frame R, metres).

Planes are ``n . p = d`` with a unit normal ``n`` (3,) and offset ``d``.
"""

from __future__ import annotations

import numpy as np

from cell.geometry import FloatArray
from cell.types import Box, Part


def plane_intersection(
    n_a: FloatArray, d_a: float, n_b: FloatArray, d_b: float, p_near: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Line where two planes meet: the point (3,) of it nearest ``p_near`` and its unit direction n_a x n_b
    (3,).

    Raises ValueError when the planes are (nearly) parallel.
    """
    ax, ay, az = (float(v) for v in n_a)
    bx, by, bz = (float(v) for v in n_b)
    t = np.array([ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx])
    norm2 = float(t @ t)  # = 1 - c^2 for unit normals
    if norm2 < 1e-12:
        raise ValueError("planes are parallel: they do not meet in a line")
    t = t / np.sqrt(norm2)
    c = ax * bx + ay * by + az * bz
    # The point of the line nearest the origin is a n_a + b n_b; then slide along t to the one nearest p_near.
    a = (d_a - d_b * c) / norm2
    b = (d_b - d_a * c) / norm2
    p0 = a * np.asarray(n_a, float) + b * np.asarray(n_b, float)
    p0 = p0 + float(t @ (np.asarray(p_near, float) - p0)) * t
    return p0, t


def line_plane_parameter(p0: FloatArray, t: FloatArray, n: FloatArray, d: float) -> float:
    """Parameter s [m] where the line p0 + s t meets the plane n . p = d (inf when parallel)."""
    nt = float(n @ t)
    if abs(nt) < 1e-9:
        return float("inf")
    return float((d - n @ p0) / nt)


def line_box_span(p0: FloatArray, t: FloatArray, box: Box) -> tuple[float, float]:
    """Parameters (s_in, s_out) [m] where the line p0 + s t (3,) (frame of ``box``) enters and leaves ``box``;
    (inf, -inf) when it misses it."""
    R, c = box.X_AB[:3, :3], box.center
    o, d = R.T @ (np.asarray(p0, float) - c), R.T @ np.asarray(t, float)
    h = 0.5 * np.asarray(box.size, float)
    s_in, s_out = -np.inf, np.inf
    for k in range(3):
        if abs(d[k]) < 1e-12:
            if abs(o[k]) > h[k]:
                return float("inf"), float("-inf")
            continue
        a, b = (-h[k] - o[k]) / d[k], (h[k] - o[k]) / d[k]
        s_in, s_out = max(s_in, min(a, b)), min(s_out, max(a, b))
    return (float(s_in), float(s_out)) if s_in <= s_out else (float("inf"), float("-inf"))


def extent_behind(part: Part, n: FloatArray, d: float) -> float:
    """How far [m] a part's body reaches behind the plane n . p = d (one of its outward face planes): the largest
    d - n . v over its vertices (a box's edge length across that face)."""
    return float(np.max(d - part.vertices() @ n))
