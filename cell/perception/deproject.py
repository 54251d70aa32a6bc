"""Depth images to point clouds (paper section 3.2): pinhole back-projection, passthrough crop, robot frame.

Frames: ``C`` camera optical frame (z forward, x right, y down), ``W`` world, ``R`` robot base. A pixel (u, v)
is (column, row) of the depth array and the intrinsics' (cx, cy) follow that convention, so the optical-frame
point of a pixel with depth z is ((u - cx) z / fx, (v - cy) z / fy, z).
"""

from __future__ import annotations

from collections.abc import Mapping
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray, invert, transform_points
from cell.scenario import WorkspaceSpec
from cell.types import Cloud, DepthImage


def deproject(image: DepthImage) -> FloatArray:
    """Points p_WS (n, 3) [m] in the world of the valid pixels (finite depth > 0), in row-major pixel order.

    Uses the calibrated pose ``image.X_WC`` and the pinhole ``image.intrinsics``.
    """
    k = image.intrinsics
    depth = image.depth
    h, w = depth.shape
    valid = depth > 0
    valid &= np.isfinite(depth)
    z = depth[valid].astype(np.float64)
    # Normalised image coordinates of every column and row, gathered for the valid pixels only.
    a = (np.arange(w, dtype=np.float64) - k.cx) / k.fx
    b = (np.arange(h, dtype=np.float64) - k.cy) / k.fy
    x_n = np.broadcast_to(a[None, :], (h, w))[valid]
    y_n = np.broadcast_to(b[:, None], (h, w))[valid]
    R = image.X_WC[:3, :3]
    t = image.X_WC[:3, 3]
    p_W = np.empty((len(z), 3))
    for i in range(3):  # p_W = R (x_n z, y_n z, z) + t, one output column at a time (fewer temporaries)
        p_W[:, i] = z * (R[i, 0] * x_n + R[i, 1] * y_n + R[i, 2]) + t[i]
    return p_W


def crop(points: npt.ArrayLike, workspace: WorkspaceSpec) -> npt.NDArray[np.bool_]:
    """Passthrough filter (paper eq. 2): (n,) True for points (n, 3) inside the workspace box (bounds
    included).

    ``points`` must be in the frame the workspace is given in (the world W).
    """
    p = np.asarray(points, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"crop: points must be (n, 3), got {p.shape}")
    lo, hi = workspace.min_m, workspace.max_m
    mask = (p[:, 0] >= lo[0]) & (p[:, 0] <= hi[0])
    mask &= (p[:, 1] >= lo[1]) & (p[:, 1] <= hi[1])
    mask &= (p[:, 2] >= lo[2]) & (p[:, 2] <= hi[2])
    return mask


def clouds_in_robot_frame(
    images: Mapping[str, DepthImage], X_WR: FloatArray, workspace: WorkspaceSpec
) -> dict[str, Cloud]:
    """One cloud per camera in the robot frame R: deproject, crop in W, then p_R = inv(X_WR) p_W.

    Every cloud shares ``cameras = tuple(images)`` and tags its points with its own index in it, so clouds can
    be concatenated without losing where each point came from. A camera that sees nothing in the workspace
    gives an empty cloud (the caller decides whether that is a lost camera).
    """
    names = tuple(images)
    X_RW = invert(np.asarray(X_WR, dtype=np.float64))

    def cloud(index: int) -> Cloud:
        p_W = deproject(images[names[index]])
        p_R = transform_points(X_RW, p_W[crop(p_W, workspace)])
        return Cloud(p_R, "R", np.full(len(p_R), index, np.int16), names)

    # The cameras two at a time (numpy's arithmetic lets go of the interpreter lock); each cloud is its own.
    with ThreadPoolExecutor(max_workers=2) as pool:
        return dict(zip(names, pool.map(cloud, range(len(names))), strict=True))
