"""The camera's own model checked on the calibration's images: focal length and principal point fitted to the
board's corners (OpenCV), the depth scale against the board's PnP (:func:`cell.calibrate.checks.depth_scale`), each
with its uncertainty, and flagged when it disagrees with the stated model beyond the scenario's tolerance."""

from __future__ import annotations

import enum
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from cell.calibrate import _opencv
from cell.calibrate.checks import DepthScale
from cell.calibrate.views import View
from cell.geometry import FloatArray
from cell.scenario.calibration_specs import CalibrationRunSpec
from cell.types import CameraIntrinsics


class IntrinsicsFlag(enum.StrEnum):
    """What of a camera's stated model its images disagree with."""

    FOCAL = "focal"
    PRINCIPAL_POINT = "principal_point"
    DEPTH_SCALE = "depth_scale"


@dataclass(frozen=True)
class IntrinsicsCheck:
    """The measured model against the stated: focal lengths and principal point [px] with their standard
    deviations, the depth scale (measured / true depth) with its, the RMS of the fit [px], what is flagged."""

    fx: float
    fy: float
    cx: float
    cy: float
    sigma_px: tuple[float, float, float, float]
    depth_scale: float
    depth_scale_sigma: float
    rms_px: float
    flags: tuple[IntrinsicsFlag, ...]


def check_intrinsics(
    views: Sequence[View], p_B: FloatArray, stated: CameraIntrinsics, scale: DepthScale, spec: CalibrationRunSpec
) -> IntrinsicsCheck:
    """Fit the pinhole to the views' corners and hold it, and the depth scale, against the stated model (flagged
    when the disagreement exceeds the tolerance by more than twice its standard deviation)."""
    K, std, rms = _opencv.calibrate_intrinsics(
        [p_B[v.corners.ids] for v in views], [v.corners.px for v in views], (stated.width, stated.height), stated.K
    )
    fx, fy, cx, cy = float(K[0, 0]), float(K[1, 1]), float(K[0, 2]), float(K[1, 2])
    # Flagged when the disagreement is beyond the tolerance by more than twice its own uncertainty: a figure this
    # set of images cannot pin down is reported, never flagged on its noise.
    flags: list[IntrinsicsFlag] = []
    focal = max(abs(fx - stated.fx) - 2.0 * std[0], abs(fy - stated.fy) - 2.0 * std[1])
    if focal > spec.focal_tolerance * stated.fx:
        flags.append(IntrinsicsFlag.FOCAL)
    if max(abs(cx - stated.cx) - 2.0 * std[2], abs(cy - stated.cy) - 2.0 * std[3]) > spec.principal_tolerance_px:
        flags.append(IntrinsicsFlag.PRINCIPAL_POINT)
    sigma = scale.sigma if np.isfinite(scale.sigma) else 0.0
    if np.isfinite(scale.ratio) and abs(scale.ratio - 1.0) - 2.0 * sigma > spec.depth_scale_tolerance:
        flags.append(IntrinsicsFlag.DEPTH_SCALE)
    sig = (float(std[0]), float(std[1]), float(std[2]), float(std[3]))
    return IntrinsicsCheck(fx, fy, cx, cy, sig, scale.ratio, scale.sigma, rms, tuple(flags))
