"""What sensors deliver: pinhole intrinsics, depth images and point clouds.

Frames: ``C`` camera optical frame (z forward, x right, y down), ``W`` world, ``R`` robot base. Metres.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray, readonly, transform_points


@dataclass(frozen=True)
class CameraIntrinsics:
    """Pinhole intrinsics [px] of a depth image, optical frame z forward, x right, y down; ``distortion`` the lens'
    Brown-Conrady model (k1, k2, p1, p2, k3), OpenCV's order and meaning (all zero: a pinhole image)."""

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float
    distortion: tuple[float, float, float, float, float] = (0.0, 0.0, 0.0, 0.0, 0.0)

    @property
    def K(self) -> FloatArray:
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    @property
    def distorted(self) -> bool:
        return any(d != 0.0 for d in self.distortion)

    def distort(self, x_n: npt.ArrayLike, y_n: npt.ArrayLike) -> tuple[FloatArray, FloatArray]:
        """The lens model: ideal normalised image coordinates (x, y) to where the lens puts them (same shapes)."""
        x, y = np.asarray(x_n, dtype=float), np.asarray(y_n, dtype=float)
        k1, k2, p1, p2, k3 = self.distortion
        r2 = x * x + y * y
        radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
        return (
            x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
            y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y,
        )


@dataclass(frozen=True)
class DepthImage:
    """One depth capture.

    depth : (height, width) float32 metric depth along the optical axis [m]; 0 marks an invalid pixel.
    X_WC : (4, 4) pose of the optical frame in the world *as calibrated* (what perception may use; in simulation
        it can differ from the true pose by the scenario's extrinsic error).
    mount : ``"fixed"`` or ``"eye_in_hand"``.
    """

    camera: str
    depth: npt.NDArray[np.float32]
    intrinsics: CameraIntrinsics
    X_WC: FloatArray
    mount: str = "fixed"

    def __post_init__(self) -> None:
        object.__setattr__(self, "depth", readonly(self.depth, np.float32))
        object.__setattr__(self, "X_WC", readonly(self.X_WC))
        if self.depth.shape != (self.intrinsics.height, self.intrinsics.width):
            raise ValueError(
                f"depth image of camera {self.camera!r} is {self.depth.shape}, intrinsics say "
                f"{(self.intrinsics.height, self.intrinsics.width)}"
            )


@dataclass(frozen=True)
class Cloud:
    """A point cloud in ``frame``.

    points : (n, 3) [m].
    camera : (n,) int16 index of the capture each point came from (-1 when unknown or mixed).
    cameras : names of the captures, indexed by ``camera``.
    """

    points: FloatArray
    frame: str
    camera: npt.NDArray[np.int16] = field(default_factory=lambda: np.zeros(0, np.int16))
    cameras: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        pts = readonly(self.points)
        if pts.ndim != 2 or pts.shape[1] != 3:
            raise ValueError(f"Cloud points must be (n, 3), got {pts.shape}")
        cam = np.asarray(self.camera, dtype=np.int16)
        if cam.size == 0:
            cam = np.full(len(pts), -1, np.int16)
        if cam.shape != (len(pts),):
            raise ValueError(f"Cloud camera indices must be ({len(pts)},), got {cam.shape}")
        object.__setattr__(self, "points", pts)
        object.__setattr__(self, "camera", readonly(cam, np.int16))

    def __len__(self) -> int:
        return len(self.points)

    def select(self, mask: npt.NDArray[np.bool_] | npt.NDArray[np.intp]) -> Cloud:
        return Cloud(self.points[mask], self.frame, self.camera[mask], self.cameras)

    def transformed(self, X_AF: FloatArray, frame: str) -> Cloud:
        return Cloud(transform_points(X_AF, self.points), frame, self.camera, self.cameras)


IntArray = npt.NDArray[np.int64]


@dataclass(frozen=True)
class VoxelTable:
    """Where the voxels of a cloud in voxel order (:func:`voxel_order`) lie.

    voxel_m : edge of a voxel [m].
    origin : (3,) integer coordinates of the grid's corner voxel: voxel (i, j, k) of the frame's grid
        (``floor(p / voxel_m)``) has the key ``((i - o0) * dims[1] + (j - o1)) * dims[2] + (k - o2)``.
    dims : (3,) voxels along x, y, z.
    keys : (m,) keys of the occupied voxels, increasing.
    starts : (m + 1,) voxel v holds the points ``starts[v]:starts[v + 1]`` of the ordered cloud.
    lo, hi : (3,) bounds of the points [m].
    """

    voxel_m: float
    origin: tuple[int, int, int]
    dims: tuple[int, int, int]
    keys: IntArray
    starts: IntArray
    lo: FloatArray
    hi: FloatArray

    def __len__(self) -> int:
        return len(self.keys)

    @property
    def counts(self) -> IntArray:
        """(m,) points in each voxel."""
        return np.diff(self.starts)
