"""What refuses a calibration before or after it is solved: a pose set without rotation diversity (the hand-eye
equations are then singular), and a board whose stated size the depth image disagrees with; and the depth scale
those same images measure."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from cell.calibrate.solve import pnp_poses
from cell.calibrate.views import Mount, View, chain_T
from cell.errors import CalibrationError, CalibrationFault
from cell.geometry import FloatArray

MIN_SPREAD_DEG = 5.0  # the second axis of the pose set's relative rotations must turn at least this much (RMS)


def rotation_spread_deg(views: Sequence[View], mount: Mount) -> tuple[float, float]:
    """(first, second) singular values [deg, RMS per pair] of the relative rotations between every pair of views'
    robot poses: (0, 0) for a pure translation, (x, 0) for rotations about one axis."""
    T = [chain_T(v, mount) for v in views]
    w = [
        Rotation.from_matrix(T[i][:3, :3].T @ T[j][:3, :3]).as_rotvec()
        for i in range(len(T))
        for j in range(i + 1, len(T))
    ]
    if not w:
        return 0.0, 0.0
    s = np.linalg.svd(np.array(w), compute_uv=False) / np.sqrt(len(w))
    return float(np.degrees(s[0])), float(np.degrees(s[1]))


def check_diversity(views: Sequence[View], mount: Mount, camera: str, min_spread_deg: float = MIN_SPREAD_DEG) -> None:
    """CalibrationError (degenerate) when the poses turn about fewer than two axes by ``min_spread_deg``."""
    first, second = rotation_spread_deg(views, mount)
    if second < min_spread_deg:
        kind = "a pure translation" if first < min_spread_deg else "rotations about one axis only"
        raise CalibrationError(
            f"cameras.{camera}: the {len(views)} poses are {kind} (relative rotations {first:.1f} and {second:.1f} "
            f"deg RMS on their two main axes; at least {min_spread_deg:.0f} deg on two are needed): the camera's "
            "pose and the board's are not separable",
            code=CalibrationFault.DEGENERATE,
            camera=camera,
            value=second,
            needed=min_spread_deg,
        )


@dataclass(frozen=True)
class DepthScale:
    """The depth image against the board's PnP: ``ratio`` (measured depth / PnP depth, 1 when both agree), its
    standard deviation over the views, and how many views and corners it stands on."""

    ratio: float
    sigma: float
    views: int
    corners: int


def depth_scale(views: Sequence[View], p_B: FloatArray, K: FloatArray) -> DepthScale:
    """The depth image's scale against the board's PnP pose in each view (one ratio per view: the median of its
    corners'), their mean and its standard error."""
    ratios, n = [], 0
    for v, X_CB in zip(views, pnp_poses(views, p_B, K), strict=True):
        z = (p_B[v.corners.ids] @ X_CB[:3, :3].T + X_CB[:3, 3])[:, 2]
        ok = np.isfinite(v.depth_m) & (v.depth_m > 0.0)
        if np.count_nonzero(ok) >= 4:
            ratios.append(float(np.median(v.depth_m[ok] / z[ok])))
            n += int(np.count_nonzero(ok))
    if not ratios:
        return DepthScale(float("nan"), float("nan"), 0, 0)
    r = np.array(ratios)
    sigma = float(np.std(r, ddof=1) / np.sqrt(len(r))) if len(r) > 1 else float("nan")
    return DepthScale(float(np.mean(r)), sigma, len(r), n)


def check_board_size(scale: DepthScale, camera: str, tolerance: float) -> None:
    """CalibrationError (board_size) when the depth image says the board is not the size the scenario states."""
    if np.isfinite(scale.ratio) and abs(scale.ratio - 1.0) > tolerance:
        raise CalibrationError(
            f"cameras.{camera}: the depth image puts the board {100.0 * (scale.ratio - 1.0):+.1f} % farther than its "
            f"stated size does (over {scale.views} images; at most {100.0 * tolerance:.1f} %): the board's square "
            "size (calibration.board.square_mm) or the camera's depth scale is wrong",
            code=CalibrationFault.BOARD_SIZE,
            camera=camera,
            value=scale.ratio,
            needed=1.0,
        )
