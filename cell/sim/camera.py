"""Pinhole camera <-> OpenGL matrices for PyBullet's renderer, numpy only: pixel centres at integer (u, v) in the
optical frame C (z forward, x right, y down), the renderer's half-pixel offset built into the projection so the
reported intrinsics are exact for the rendered image (docs/reference.md section 2)."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray, invert
from cell.types import CameraIntrinsics

# OpenGL eye frame G (x right, y up, looking along -z) in the optical frame C (x right, y down, z forward).
X_CG = np.diag([1.0, -1.0, -1.0, 1.0])


def intrinsics_for(
    width: int, height: int, hfov_rad: float, distortion: tuple[float, float, float, float, float] = (0.0,) * 5
) -> CameraIntrinsics:
    """Square-pixel intrinsics, principal point at the image centre, f = 0.5 * width / tan(hfov / 2) [px], with a
    lens' ``distortion`` (k1, k2, p1, p2, k3)."""
    f = 0.5 * width / math.tan(hfov_rad / 2.0)
    return CameraIntrinsics(width, height, f, f, (width - 1) / 2.0, (height - 1) / 2.0, distortion)


def gl_view_matrix(X_WC: FloatArray) -> list[float]:
    """OpenGL view matrix (world -> eye), 16 floats column-major, for an optical frame at X_WC (4, 4)."""
    V = invert(np.asarray(X_WC, dtype=float) @ X_CG)
    return [float(v) for v in V.flatten(order="F")]


def gl_projection_matrix(intrinsics: CameraIntrinsics, near_m: float, far_m: float) -> list[float]:
    """OpenGL projection matrix, 16 floats column-major, reproducing ``intrinsics`` in TinyRenderer.

    Window x of pixel column u is u, window y of row v is H - 1 - v (see the module docstring); window depth
    d in [0, 1] follows the standard perspective depth, so that :func:`linearise_depth` inverts it.
    """
    W, H = intrinsics.width, intrinsics.height
    n, f = near_m, far_m
    P = np.zeros((4, 4))
    P[0, 0] = 2.0 * intrinsics.fx / W
    P[0, 2] = 1.0 - 2.0 * intrinsics.cx / W
    P[1, 1] = 2.0 * intrinsics.fy / H
    P[1, 2] = 2.0 * (intrinsics.cy + 1.0) / H - 1.0
    P[2, 2] = -(f + n) / (f - n)
    P[2, 3] = -2.0 * f * n / (f - n)
    P[3, 2] = -1.0
    return [float(v) for v in P.flatten(order="F")]


def linearise_depth(buffer: npt.ArrayLike, near_m: float, far_m: float) -> FloatArray:
    """Metric depth along the optical axis [m] from a depth buffer in [0, 1] (docs/reference.md section 2):
    ``z = far * near / (far - (far - near) * d)``. Pixels where nothing was drawn (d = 1, at or beyond the far
    plane) become 0 (invalid)."""
    d = np.asarray(buffer, dtype=float)
    z = far_m * near_m / (far_m - (far_m - near_m) * d)
    return np.asarray(np.where(d >= 1.0, 0.0, z))
