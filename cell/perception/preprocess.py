"""Preprocessing of the spliced cloud (paper section 3.4): Z passthrough, outlier removal, voxel grid.

All thresholds derive from the voxel size ``spec.voxel_m`` here, in one place (:func:`outlier_parameters`).
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
from scipy.spatial import cKDTree

from cell.geometry import FloatArray, invert, transform_points
from cell.scenario import PerceptionSpec, WorkspaceSpec
from cell.types import Cloud
from cell.voxels import voxel_corners, voxel_order

_OUTLIER_MIN_NEIGHBOURS = 3  # other points within the radius a point needs to be kept


def outlier_parameters(voxel_m: float) -> tuple[float, int]:
    """(radius [m], minimum number of other points within it) of the isolated-outlier filter.

    The radius is one voxel: a point with fewer than three others within it would be a voxel of its own, made
    of a single stray measurement (flying pixel, splice artefact).
    """
    return voxel_m, _OUTLIER_MIN_NEIGHBOURS


def z_range_R(workspace: WorkspaceSpec, X_WR: FloatArray) -> tuple[float, float]:
    """(z_min, z_max) [m] in R of the workspace box (given in W): the z extent of its eight corners in R."""
    lo, hi = np.asarray(workspace.min_m), np.asarray(workspace.max_m)
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    z = transform_points(invert(np.asarray(X_WR, dtype=np.float64)), corners)[:, 2]
    return float(z.min()), float(z.max())


def radius_outlier_mask(points: FloatArray, radius_m: float, min_neighbours: int) -> npt.NDArray[np.bool_]:
    """(n,) True for points (n, 3) with at least ``min_neighbours`` other points within ``radius_m``.

    Same answer as open3d's radius outlier removal, but only the points that are not plainly inliers are
    searched. Cut space into cubes of edge radius / (2 sqrt 3): every point of the 3 x 3 x 3 cubes around a
    point's own cube lies within the radius of it, so a point with enough points in that block is kept without
    a search; the others are counted with a KD-tree of the points near them only.
    """
    n = len(points)
    if n == 0:
        return np.zeros(0, dtype=bool)
    cube = radius_m / (2.0 * math.sqrt(3.0)) * (1.0 - 1e-9)
    ijk = np.floor(points / cube).astype(np.int64)
    ijk -= ijk.min(axis=0) - 1  # one empty layer of cubes around, so neighbour keys never wrap
    dims = ijk.max(axis=0) + 2
    keys = (ijk[:, 0] * dims[1] + ijk[:, 1]) * dims[2] + ijk[:, 2]
    cells, inverse, counts = np.unique(keys, return_inverse=True, return_counts=True)
    offsets = np.arange(-1, 2)
    di, dj, dk = np.meshgrid(offsets, offsets, offsets, indexing="ij")
    block = np.zeros(len(cells), dtype=np.int64)
    for shift in ((di * dims[1] + dj) * dims[2] + dk).reshape(-1):
        at = np.searchsorted(cells, cells + shift)
        at = np.minimum(at, len(cells) - 1)
        block += np.where(cells[at] == cells + shift, counts[at], 0)
    inverse = inverse.reshape(-1)
    keep = block[inverse] - 1 >= min_neighbours
    doubtful = np.flatnonzero(~keep)
    if len(doubtful):
        # Only points within one radius-sized cube of a doubtful point's cube can be its neighbours.
        coarse = np.floor(points / radius_m).astype(np.int64)
        coarse -= coarse.min(axis=0) - 1
        cdims = coarse.max(axis=0) + 2
        ckeys = (coarse[:, 0] * cdims[1] + coarse[:, 1]) * cdims[2] + coarse[:, 2]
        near = np.unique(ckeys[doubtful])
        shifts = ((di * cdims[1] + dj) * cdims[2] + dk).reshape(-1)
        wanted = np.unique((near[:, None] + shifts[None, :]).reshape(-1))
        candidates = points[np.isin(ckeys, wanted)]
        found = cKDTree(candidates).query_ball_point(points[doubtful], radius_m, return_length=True)
        keep[doubtful] = np.asarray(found) - 1 >= min_neighbours  # each query point finds itself
    return keep


def preprocess(dense: Cloud, workspace: WorkspaceSpec, X_WR: FloatArray, spec: PerceptionSpec) -> Cloud:
    """The spliced cloud (frame R) filtered: Z passthrough (paper eq. 4) to the workspace's z range in R, then
    isolated outliers removed (radius and count from :func:`outlier_parameters`)."""
    if dense.frame != "R":
        raise ValueError(f"preprocess: cloud is in frame {dense.frame!r}; expected 'R'")
    z_lo, z_hi = z_range_R(workspace, X_WR)
    z = dense.points[:, 2]
    cloud = dense.select((z >= z_lo) & (z <= z_hi))
    radius, min_neighbours = outlier_parameters(spec.voxel_m)
    return cloud.select(radius_outlier_mask(np.asarray(cloud.points), radius, min_neighbours))


def downsample(cloud: Cloud, voxel_m: float) -> Cloud:
    """Voxel-grid filter: one point per occupied voxel of edge ``voxel_m`` [m], the centroid of its points.

    The grid is anchored at the origin of the cloud's frame (so it does not move with outliers). A voxel's
    camera index is that of its points when they all came from one capture, else -1. Points come out in voxel
    order (:func:`cell.voxels.voxel_order`).
    """
    if voxel_m <= 0:
        raise ValueError(f"downsample: voxel_m must be positive, got {voxel_m}")
    if len(cloud) == 0:
        return cloud
    ordered, table = voxel_order(cloud, voxel_m)
    at = table.starts[:-1]
    counts = table.counts
    # Centroids relative to each voxel's corner keep the sums small (precision far from the origin).
    corner = voxel_corners(table)
    q = ordered.points - np.repeat(corner, counts, axis=0)
    centroid = np.add.reduceat(q, at, axis=0) / counts[:, None] + corner
    cam = ordered.camera
    lo, hi = np.minimum.reduceat(cam, at), np.maximum.reduceat(cam, at)
    camera = np.where(lo == hi, lo, -1).astype(np.int16)
    return Cloud(centroid, cloud.frame, camera, cloud.cameras)
