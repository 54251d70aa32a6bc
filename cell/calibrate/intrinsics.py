"""The camera's own model checked on the calibration's images: focal length, principal point and the lens'
distortion fitted to the board's corners (OpenCV), the depth scale against the board's PnP
(:func:`cell.calibrate.checks.depth_scale`), each with its uncertainty, and flagged when it disagrees with the
stated model beyond the scenario's tolerance."""

from __future__ import annotations

import enum
from collections.abc import Sequence
from dataclasses import dataclass, replace

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
    DISTORTION = "distortion"


@dataclass(frozen=True)
class IntrinsicsCheck:
    """The measured model against the stated: focal lengths and principal point [px] with their standard
    deviations, the depth scale (measured / true depth) with its, the RMS of the fit [px], what is flagged;
    the lens' distortion (k1, k2, p1, p2, k3) with its standard deviations, and how far [px] the measured lens
    puts the farthest corner found from where the stated one does (``distortion_shift_px``, with its sigma);
    ``lens`` the model the cell is told from now on: the measured one where the stated is flagged, else the
    stated."""

    fx: float
    fy: float
    cx: float
    cy: float
    sigma_px: tuple[float, float, float, float]
    depth_scale: float
    depth_scale_sigma: float
    rms_px: float
    flags: tuple[IntrinsicsFlag, ...]
    distortion: tuple[float, float, float, float, float] = (0.0, 0.0, 0.0, 0.0, 0.0)
    distortion_sigma: tuple[float, float, float, float, float] = (0.0, 0.0, 0.0, 0.0, 0.0)
    distortion_shift_px: float = 0.0
    distortion_shift_sigma_px: float = 0.0
    lens: tuple[float, float, float, float, float] = (0.0, 0.0, 0.0, 0.0, 0.0)

    @property
    def flagged_lens(self) -> bool:
        return IntrinsicsFlag.DISTORTION in self.flags


def check_intrinsics(
    views: Sequence[View], p_B: FloatArray, stated: CameraIntrinsics, scale: DepthScale, spec: CalibrationRunSpec
) -> IntrinsicsCheck:
    """Fit the pinhole to the views' corners and hold it, and the depth scale, against the stated model (flagged
    when the disagreement exceeds the tolerance by more than twice its standard deviation)."""
    K, D, std, rms = _opencv.calibrate_intrinsics(
        [p_B[v.corners.ids] for v in views],
        [v.corners.px for v in views],
        (stated.width, stated.height),
        stated.K,
        np.asarray(stated.distortion),
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
    shift, shift_sigma = _corner_shift(stated, D, std[4:9], np.concatenate([v.corners.px for v in views]))
    if shift - 2.0 * shift_sigma > spec.distortion_tolerance_px:
        flags.append(IntrinsicsFlag.DISTORTION)
    sig = (float(std[0]), float(std[1]), float(std[2]), float(std[3]))
    return IntrinsicsCheck(
        fx,
        fy,
        cx,
        cy,
        sig,
        scale.ratio,
        scale.sigma,
        rms,
        tuple(flags),
        _five(D),
        _five(std[4:9]),
        shift,
        shift_sigma,
        _five(D) if IntrinsicsFlag.DISTORTION in flags else stated.distortion,
    )


def _five(v: FloatArray) -> tuple[float, float, float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]), float(v[3]), float(v[4]))


def _corner_shift(stated: CameraIntrinsics, D: FloatArray, sigma: FloatArray, px: FloatArray) -> tuple[float, float]:
    """How far [px] the lens D puts the corner farthest from the image's centre among those found (px (n, 2), the
    part of the image the board covered: beyond it a fitted lens is an extrapolation) from where the stated lens
    does, and its standard deviation from the coefficients' (taken independent, a finite difference for each:
    k1 and k2 pull against each other, so this overstates it)."""
    x_n = (px[:, 0] - stated.cx) / stated.fx
    y_n = (px[:, 1] - stated.cy) / stated.fy
    far = int(np.argmax(x_n**2 + y_n**2))
    ideal = _opencv.undistort_px(px[far : far + 1], stated.K, stated.distortion)[0]
    xs, ys = np.array([(ideal[0] - stated.cx) / stated.fx]), np.array([(ideal[1] - stated.cy) / stated.fy])

    def at(d: FloatArray) -> FloatArray:
        u, v = replace(stated, distortion=_five(d)).distort(xs, ys)
        return np.array([u[0] * stated.fx, v[0] * stated.fy])

    base = at(np.asarray(stated.distortion, dtype=float))
    shift = float(np.linalg.norm(at(D) - base))
    var = 0.0
    for i in range(5):
        if sigma[i] > 0.0:
            d = np.array(D, dtype=float)
            d[i] += sigma[i]
            var += float(np.linalg.norm(at(d) - base) - shift) ** 2
    return shift, float(np.sqrt(var))
