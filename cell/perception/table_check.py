"""A camera's depth scale and focal length checked in every run from its own depth image, with no board in view:
the table's top is a plane at a known height, so each pixel that sees it has a depth the camera's told pose and
intrinsics predict. The log of measured over predicted depth is ln(s) + e k over those pixels, s the depth scale
and e the focal length's relative error (k: how the predicted depth moves when the rays are narrowed by 1 + e,
which needs the table seen at a slant; seen square on, e is not known and never flagged). Each figure carries its
noise and what the pose's own uncertainty (its calibration residual) could make of it: a camera off its told pose
looks like a depth scale off, and is flagged as that (the reason says both). Frames: W; metres."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray, axis_angle_to_matrix, make_pose
from cell.perception.splicing.pose_prior import PoseUncertainty
from cell.scenario import Scenario
from cell.types import DepthImage, WeldMap

_BAND_M = 0.06  # a pixel sees the table if its point lies this near the top's plane (wide: no selection bias) ...
_INSET_M = 0.03  # ... this far inside its edges, and outside the bodies on it (their drawn bounds, grown)
_MIN_PIXELS = 2000  # fewer table pixels: no check
_MAX_SAMPLES = 20000  # the fit runs on at most this many of them (an even stride)
_BLOCK_PX = 8  # neighbouring pixels' errors are not independent: the fit's noise counts blocks of this size
_FOCAL_STEP = 1e-4
_BODY_PLAY_M = 0.08  # the part may lie this far off its drawn place (and the camera see its sides beyond it)


@dataclass(frozen=True)
class SensorCheck:
    """One camera's check on the table: the depth scale s (measured over true depth) and the focal scale 1 + e
    (true over told focal length), each with its standard deviation (noise and the told pose's uncertainty), how
    many table pixels it rests on, and what is flagged (``depth_scale``, ``focal``) beyond the tolerances."""

    camera: str
    pixels: int
    depth_scale: float
    depth_scale_sigma: float
    focal_scale: float
    focal_scale_sigma: float
    flags: tuple[str, ...]

    def describe(self) -> str:
        return (
            f"depth scale {self.depth_scale:.4f} +- {self.depth_scale_sigma:.4f}, focal scale {self.focal_scale:.4f}"
            f" +- {self.focal_scale_sigma:.4f} on {self.pixels} table pixels"
        )

    def reason(self) -> str:
        """Why the camera's data cannot be trusted ('' when nothing is flagged)."""
        if not self.flags:
            return ""
        what = []
        if "depth_scale" in self.flags:
            what.append(f"its depth reads {self.depth_scale:.4f} +- {self.depth_scale_sigma:.4f} of the table's")
        if "focal" in self.flags:
            what.append(f"its focal length is {self.focal_scale:.4f} +- {self.focal_scale_sigma:.4f} of the told one")
        return (
            "the table plane says " + " and ".join(what) + " (or its pose is that far off its calibration): "
            "recalibrate it (cell calibrate)"
        )


def check_cameras(
    images: Mapping[str, DepthImage], scenario: Scenario, drawn_W: WeldMap, priors: Mapping[str, PoseUncertainty]
) -> dict[str, SensorCheck]:
    """Every camera's check on the scenario's table (its parts and fixtures as drawn, in W, kept out), against the
    calibration's tolerances, each camera's told pose as uncertain as its prior says; cameras seeing too little of
    the table are left out."""
    t = scenario.table
    lo = (t.center_m[0] - t.size_m[0] / 2.0, t.center_m[1] - t.size_m[1] / 2.0)
    hi = (t.center_m[0] + t.size_m[0] / 2.0, t.center_m[1] + t.size_m[1] / 2.0)
    tol = (scenario.calibration.depth_scale_tolerance, scenario.calibration.focal_tolerance)
    corners = [b.vertices()[:, :2] for b in (*drawn_W.parts, *drawn_W.fixtures)]
    bodies = (
        np.array([c.min(axis=0) - _BODY_PLAY_M for c in corners]).reshape(-1, 2),
        np.array([c.max(axis=0) + _BODY_PLAY_M for c in corners]).reshape(-1, 2),
    )
    out = {}
    for name, image in images.items():
        s = priors.get(name) or PoseUncertainty()
        check = check_on_table(image, t.top_z, lo, hi, (s.translation_m, s.rotation_rad), tol, bodies)
        if check is not None:
            out[name] = check
    return out


def check_on_table(
    image: DepthImage,
    top_z: float,
    table_lo_xy: tuple[float, float],
    table_hi_xy: tuple[float, float],
    pose_sigma: tuple[float, float],
    tolerances: tuple[float, float],
    bodies: tuple[FloatArray, FloatArray] | None = None,
) -> SensorCheck | None:
    """The check of one (pinhole) depth image against the table top at height ``top_z`` [m] between its corners
    ``table_lo_xy`` and ``table_hi_xy`` in W; ``pose_sigma`` the told pose's RMS translation [m] and rotation
    [rad]; ``tolerances`` the depth scale's and the focal length's (relative); ``bodies`` the (b, 2) lower and upper
    xy corners [m] of what stands on the table (the parts and fixtures where drawn, grown by their placement's
    play): their pixels are not the table's. None when too few pixels see the table."""
    k = image.intrinsics
    rows, cols, depth = _table_pixels(image, top_z, table_lo_xy, table_hi_xy, bodies)
    if len(depth) < _MIN_PIXELS:
        return None
    x_n, y_n = (cols - k.cx) / k.fx, (rows - k.cy) / k.fy

    def fit(X_WC: FloatArray, keep: npt.NDArray[np.bool_] | None = None) -> tuple[FloatArray, FloatArray, FloatArray]:
        z0 = _plane_depth(X_WC, x_n, y_n, top_z)
        slope = (_plane_depth(X_WC, x_n / (1 + _FOCAL_STEP), y_n / (1 + _FOCAL_STEP), top_z) / z0 - 1) / _FOCAL_STEP
        y = np.log(depth / z0)
        A = np.column_stack([np.ones_like(y), slope])
        use = np.isfinite(y) & np.isfinite(slope) & (z0 > 0) if keep is None else keep
        coef = np.linalg.lstsq(A[use], y[use], rcond=None)[0]
        return coef, y - A @ coef, A

    coef, r, A = fit(image.X_WC)
    good = np.isfinite(r)
    for _ in range(2):  # what is not the table (a part's foot, a flying pixel): beyond 3.5 robust sigmas, out
        mad = 1.4826 * np.median(np.abs(r[good] - np.median(r[good])))
        good &= np.abs(r) < 3.5 * max(mad, 1e-6)
        coef, r, A = fit(image.X_WC, good)
    n_eff = max(len(np.unique((rows[good] // _BLOCK_PX) * 100000 + cols[good] // _BLOCK_PX)), 3)
    cov = np.linalg.inv(A[good].T @ A[good]) * float(np.mean(r[good] ** 2)) * len(r[good]) / n_eff
    var = np.diag(cov).copy()
    var += _pose_variance(lambda X: fit(X, good)[0], image.X_WC, coef, pose_sigma)
    s, e = math.exp(coef[0]), float(coef[1])
    s_sigma, e_sigma = s * math.sqrt(var[0]), math.sqrt(var[1])
    flags = []
    if abs(s - 1.0) - 2.0 * s_sigma > tolerances[0]:
        flags.append("depth_scale")
    if abs(e) - 2.0 * e_sigma > tolerances[1]:
        flags.append("focal")
    return SensorCheck(image.camera, int(good.sum()), s, s_sigma, 1.0 + e, e_sigma, tuple(flags))


def _table_pixels(
    image: DepthImage,
    top_z: float,
    lo_xy: tuple[float, float],
    hi_xy: tuple[float, float],
    bodies: tuple[FloatArray, FloatArray] | None,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Rows, columns and depths of the pixels whose point (told pose and intrinsics) lies on the table's top."""
    k, d = image.intrinsics, np.asarray(image.depth, dtype=float)
    v, u = np.nonzero(np.isfinite(d) & (d > 0))
    step = max(1, len(v) // (4 * _MAX_SAMPLES))
    v, u = v[::step], u[::step]
    z = d[v, u]
    p_C = np.column_stack([(u - k.cx) / k.fx * z, (v - k.cy) / k.fy * z, z])
    p_W = p_C @ image.X_WC[:3, :3].T + image.X_WC[:3, 3]
    on = np.abs(p_W[:, 2] - top_z) < _BAND_M
    on &= (p_W[:, 0] > lo_xy[0] + _INSET_M) & (p_W[:, 0] < hi_xy[0] - _INSET_M)
    on &= (p_W[:, 1] > lo_xy[1] + _INSET_M) & (p_W[:, 1] < hi_xy[1] - _INSET_M)
    idx = np.flatnonzero(on)
    if bodies is not None and len(bodies[0]):  # only the points on the table's top can be under a body
        xy = p_W[idx, None, :2]
        idx = idx[~np.any(np.all((xy >= bodies[0][None]) & (xy <= bodies[1][None]), axis=2), axis=1)]
    idx = idx[:: max(1, len(idx) // _MAX_SAMPLES)]
    return v[idx].astype(float), u[idx].astype(float), z[idx]


def _plane_depth(X_WC: FloatArray, x_n: FloatArray, y_n: FloatArray, top_z: float) -> FloatArray:
    """Depth along the optical axis at which each ray (x_n, y_n, 1) of the camera at X_WC meets z = top_z in W."""
    R, c = X_WC[:3, :3], X_WC[:3, 3]
    dz = R[2, 0] * x_n + R[2, 1] * y_n + R[2, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.asarray((top_z - c[2]) / dz)


def _pose_variance(
    refit: Callable[[FloatArray], FloatArray], X_WC: FloatArray, coef: FloatArray, pose_sigma: tuple[float, float]
) -> FloatArray:
    """(2,) what the told pose's uncertainty adds to the fit's variance: the fit redone with the pose moved by its
    per-axis sigma along and about each of the camera's axes (taken independent)."""
    t_sigma, r_sigma = pose_sigma[0] / math.sqrt(3.0), pose_sigma[1] / math.sqrt(3.0)
    var = np.zeros(2)
    for axis in np.eye(3):
        if t_sigma > 0.0:
            var += (refit(X_WC @ make_pose(p=t_sigma * axis)) - coef) ** 2
        if r_sigma > 0.0:
            var += (refit(X_WC @ make_pose(axis_angle_to_matrix(axis, r_sigma))) - coef) ** 2
    return var
