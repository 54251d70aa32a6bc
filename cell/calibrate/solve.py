"""The calibration's solvers: a start from PnP per image and OpenCV's hand-eye (Park, Tsai, Daniilidis), then the
joint refinement of both unknown poses over every corner of every image (scipy's least squares on the reprojection
error), its covariance from the Jacobian and the residuals, and the residuals on images held out of the fit.

The chain p_C = X_CA T_i X_HB p_B: A is the frame the camera is fixed in (the robot base R for a fixed camera, the
flange F for the arm's), H the board's holder (the flange F, the base R), T_i the robot's reported pose between them
(:func:`cell.calibrate.views.chain_T`)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from cell.calibrate import HandEyeMethod, _opencv
from cell.calibrate.views import Mount, View, chain_T
from cell.errors import CalibrationError, CalibrationFault
from cell.geometry import FloatArray, invert, make_pose, readonly

_MIN_CORNERS = 6  # a view with fewer corners found is not used
WRIST_LEVER_M = 0.5  # the repeatability's rotation: the data sheet's distance over this lever [rad per m]
_STEP = 1e-7  # finite-difference step of the flange pose's perturbation [m, rad]


@dataclass(frozen=True)
class Solution:
    """Both poses of the chain: X_AC (4, 4) the camera in A, X_HB (4, 4) the board in H; cov_AC (6, 6) the camera
    pose's covariance, rotation [rad] then translation [m], both about and along A's axes (X_AC's error is
    (Exp(w) R, p + v) with (w, v) of this covariance); rms_px the fit's reprojection RMS over ``corners`` corners."""

    X_AC: FloatArray
    X_HB: FloatArray
    cov_AC: FloatArray
    rms_px: float
    corners: int

    def __post_init__(self) -> None:
        for name in ("X_AC", "X_HB", "cov_AC"):
            object.__setattr__(self, name, readonly(getattr(self, name)))

    @property
    def sigma_translation_m(self) -> float:
        """RMS of the camera position's error (the root of the covariance's translation trace) [m]."""
        return float(np.sqrt(np.trace(self.cov_AC[3:, 3:])))

    @property
    def sigma_rotation_rad(self) -> float:
        """RMS of the camera rotation's error angle [rad]."""
        return float(np.sqrt(np.trace(self.cov_AC[:3, :3])))


def usable(views: Sequence[View]) -> list[View]:
    """The views with enough corners to stand on their own (PnP)."""
    return [v for v in views if len(v.corners) >= _MIN_CORNERS]


def pnp_poses(views: Sequence[View], p_B: FloatArray, K: FloatArray) -> list[FloatArray]:
    """X_CB (4, 4) of each view from its corners alone."""
    return [_opencv.solve_pnp(p_B[v.corners.ids], v.corners.px, K) for v in views]


def hand_eye_start(
    views: Sequence[View], p_B: FloatArray, K: FloatArray, mount: Mount, method: HandEyeMethod = "park"
) -> tuple[FloatArray, FloatArray]:
    """(X_AC, X_HB): OpenCV's hand-eye solution for the camera and the board's pose averaged over the views."""
    X_CB = pnp_poses(views, p_B, K)
    T = [chain_T(v, mount) for v in views]
    X_AC = _opencv.hand_eye([invert(t) for t in T], X_CB, method)
    boards = [invert(t) @ X_AC @ x for t, x in zip(T, X_CB, strict=True)]
    R_mean = Rotation.from_matrix(np.array([b[:3, :3] for b in boards])).mean().as_matrix()
    return X_AC, make_pose(R_mean, np.mean([b[:3, 3] for b in boards], axis=0))


def _perturbed(X0: FloatArray, x: FloatArray) -> FloatArray:
    return make_pose(Rotation.from_rotvec(x[:3]).as_matrix() @ X0[:3, :3], X0[:3, 3] + x[3:])


def _project(K: FloatArray, p_C: FloatArray) -> FloatArray:
    uvw = p_C @ K.T
    return np.asarray(uvw[:, :2] / uvw[:, 2:3])


def _chain_px(X_AC: FloatArray, T: FloatArray, X_HB: FloatArray, p: FloatArray, K: FloatArray) -> FloatArray:
    X_CB = invert(X_AC) @ T @ X_HB
    return _project(K, p @ X_CB[:3, :3].T + X_CB[:3, 3])


def predicted_px(
    X_AC: FloatArray, X_HB: FloatArray, view: View, p_B: FloatArray, K: FloatArray, mount: Mount
) -> FloatArray:
    """(k, 2) where the chain puts the view's corners in its image [px]."""
    return _chain_px(X_AC, chain_T(view, mount), X_HB, p_B[view.corners.ids], K)


def flange_px_jacobian(
    X_AC: FloatArray, X_HB: FloatArray, view: View, p_B: FloatArray, K: FloatArray, mount: Mount
) -> FloatArray:
    """(2k, 6) how the view's corners move in its image [px] with the flange's true pose off the reported one,
    X_RF Exp(w, v), w [rad] then v [m] about and along the flange's axes (central differences)."""
    p = p_B[view.corners.ids]
    cols = []
    for j in range(6):
        d = np.zeros(6)
        d[j] = _STEP
        moved = [view.X_RF @ make_pose(Rotation.from_rotvec(s * d[:3]).as_matrix(), s * d[3:]) for s in (1.0, -1.0)]
        T = [m if mount == Mount.EYE_TO_HAND else invert(m) for m in moved]
        cols.append((_chain_px(X_AC, T[0], X_HB, p, K) - _chain_px(X_AC, T[1], X_HB, p, K)).ravel() / (2 * _STEP))
    return np.stack(cols, axis=1)


def flange_covariance(repeatability_m: float) -> FloatArray:
    """(6, 6) the covariance of the flange's true pose about the reported one, rotation [rad] then translation [m]:
    the data sheet's repeatability on each axis, and its rotation that distance over the wrist's lever."""
    return np.diag([(repeatability_m / WRIST_LEVER_M) ** 2] * 3 + [repeatability_m**2] * 3)


def refine(
    views: Sequence[View],
    p_B: FloatArray,
    K: FloatArray,
    mount: Mount,
    X_AC0: FloatArray,
    X_HB0: FloatArray,
    repeatability_m: float = 0.0,
) -> Solution:
    """The joint refinement from a start: both poses fitted to every corner's pixel (Levenberg-Marquardt). The
    camera's covariance is the larger of the model's, the pixels' (s^2 (J^T J)^-1) plus the robot's repeatability
    (each image's flange pose off by :func:`flange_covariance`, carried through the fit), and the one robust to any
    error shared by an image's corners (a sandwich clustered by image)."""

    def residual(x: FloatArray) -> FloatArray:
        X_AC, X_HB = _perturbed(X_AC0, x[:6]), _perturbed(X_HB0, x[6:])
        return np.concatenate([(predicted_px(X_AC, X_HB, v, p_B, K, mount) - v.corners.px).ravel() for v in views])

    fit = least_squares(residual, np.zeros(12), method="lm", x_scale=np.full(12, 1e-3))
    if not fit.success:
        raise CalibrationError(
            f"the joint refinement did not converge ({fit.message})", code=CalibrationFault.NOT_CONVERGED
        )
    r, J = fit.fun, fit.jac
    m, n = J.shape
    info = np.linalg.inv(J.T @ J)
    cov = info * float(r @ r) / max(m - n, 1)
    meat = np.zeros((n, n))
    start = 0
    for v in views:
        k = 2 * len(v.corners)
        g = J[start : start + k].T @ r[start : start + k]
        meat += np.outer(g, g)
        start += k
    clustered = info @ meat @ info * len(views) / max(len(views) - 1, 1)
    if repeatability_m > 0.0:
        cov = cov + _repeatability_cov(views, p_B, K, mount, fit.x, X_AC0, X_HB0, J, info, repeatability_m)
    pick = clustered if np.trace(clustered[:6, :6]) > np.trace(cov[:6, :6]) else cov
    return Solution(
        X_AC=_perturbed(X_AC0, fit.x[:6]),
        X_HB=_perturbed(X_HB0, fit.x[6:]),
        cov_AC=pick[:6, :6],
        rms_px=float(np.sqrt(np.mean(r**2) * 2.0)),
        corners=m // 2,
    )


def _repeatability_cov(
    views: Sequence[View],
    p_B: FloatArray,
    K: FloatArray,
    mount: Mount,
    x: FloatArray,
    X_AC0: FloatArray,
    X_HB0: FloatArray,
    J: FloatArray,
    info: FloatArray,
    repeatability_m: float,
) -> FloatArray:
    """(12, 12) the fit's covariance from the flange poses' independent errors: a flange off by d_i moves image i's
    corners by B_i d_i, and the fit by -(J^T J)^-1 J_i^T B_i d_i (first order)."""
    X_AC, X_HB = _perturbed(X_AC0, x[:6]), _perturbed(X_HB0, x[6:])
    S = flange_covariance(repeatability_m)
    out = np.zeros((J.shape[1], J.shape[1]))
    start = 0
    for v in views:
        k = 2 * len(v.corners)
        A = info @ J[start : start + k].T @ flange_px_jacobian(X_AC, X_HB, v, p_B, K, mount)
        out += A @ S @ A.T
        start += k
    return out


def held_out(sol: Solution, views: Sequence[View], p_B: FloatArray, K: FloatArray, mount: Mount) -> tuple[float, float]:
    """(reprojection RMS [px], 3D RMS [m]) of the solution on views it was not fitted to: the corners' pixels, and
    the corners where the chain puts them against where each view's own PnP does (in the camera)."""
    if not views:
        return float("nan"), float("nan")
    px2, d2, n = 0.0, 0.0, 0
    for v, X_CB in zip(views, pnp_poses(views, p_B, K), strict=True):
        px2 += float(np.sum((predicted_px(sol.X_AC, sol.X_HB, v, p_B, K, mount) - v.corners.px) ** 2))
        X_chain = invert(sol.X_AC) @ chain_T(v, mount) @ sol.X_HB
        p = p_B[v.corners.ids]
        d2 += float(np.sum((p @ (X_chain[:3, :3] - X_CB[:3, :3]).T + (X_chain[:3, 3] - X_CB[:3, 3])) ** 2))
        n += len(v.corners)
    return float(np.sqrt(px2 / n)), float(np.sqrt(d2 / n))


def pose_error(X_est: FloatArray, X_true: FloatArray) -> tuple[float, float]:
    """(translation [m], rotation [rad]) between two poses of one frame."""
    dR = X_est[:3, :3].T @ X_true[:3, :3]
    angle = float(np.linalg.norm(Rotation.from_matrix(dR).as_rotvec()))
    return float(np.linalg.norm(X_est[:3, 3] - X_true[:3, 3])), angle
