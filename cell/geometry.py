"""Rigid transforms and small geometry helpers, numpy only.

Conventions (docs/architecture.md): ``X_AB`` is the 4x4 homogeneous pose of frame B in frame A, so
``X_AC = X_AB @ X_BC``; ``p_AS`` are points S expressed in A, shape (n, 3) [m]. Angles are radians inside the package.
Roll-pitch-yaw is the fixed-axis X-Y-Z convention: ``R = Rz(yaw) @ Ry(pitch) @ Rx(roll)``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]


def readonly(a: npt.ArrayLike, dtype: type = np.float64) -> npt.NDArray:
    """A read-only copy of ``a`` (values in frozen dataclasses must not be mutated in place)."""
    out: npt.NDArray[Any] = np.array(a, dtype=dtype, copy=True)
    out.setflags(write=False)
    return out


def rot_x(a: float) -> FloatArray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(a: float) -> FloatArray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(a: float) -> FloatArray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rpy_to_matrix(rpy: npt.ArrayLike) -> FloatArray:
    """Rotation from fixed-axis roll, pitch, yaw [rad]."""
    roll, pitch, yaw = (float(v) for v in np.asarray(rpy, dtype=float).reshape(3))
    return rot_z(yaw) @ rot_y(pitch) @ rot_x(roll)


def matrix_to_rpy(R: FloatArray) -> FloatArray:
    """Inverse of :func:`rpy_to_matrix`, (3,) [rad]; pitch in [-pi/2, pi/2]."""
    pitch = float(np.arcsin(np.clip(-R[2, 0], -1.0, 1.0)))
    if abs(np.cos(pitch)) > 1e-9:
        roll = float(np.arctan2(R[2, 1], R[2, 2]))
        yaw = float(np.arctan2(R[1, 0], R[0, 0]))
    else:  # gimbal lock: put everything into yaw
        roll = 0.0
        yaw = float(np.arctan2(-R[0, 1], R[1, 1]))
    return np.array([roll, pitch, yaw])


def make_pose(R: npt.ArrayLike | None = None, p: npt.ArrayLike | None = None) -> FloatArray:
    """4x4 pose from rotation (3, 3) and translation (3,) [m]."""
    X = np.eye(4)
    if R is not None:
        X[:3, :3] = np.asarray(R, dtype=float)
    if p is not None:
        X[:3, 3] = np.asarray(p, dtype=float)
    return X


def pose_from_xyz_rpy(xyz: npt.ArrayLike, rpy: npt.ArrayLike) -> FloatArray:
    """4x4 pose from a translation [m] and fixed-axis roll, pitch, yaw [rad]."""
    return make_pose(rpy_to_matrix(rpy), xyz)


def invert(X_AB: FloatArray) -> FloatArray:
    """X_BA from X_AB."""
    R = X_AB[:3, :3]
    X_BA = np.eye(4)
    X_BA[:3, :3] = R.T
    X_BA[:3, 3] = -R.T @ X_AB[:3, 3]
    return X_BA


def transform_points(X_AB: FloatArray, p_BS: npt.ArrayLike) -> FloatArray:
    """p_AS = X_AB * p_BS for points (n, 3) or a single point (3,)."""
    p = np.asarray(p_BS, dtype=float)
    return p @ X_AB[:3, :3].T + X_AB[:3, 3]


def rotate_vectors(X_AB: FloatArray, v_B: npt.ArrayLike) -> FloatArray:
    """Directions (n, 3) or (3,) from B to A (rotation only)."""
    return np.asarray(v_B, dtype=float) @ X_AB[:3, :3].T


def look_at(eye: Sequence[float], target: Sequence[float], up: Sequence[float] = (0.0, 0.0, 1.0)) -> FloatArray:
    """Pose X_WC of a camera optical frame (z forward, x right, y down) at ``eye`` looking at ``target``."""
    e = np.asarray(eye, dtype=float)
    z = np.asarray(target, dtype=float) - e
    n = np.linalg.norm(z)
    if n < 1e-9:
        raise ValueError("look_at: eye and target coincide")
    z /= n
    u = np.asarray(up, dtype=float)
    x = np.cross(z, u)
    if np.linalg.norm(x) < 1e-9:  # looking along up: pick any perpendicular
        x = np.cross(z, [1.0, 0.0, 0.0] if abs(z[0]) < 0.9 else [0.0, 1.0, 0.0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    return make_pose(np.column_stack([x, y, z]), e)


def cross3(a: FloatArray, b: FloatArray) -> FloatArray:
    """The cross product of two 3-vectors (3,), the same floating-point operations as ``np.cross`` without its
    array set-up (ten times faster on one pair: a hot loop's)."""
    a0, a1, a2 = float(a[0]), float(a[1]), float(a[2])
    b0, b1, b2 = float(b[0]), float(b[1]), float(b[2])
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def axis_angle_to_matrix(axis: npt.ArrayLike, angle: float) -> FloatArray:
    """Rodrigues' formula; ``axis`` need not be unit length (a zero axis gives identity)."""
    a = np.asarray(axis, dtype=float)
    n = np.linalg.norm(a)
    if n < 1e-15 or angle == 0.0:
        return np.eye(3)
    k = a / n
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * (K @ K)


def point_line_distance(p: npt.ArrayLike, a: npt.ArrayLike, b: npt.ArrayLike) -> FloatArray:
    """Distance of points p (n, 3) or (3,) from the infinite line through a and b [m]."""
    p = np.asarray(p, dtype=float)
    a = np.asarray(a, dtype=float)
    d = np.asarray(b, dtype=float) - a
    d = d / np.linalg.norm(d)
    v = p - a
    return np.linalg.norm(v - np.outer(v @ d, d).reshape(v.shape), axis=-1)
