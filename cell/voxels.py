"""A cloud grouped by voxel: the points in voxel order and a table of where each voxel's points start. One sort serves
every consumer (the voxel-grid filter's centroids, a locator's tube from a few contiguous runs); the grid is
anchored at the origin of the cloud's frame."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.types import Cloud
from cell.types.sensing import VoxelTable


def voxel_order(cloud: Cloud, voxel_m: float) -> tuple[Cloud, VoxelTable]:
    """``cloud`` with its points sorted by voxel of edge ``voxel_m`` [m] (x, then y, then z; deterministic
    order within a voxel), and the table of its voxels. Raises ValueError for a non-positive voxel."""
    if voxel_m <= 0:
        raise ValueError(f"voxel_order: voxel_m must be positive, got {voxel_m}")
    p = np.asarray(cloud.points)
    if len(p) == 0:
        empty = np.zeros(0, np.int64)
        return cloud, VoxelTable(voxel_m, (0, 0, 0), (1, 1, 1), empty, np.zeros(1, np.int64), np.zeros(3), np.zeros(3))
    # Column by column: reductions along axis 0 of an (n, 3) array are several times slower.
    ijk = [np.floor(p[:, k] / voxel_m).astype(np.int64) for k in range(3)]
    lo_ijk = [int(c.min()) for c in ijk]
    dims = [int(c.max()) - o + 1 for c, o in zip(ijk, lo_ijk, strict=True)]
    keys = ((ijk[0] - lo_ijk[0]) * dims[1] + (ijk[1] - lo_ijk[1])) * dims[2] + (ijk[2] - lo_ijk[2])
    order = np.argsort(keys)  # quicksort: deterministic for the same keys, several times faster than stable
    keys = keys[order]
    starts = np.concatenate(([0], np.flatnonzero(np.diff(keys)) + 1, [len(keys)])).astype(np.int64)
    ordered = Cloud(np.take(p, order, axis=0), cloud.frame, cloud.camera[order], cloud.cameras)
    table = VoxelTable(
        voxel_m=float(voxel_m),
        origin=(lo_ijk[0], lo_ijk[1], lo_ijk[2]),
        dims=(dims[0], dims[1], dims[2]),
        keys=keys[starts[:-1]],
        starts=starts,
        lo=np.array([p[:, k].min() for k in range(3)]),
        hi=np.array([p[:, k].max() for k in range(3)]),
    )
    return ordered, table


def voxel_corners(table: VoxelTable) -> FloatArray:
    """(m, 3) the lowest corner of each occupied voxel [m]."""
    _, ny, nz = table.dims
    i, rest = np.divmod(table.keys, ny * nz)
    j, k = np.divmod(rest, nz)
    return (np.stack([i, j, k], axis=1) + np.asarray(table.origin)) * table.voxel_m


def in_box(table: VoxelTable, lo: FloatArray, hi: FloatArray) -> npt.NDArray[np.intp]:
    """Indices into the voxel-ordered cloud of ``table`` of every point that may lie in the axis-aligned box
    lo-hi (3,) [m]: the points of the occupied voxels the box touches, a superset of those inside it (a point
    inside lies in a voxel between those of the corners: the floor is monotone), in cloud order."""
    v = table.voxel_m
    first = [max(int(np.floor(lo[k] / v)), table.origin[k]) for k in range(3)]
    last = [min(int(np.floor(hi[k] / v)), table.origin[k] + table.dims[k] - 1) for k in range(3)]
    if any(a > b for a, b in zip(first, last, strict=True)):
        return np.zeros(0, np.intp)
    i, j, k = (np.arange(a, b + 1) - o for a, b, o in zip(first, last, table.origin, strict=True))
    _, ny, nz = table.dims
    wanted = ((i[:, None, None] * ny + j[None, :, None]) * nz + k[None, None, :]).reshape(-1)
    at = np.searchsorted(table.keys, wanted)
    hit = at < len(table.keys)
    hit[hit] = table.keys[at[hit]] == wanted[hit]
    at = at[hit]
    begin, end = table.starts[at], table.starts[at + 1]
    counts = end - begin
    # The runs begin..end concatenated: each run's offsets from its own start.
    offsets = np.arange(int(counts.sum())) - np.repeat(np.cumsum(counts) - counts, counts)
    return np.asarray(np.repeat(begin, counts) + offsets, np.intp)
