"""Where the board or the camera goes for each calibration image, before any reach is tried: candidates drawn for
good conditioning (distances over a range, the board across the image, tilts about both of its axes and turns about
its normal, so no pose set is a translation or one rotation axis), each with the board whole in the image."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from cell.calibrate.board import Board
from cell.geometry import FloatArray, axis_angle_to_matrix, invert, look_at, make_pose, pose_from_xyz_rpy
from cell.types import CameraIntrinsics

_EDGE_PX = 25.0  # every corner at least this far inside the image


def in_view(board: Board, X_CB: FloatArray, intr: CameraIntrinsics) -> bool:
    """Whether every corner of the board at X_CB (4, 4) lies in front of the camera and inside the image, and its
    face looks towards the camera."""
    p = board.p_B @ X_CB[:3, :3].T + X_CB[:3, 3]
    if np.any(p[:, 2] <= 0.05):
        return False
    u = intr.fx * p[:, 0] / p[:, 2] + intr.cx
    v = intr.fy * p[:, 1] / p[:, 2] + intr.cy
    inside = (u > _EDGE_PX) & (u < intr.width - 1 - _EDGE_PX) & (v > _EDGE_PX) & (v < intr.height - 1 - _EDGE_PX)
    facing = float(-X_CB[:3, 2] @ (X_CB[:3, :3] @ board.centre_B + X_CB[:3, 3])) < 0.0  # face normal against the ray
    return bool(np.all(inside) and facing)


def board_poses(
    board: Board,
    intr: CameraIntrinsics,
    range_m: tuple[float, float],
    tilt_deg: float,
    rng: np.random.Generator,
    tries: int = 400,
) -> Iterator[FloatArray]:
    """Candidate X_CB (4, 4) of the board before a fixed camera: its centre at a drawn distance and place in the
    image, tilted about its two axes within ``tilt_deg`` and turned about its normal within 45 deg, whole in the
    image."""
    half_w = 0.35 * intr.width / intr.fx
    half_h = 0.35 * intr.height / intr.fy
    for _ in range(tries):
        d = rng.uniform(*range_m)
        centre = np.array([rng.uniform(-half_w, half_w) * d, rng.uniform(-half_h, half_h) * d, d])
        tilt = rng.uniform(-tilt_deg, tilt_deg, 2)
        turn = rng.uniform(-45.0, 45.0)
        X_CB = pose_from_xyz_rpy(centre, np.radians([tilt[0], tilt[1], turn])) @ make_pose(p=-board.centre_B)
        if in_view(board, X_CB, intr):
            yield X_CB


def camera_poses(
    board: Board,
    X_RB: FloatArray,
    intr: CameraIntrinsics,
    range_m: tuple[float, float],
    tilt_deg: float,
    rng: np.random.Generator,
    tries: int = 400,
    offset: tuple[float, float] = (0.0, 0.0),
) -> Iterator[FloatArray]:
    """Candidate X_RC (4, 4) of the arm's camera over the board lying at X_RB: a drawn distance, tilted off the
    board's normal within ``tilt_deg`` about a drawn azimuth, aimed near the board's centre, turned about its
    optical axis within 60 deg, the board whole in the image. ``offset``: the board's centre that fraction of the
    image's width to one side (drawn) and of its height above the middle (clear of a torch that hides the image's
    lower middle)."""
    centre_R = X_RB[:3, :3] @ board.centre_B + X_RB[:3, 3]
    normal_R = -X_RB[:3, 2]  # the printed face looks along -z_B
    a = np.cross(normal_R, [1.0, 0.0, 0.0] if abs(normal_R[0]) < 0.9 else [0.0, 1.0, 0.0])
    a /= np.linalg.norm(a)
    b = np.cross(normal_R, a)
    for _ in range(tries):
        d = rng.uniform(*range_m)
        tilt, azimuth = np.radians(rng.uniform(0.3 * tilt_deg, tilt_deg)), rng.uniform(0.0, 2.0 * np.pi)
        ray = np.cos(tilt) * normal_R + np.sin(tilt) * (np.cos(azimuth) * a + np.sin(azimuth) * b)
        aim = centre_R + rng.uniform(-0.03, 0.03) * a + rng.uniform(-0.03, 0.03) * b
        turn = rng.uniform(-np.pi / 3.0, np.pi / 3.0)
        up = np.cos(turn) * b + np.sin(turn) * a
        side = offset[0] * intr.width * (1.0 if rng.uniform() < 0.5 else -1.0)
        X_RC = look_at(_seq(aim + d * ray), _seq(aim), _seq(up)) @ make_pose(
            _turned_to(side / intr.fx, -offset[1] * intr.height / intr.fy)
        )
        if in_view(board, invert(X_RC) @ X_RB, intr):
            yield X_RC


def _turned_to(x: float, y: float) -> FloatArray:
    """R (3, 3) of a camera turned so that what lay on its optical axis appears at normalised image point (x, y)."""
    d = np.array([x, y, 1.0]) / np.hypot(np.hypot(x, y), 1.0)
    axis = np.cross(d, [0.0, 0.0, 1.0])
    n = float(np.linalg.norm(axis))
    return np.eye(3) if n < 1e-12 else axis_angle_to_matrix(axis / n, float(np.arccos(np.clip(d[2], -1.0, 1.0))))


def _seq(v: FloatArray) -> tuple[float, float, float]:
    return float(v[0]), float(v[1]), float(v[2])
