"""Features of a mask's points for the paper's locator (:mod:`cell.seams.paper`, its step 2): point spacing, PCA
normals and boundary points (an angle gap on the tangent plane, as open3d's ``compute_boundary_points``), with
numpy/scipy from the points' own KD-tree. Everything is in the robot frame R, metres.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy.spatial import cKDTree

from cell.geometry import FloatArray

# Point spacing = median distance to the 4th nearest neighbour: on a voxel grid that is one voxel whether a
# face keeps one point per grid cell or two (a face lying on a grid plane fills the voxels on both sides of
# it, and the nearest neighbour is then its twin, a fraction of a millimetre away).
SPACING_NEIGHBOUR = 4
NORMAL_NEIGHBOURS = 12  # PCA normal from the k nearest points ...
NORMAL_RADIUS_SPACINGS = 2.5  # ... within this many point spacings
BOUNDARY_NEIGHBOURS = 30  # as open3d's compute_boundary_points default max_nn
BOUNDARY_RADIUS_SPACINGS = 2.5
BOUNDARY_ANGLE_RAD = np.pi / 2.0  # angle gap that makes a boundary point (open3d's default 90 deg)


@dataclass(frozen=True)
class CloudFeatures:
    """Features of a set of points (n, 3).

    spacing : point spacing [m] (the voxel size of a voxelised cloud, see :data:`SPACING_NEIGHBOUR`);
    normals : (n, 3) unit (sign arbitrary);
    boundary : (n,) bool, the point's neighbourhood is one-sided on its tangent plane."""

    spacing: float
    normals: FloatArray
    boundary: npt.NDArray[np.bool_]


def _neighbours(tree: cKDTree, pts: FloatArray, k: int, radius: float) -> tuple[npt.NDArray[np.intp], npt.NDArray]:
    """(n, k) neighbour indices and a validity mask (inside ``radius``, not the point itself)."""
    k = min(k, len(pts))
    dist, idx = tree.query(pts, k=k, distance_upper_bound=radius)
    idx = np.asarray(idx).reshape(len(pts), k)
    valid = np.isfinite(np.asarray(dist).reshape(len(pts), k)) & (idx != np.arange(len(pts))[:, None])
    return np.where(valid, idx, 0), valid


def estimate_normals(tree: cKDTree, pts: FloatArray, radius: float) -> FloatArray:
    """(n, 3) unit normals by PCA of each point's neighbourhood (the point included); NaN rows when < 3
    points."""
    idx, valid = _neighbours(tree, pts, NORMAL_NEIGHBOURS + 1, radius)
    w = valid.astype(float)
    q = pts[idx]  # (n, k, 3)
    cnt = w.sum(1) + 1.0
    mean = (np.einsum("nk,nkd->nd", w, q) + pts) / cnt[:, None]
    dq = (q - mean[:, None, :]) * w[:, :, None]
    d0 = pts - mean
    cov = np.einsum("nki,nkj->nij", dq, dq) + np.einsum("ni,nj->nij", d0, d0)
    _, vecs = np.linalg.eigh(cov)
    normals = vecs[:, :, 0]
    normals[cnt < 3.5] = np.nan
    return np.asarray(normals)


def boundary_points(tree: cKDTree, pts: FloatArray, normals: FloatArray, radius: float) -> npt.NDArray[np.bool_]:
    """Angle-gap criterion: project the neighbours onto the point's tangent plane; a gap wider than 90 deg
    between consecutive neighbour directions makes it a boundary point (so do fewer than 3 neighbours or no
    normal)."""
    idx, valid = _neighbours(tree, pts, BOUNDARY_NEIGHBOURS + 1, radius)
    n = np.nan_to_num(normals)
    # A tangent basis (e1, e2) per point.
    helper = np.where(np.abs(n[:, [0]]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    e1 = np.cross(n, helper)
    e1 /= np.maximum(np.linalg.norm(e1, axis=1, keepdims=True), 1e-12)
    e2 = np.cross(n, e1)
    v = pts[idx] - pts[:, None, :]
    ang = np.arctan2(np.einsum("nkd,nd->nk", v, e2), np.einsum("nkd,nd->nk", v, e1))
    # Invalid neighbours repeat the first valid angle: duplicates open no gap.
    first = np.take_along_axis(ang, np.argmax(valid, axis=1)[:, None], axis=1)
    ang = np.sort(np.where(valid, ang, first), axis=1)
    gaps = np.diff(ang, axis=1)
    wrap = 2.0 * np.pi - (ang[:, -1] - ang[:, 0])
    max_gap = np.maximum(gaps.max(axis=1, initial=0.0), wrap)
    few = valid.sum(1) < 3
    return np.asarray((max_gap > BOUNDARY_ANGLE_RAD) | few | ~np.isfinite(normals).all(1))


def cloud_features(pts: FloatArray) -> CloudFeatures:
    """Spacing, normals and boundary flags of the points ``pts`` (n, 3) (one mask's), from their own KD-tree."""
    if len(pts) < SPACING_NEIGHBOUR + 1:
        return CloudFeatures(0.0, np.full((len(pts), 3), np.nan), np.ones(len(pts), bool))
    tree = cKDTree(pts)
    d, _ = tree.query(pts, k=SPACING_NEIGHBOUR + 1)
    spacing = float(np.median(d[:, SPACING_NEIGHBOUR]))
    normals = estimate_normals(tree, pts, NORMAL_RADIUS_SPACINGS * spacing)
    boundary = boundary_points(tree, pts, normals, BOUNDARY_RADIUS_SPACINGS * spacing)
    return CloudFeatures(spacing, normals, boundary)
