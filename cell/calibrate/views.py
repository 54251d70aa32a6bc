"""What one calibration image gives: the flange's pose the robot reported, the board's corners found and the depth
image's values at them; and which way the board and the camera are mounted (the chain a solver closes)."""

from __future__ import annotations

import enum
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cell.calibrate import _opencv
from cell.calibrate.board import Corners
from cell.geometry import FloatArray, invert, readonly


class Mount(enum.StrEnum):
    """Which calibration: a fixed camera seeing the board on the flange, or the arm's camera the board on the table."""

    EYE_TO_HAND = "eye_to_hand"  # unknowns X_RC (camera in the robot base) and X_FB (board on the flange)
    EYE_IN_HAND = "eye_in_hand"  # unknowns X_FC (camera on the flange) and X_RB (board on the table)


@dataclass(frozen=True)
class View:
    """One image of the board: X_RF (4, 4) the flange pose the robot reported, the corners found, depth_m (k,) the
    depth image at each corner [m] (nan where invalid)."""

    X_RF: FloatArray
    corners: Corners
    depth_m: FloatArray

    def __post_init__(self) -> None:
        object.__setattr__(self, "X_RF", readonly(self.X_RF))
        object.__setattr__(self, "depth_m", readonly(self.depth_m))
        if self.depth_m.shape != (len(self.corners),):
            raise ValueError(f"depth_m has {self.depth_m.shape}, corners {len(self.corners)}")


def chain_T(view: View, mount: Mount) -> FloatArray:
    """The known pose between the two unknowns: X_RF for a fixed camera (p_C = X_CR X_RF X_FB p_B), X_FR for the
    arm's (p_C = X_CF X_FR X_RB p_B)."""
    return view.X_RF if mount == Mount.EYE_TO_HAND else invert(view.X_RF)


def stack_T(views: list[View] | tuple[View, ...], mount: Mount) -> npt.NDArray[np.float64]:
    """(n, 4, 4) :func:`chain_T` of every view."""
    return np.array([chain_T(v, mount) for v in views], dtype=float)


def undistorted(views: Sequence[View], K: FloatArray, D: tuple[float, ...]) -> list[View]:
    """The views with their corners moved to where a pinhole of K puts them, through the lens D (k1, k2, p1, p2,
    k3); the views as they are for a pinhole (D all zero). Their depths stay those read at the pixels found."""
    if not any(d != 0.0 for d in D):
        return list(views)
    return [View(v.X_RF, Corners(v.corners.ids, _opencv.undistort_px(v.corners.px, K, D)), v.depth_m) for v in views]
