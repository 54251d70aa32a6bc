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


def _cube_keys(
    ijk: tuple[npt.NDArray[np.int64], ...], lo: npt.NDArray[np.int64], hi: npt.NDArray[np.int64]
) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
    """(n,) one int64 per point naming its cube (integer cube coordinates ``ijk``: three (n,) columns, between
    ``lo`` and ``hi`` (3,)), and the grid's dims (3,); the grid has one empty layer of cubes around the points,
    so a neighbour key (+-1 along each axis) never wraps."""
    dims = hi - lo + 3
    return ((ijk[0] - (lo[0] - 1)) * dims[1] + (ijk[1] - (lo[1] - 1))) * dims[2] + (ijk[2] - (lo[2] - 1)), dims


def _block_shifts(dims: npt.NDArray[np.int64]) -> npt.NDArray[np.int64]:
    """(27,) key offsets of a cube's 3 x 3 x 3 block (itself included) in a grid of ``dims``."""
    o = np.arange(-1, 2)
    di, dj, dk = np.meshgrid(o, o, o, indexing="ij")
    return np.asarray(((di * dims[1] + dj) * dims[2] + dk).reshape(-1))


def radius_outlier_mask(points: FloatArray, radius_m: float, min_neighbours: int) -> npt.NDArray[np.bool_]:
    """(n,) True for points (n, 3) with at least ``min_neighbours`` other points within ``radius_m``.

    Same answer as open3d's radius outlier removal, but only the points that are not plainly inliers are
    searched, in three tests of growing cost, each exact:

    1. cubes of edge radius / sqrt 3 (their diagonal is the radius): a point whose own cube holds enough points
       is kept (95 % of a scene's points, one sort); every grid here is one floor of the points, halved;
    2. for the others, cubes of edge radius / (2 sqrt 3): every point of the 3 x 3 x 3 cubes around a point's own
       cube lies within the radius of it, so a point with enough points in that block is kept (looked up for
       the doubtful cubes only);
    3. the rest (sparse surfaces, strays: 2-3 %) ask a KD-tree of the points near them for their
       ``min_neighbours`` nearest others within the radius.
    """
    n = len(points)
    if n == 0:
        return np.zeros(0, dtype=bool)
    shrink = 1.0 - 1e-9  # cubes a hair smaller than the bound: rounding never puts two points a radius apart
    # One floor for all three grids: the finest cubes (edge radius / (2 sqrt 3)), and by halving their integer
    # coordinates cubes of twice and four times that edge (the first test's, and cubes wider than the radius).
    scaled = np.floor(points.T * (2.0 * math.sqrt(3.0) / (radius_m * shrink)))
    fine_ijk = tuple(np.asarray(column, dtype=np.int64) for column in scaled)
    lo, hi = np.array([c.min() for c in fine_ijk]), np.array([c.max() for c in fine_ijk])

    def grid(halvings: int) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
        return _cube_keys(tuple(c >> halvings for c in fine_ijk), lo >> halvings, hi >> halvings)

    keys, _ = grid(1)
    _, inverse, counts = np.unique(keys, return_inverse=True, return_counts=True)
    keep = counts[inverse.reshape(-1)] - 1 >= min_neighbours
    doubtful = np.flatnonzero(~keep)
    if len(doubtful):
        fine, dims = grid(0)
        cells, cell_counts = np.unique(fine, return_counts=True)
        asked, asked_at = np.unique(fine[doubtful], return_inverse=True)
        block = np.zeros(len(asked), dtype=np.int64)
        for shift in _block_shifts(dims):
            at = np.minimum(np.searchsorted(cells, asked + shift), len(cells) - 1)
            block += np.where(cells[at] == asked + shift, cell_counts[at], 0)
        sure = block[asked_at.reshape(-1)] - 1 >= min_neighbours
        keep[doubtful[sure]] = True
        doubtful = doubtful[~sure]
    if len(doubtful):
        # Only points within one cube (edge 2 radius / sqrt 3, wider than the radius) of a doubtful point's cube
        # can be its neighbours.
        coarse, cdims = grid(2)
        near = np.unique(coarse[doubtful])
        wanted = np.unique((near[:, None] + _block_shifts(cdims)[None, :]).reshape(-1))
        candidates = points[np.isin(coarse, wanted)]
        tree = cKDTree(candidates, balanced_tree=False, compact_nodes=False)
        # Each query point finds itself: the (min_neighbours + 1)-th nearest within the radius (bound included).
        dist, _ = tree.query(
            points[doubtful], k=min_neighbours + 1, distance_upper_bound=np.nextafter(radius_m, np.inf), workers=-1
        )
        keep[doubtful] = np.isfinite(np.reshape(dist, (len(doubtful), -1))[:, -1])
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
