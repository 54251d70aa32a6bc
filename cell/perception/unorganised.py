"""Unorganised point clouds from any sensor (a swept laser line, a lidar, a stitched scan): the steps that replace what
a depth camera's intrinsics and viewing direction give for free: the table plane and the noise on it, levelling, the
point spacing, normals oriented by a stated heuristic (docs/locate.md, "From the cloud to the seams").
All in one frame (the cloud's, or the levelled one), metres."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from cell.errors import SensorError
from cell.geometry import FloatArray, make_pose
from cell.perception import _open3d
from cell.perception.preprocess import downsample
from cell.types import Cloud

_NORMAL_RADIUS_M = 0.01  # neighbourhood of a point's normal for the table search
_NORMAL_NEIGHBOURS = 30
_GRID_M = 0.003  # the table's hypotheses are drawn from the cloud on this grid
_UP_COS = math.cos(math.radians(20.0))  # a table candidate's normal within 20 deg of +z
_STEEP_COS = math.cos(math.radians(70.0))  # |n_z| below this: a steep face (oriented away from the centroid)


@dataclass(frozen=True)
class TablePlane:
    """The table top found in a cloud: points p with ``normal @ p = offset`` (normal up, unit).

    sigma_m : the cloud's noise on it (1.4826 x the median absolute residual of the inliers) [m].
    inliers : (n,) mask of the cloud's points on it (within ``inlier_sigmas`` of the refit).
    """

    normal: FloatArray
    offset: float
    sigma_m: float
    inliers: np.ndarray

    @property
    def tilt_rad(self) -> float:
        """Angle between the table's normal and +z [rad]."""
        return float(math.acos(min(1.0, abs(float(self.normal[2])))))

    def height(self, points: FloatArray) -> FloatArray:
        """Signed height (n,) of points (n, 3) above the table [m]."""
        return np.asarray(points) @ self.normal - self.offset


def find_table(
    points: FloatArray,
    rng: np.random.Generator,
    *,
    threshold_m: float = 0.004,
    iterations: int = 300,
    inlier_sigmas: float = 3.0,
) -> TablePlane:
    """The largest near-horizontal plane of ``points`` (n, 3): the table (see the module docstring).

    RANSAC on the points whose local normal is within 20 degrees of +z (of the cloud on a 3 mm grid;
    ``iterations`` hypotheses from ``rng``, inliers within ``threshold_m``), then a least-squares refit of all
    the cloud's inliers, the noise measured, and the inliers taken again within ``inlier_sigmas`` noise scales.
    SensorError when no such plane holds a tenth of the candidates.
    """
    P = np.asarray(points, dtype=np.float64)
    if len(P) < 100:
        raise SensorError(f"a table plane needs at least 100 points, the cloud has {len(P)}")
    G = downsample(Cloud(P, "F"), _GRID_M).points  # hypotheses from a grid of the cloud: its normals are cheaper
    n = _open3d.estimate_normals(G, _NORMAL_RADIUS_M, _NORMAL_NEIGHBOURS)
    Q = G[np.abs(n[:, 2]) >= _UP_COS]
    if len(Q) < 30:
        raise SensorError(f"no horizontal surface in the cloud ({len(Q)} points face up): no table to stand on")
    best, best_count = None, 0
    for _ in range(iterations):
        a, b, c = Q[rng.choice(len(Q), 3, replace=False)]
        m = np.cross(b - a, c - a)
        norm = float(np.linalg.norm(m))
        if norm < 1e-9:
            continue
        m /= norm
        if abs(m[2]) < _UP_COS:
            continue
        count = int(np.count_nonzero(np.abs((Q - a) @ m) < threshold_m))
        if count > best_count:
            best, best_count = (m, float(m @ a)), count
    if best is None or best_count < 0.1 * len(Q):
        raise SensorError(f"no table plane: the best horizontal plane holds {best_count} of {len(Q)} upward points")
    m, d = best
    on = np.abs(P @ m - d) < threshold_m
    for _ in range(3):  # least-squares refit, then the inliers by the measured noise
        c = P[on].mean(axis=0)
        _, _, vt = np.linalg.svd(P[on] - c, full_matrices=False)
        m = vt[2] if vt[2][2] > 0 else -vt[2]
        d = float(m @ c)
        r = P @ m - d
        sigma = 1.4826 * float(np.median(np.abs(r[on])))
        on = np.abs(r) < max(inlier_sigmas * sigma, 1e-4)
    return TablePlane(m, d, sigma, on)


def levelling(table: TablePlane) -> FloatArray:
    """(4, 4) X_LF: the smallest rotation about F's origin that turns the table's normal onto +z (levelled frame
    L); the table top is then the plane z = ``table.offset`` in L."""
    n = np.asarray(table.normal, dtype=np.float64)
    z = np.array([0.0, 0.0, 1.0])
    axis = np.cross(n, z)
    s, c = float(np.linalg.norm(axis)), float(n @ z)
    if s < 1e-12:
        return np.eye(4)
    k = axis / s
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    R = np.eye(3) + s * K + (1.0 - c) * (K @ K)
    return make_pose(R)


def sampling(points: FloatArray, table: TablePlane, patch_m: float = 0.1) -> tuple[float, float]:
    """(along, between) [m]: the cloud's point spacing on the table: the median nearest-neighbour distance
    (along a scan line) and, from the density of a ``patch_m`` square about the table's densest point, the
    spacing between lines (area per point over the spacing along)."""
    T = np.asarray(points)[table.inliers]
    if len(T) < 10:
        return math.nan, math.nan
    d, _ = cKDTree(T).query(T, k=2)
    along = float(np.median(d[:, 1]))
    # Density in the table's own coordinates (any two axes across the normal), where the points are.
    u = np.cross(table.normal, [1.0, 0.0, 0.0] if abs(table.normal[0]) < 0.9 else [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(table.normal, u)
    uv = np.column_stack([T @ u, T @ v])
    c = np.median(uv, axis=0)
    inside = np.all(np.abs(uv - c) < patch_m / 2.0, axis=1)
    density = np.count_nonzero(inside) / patch_m**2
    between = 1.0 / max(density * along, 1e-9)
    return along, max(between, along)


def orient_normals(normals: FloatArray, points: FloatArray, viewpoint: FloatArray | None = None) -> FloatArray:
    """``normals`` (n, 3) of ``points`` (n, 3) flipped by the heuristic of the module docstring."""
    n = np.array(normals, dtype=np.float64)
    P = np.asarray(points, dtype=np.float64)
    if viewpoint is not None:
        flip = np.einsum("ij,ij->i", n, np.asarray(viewpoint, dtype=np.float64) - P) < 0.0
    else:
        out = P - P.mean(axis=0)
        out[:, 2] = 0.0
        steep = np.abs(n[:, 2]) < _STEEP_COS
        flip = np.where(steep, np.einsum("ij,ij->i", n, out) < 0.0, n[:, 2] < 0.0)
    n[flip] *= -1.0
    return n
