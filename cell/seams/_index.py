"""The dense cloud indexed for tube queries: in voxel order, in nested layers of a share of its points.

Everything is in the robot frame R, metres.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from cell.config.seams import INDEX_SHARES
from cell.geometry import FloatArray, make_pose
from cell.types import Box, Cloud, SeamScene, VoxelTable
from cell.voxels import voxel_order

_BOX_KEY = "cell.seams._index.cloud_box"
_INDEX_KEY = "cell.seams._index.dense_index"
INDEX_VOXEL_M = 0.01  # voxel of an index built here (perception hands on its own, ``PerceptionSpec.voxel_m``)

IntArray = npt.NDArray[np.intp]


@dataclass(frozen=True)
class CloudIndex:
    """The dense cloud in voxel order (:func:`cell.voxels.voxel_order`) for tube queries, in layers: a query
    asks for a share of the points, so that a locator needing thousands, not tens of thousands, of points per
    seam gathers only those. The layer of share 1/k is every k-th point of the ordered cloud: each voxel keeps
    its share of its points (a stratified thinning, spread like the dense cloud: a fit on it only sees fewer
    points) and the layers are nested. A query gathers a few runs of the ordered cloud: no search, no sort,
    no copy of the cloud.

    points : (n, 3) the cloud's coordinates in voxel order [m]; camera : (n,) camera index (-1: unknown);
    voxels : where each voxel's points lie.
    """

    points: FloatArray
    camera: npt.NDArray[np.integer[Any]]
    voxels: VoxelTable
    shares: tuple[float, ...] = INDEX_SHARES
    _density: dict[int, float] = field(default_factory=dict, compare=False, repr=False)

    def __post_init__(self) -> None:
        if any(abs(1.0 / s - round(1.0 / s)) > 1e-9 for s in self.shares) or max(self.shares, default=0.0) != 1.0:
            raise ValueError(f"index shares must be 1 / k for whole k and include 1, got {self.shares}")

    @property
    def density(self) -> float:
        """Points per square metre of a well-seen surface [1/m^2]: the 90th percentile of the points per voxel
        over a voxel's face (a surface crossing a voxel square holds one face's area of it; most voxels hold
        less: edges, corners, surfaces seen obliquely or by fewer cameras); computed on first use."""
        out = self._density.get(0)
        if out is None:
            counts = self.voxels.counts
            out = float(np.percentile(counts, 90.0)) / self.voxels.voxel_m**2 if len(counts) else 0.0
            self._density[0] = out
        return out

    def pitch(self, share: float) -> float:
        """Point pitch [m] of ``share`` of the points on a well-seen surface (``1 / sqrt(density)``)."""
        density = self.density
        return float(1.0 / np.sqrt(density * share)) if density > 0.0 else float("nan")

    def tube(
        self, p_start: FloatArray, p_end: FloatArray, radius: float, extend: float, share: float
    ) -> tuple[FloatArray, IntArray]:
        """The points (3, k) [m] and their cameras (k,) within ``radius`` [m] of the segment p_start-p_end (3,)
        [m] extended by ``extend`` [m] at both ends (a capsule-free cylinder), from the layer of ``share`` (one
        of :attr:`shares`), in a fixed order.

        The candidates come from the voxels inside the tube's bounding box: one run of the ordered cloud per
        (x, y) column of voxels, so the cost does not grow with the size of the cloud.
        """
        if share not in self.shares:
            raise ValueError(f"share {share} is not one of the index's layers {self.shares}")
        vox = self.voxels
        a0, b0 = [float(v) for v in p_start], [float(v) for v in p_end]
        axis = [b0[k] - a0[k] for k in range(3)]
        length = math.sqrt(sum(v * v for v in axis))
        t = [v / length for v in axis]
        a = [a0[k] - extend * t[k] for k in range(3)]
        span = length + 2.0 * extend
        b = [a[k] + span * t[k] for k in range(3)]
        # Bounding box of the cylinder: per axis, the ends' range grown by radius * sqrt(1 - t_k^2).
        lo, hi = [], []
        for k in range(3):
            grow = radius * math.sqrt(max(1.0 - t[k] * t[k], 0.0))
            lo.append(max(math.floor((min(a[k], b[k]) - grow) / vox.voxel_m) - vox.origin[k], 0))
            hi.append(min(math.floor((max(a[k], b[k]) + grow) / vox.voxel_m) - vox.origin[k], vox.dims[k] - 1))
        empty = np.zeros((3, 0)), np.zeros(0, np.intp)
        if any(h < lo_ for lo_, h in zip(lo, hi, strict=True)):
            return empty
        cols = np.add.outer(np.arange(lo[0], hi[0] + 1) * vox.dims[1], np.arange(lo[1], hi[1] + 1)).ravel()
        cols *= vox.dims[2]
        k = round(1.0 / share)  # the layer: every k-th point of the ordered cloud
        starts = (vox.starts + (k - 1)) // k if k > 1 else vox.starts  # the first multiple of k from each start
        first = starts[np.searchsorted(vox.keys, cols + lo[2], side="left")]
        last = starts[np.searchsorted(vox.keys, cols + hi[2], side="right")]
        counts = last - first
        nz = counts > 0
        first, last, counts = first[nz], last[nz], counts[nz]
        total = int(counts.sum())
        if total == 0:
            return empty
        # Concatenate the runs [first, last) without a Python loop: a run of ones, jumping at each run.
        steps = np.ones(total, np.intp)
        steps[0] = first[0]
        steps[np.cumsum(counts[:-1])] = first[1:] - last[:-1] + 1
        idx = np.cumsum(steps) * k
        xyz = np.ascontiguousarray(np.take(self.points, idx, axis=0).T)  # (3, m): column reductions are faster
        x, y, z = xyz[0] - a[0], xyz[1] - a[1], xyz[2] - a[2]
        s = x * t[0] + y * t[1] + z * t[2]
        d2 = x * x + y * y + z * z - s * s
        keep = np.flatnonzero((s >= 0.0) & (s <= span) & (d2 <= radius * radius))
        return np.take(xyz, keep, axis=1), np.asarray(self.camera[idx[keep]], np.intp)


def index_of(cloud: Cloud, voxels: VoxelTable | None = None, voxel_m: float = INDEX_VOXEL_M) -> CloudIndex:
    """:class:`CloudIndex` of ``cloud``: in voxel order with its table ``voxels`` when given, else ordered
    here on a grid of ``voxel_m`` [m]."""
    if voxels is None:
        cloud, voxels = voxel_order(cloud, voxel_m)
    return CloudIndex(np.asarray(cloud.points), cloud.camera, voxels)


def dense_index(scene: SeamScene) -> CloudIndex:
    """:func:`index_of` ``scene.dense`` (with ``scene.dense_voxels`` when perception ordered it), built once per
    scene and kept in ``scene.cache``."""
    index = scene.cache.get(_INDEX_KEY)
    if index is None:
        index = scene.cache[_INDEX_KEY] = index_of(scene.dense, scene.dense_voxels)
    return index


def cloud_box(scene: SeamScene) -> Box:
    """The bounds of ``scene.dense`` along the axes of R (a box in R), cached per scene: where a passthrough
    crop of the workspace cut the cloud, when the workspace is axis-aligned in R."""
    box = scene.cache.get(_BOX_KEY)
    if box is None:
        vox = dense_index(scene).voxels
        lo, hi = (vox.lo, vox.hi) if len(vox) else (np.zeros(3), np.ones(3))
        box = Box(make_pose(p=0.5 * (lo + hi)), np.maximum(hi - lo, 1e-9))
        scene.cache[_BOX_KEY] = box
    return box
