"""The one module that imports OpenCV: the ChArUco board (its corners and printed picture), its detector on an image,
PnP, and OpenCV's hand-eye solvers. Rotations cross this edge as 3x3 matrices (OpenCV's Rodrigues vectors stay
inside); poses as 4x4 arrays in metres."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from cell.calibrate import HandEyeMethod
from cell.geometry import FloatArray, make_pose

_HAND_EYE = {
    "park": cv2.CALIB_HAND_EYE_PARK,
    "tsai": cv2.CALIB_HAND_EYE_TSAI,
    "daniilidis": cv2.CALIB_HAND_EYE_DANIILIDIS,
}
VERSION = cv2.__version__


def charuco_board(dictionary: str, squares: tuple[int, int], square_m: float, marker_m: float) -> Any:
    """OpenCV's ``CharucoBoard`` (squares across x down, sizes in metres, a dictionary named as ``DICT_5X5_100``)."""
    d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, dictionary))
    return cv2.aruco.CharucoBoard(tuple(squares), float(square_m), float(marker_m), d)


def corners_B(board: Any) -> FloatArray:
    """(n, 3) [m] the chessboard's inner corners in the board frame B (x along columns, y along rows, z = 0)."""
    return np.asarray(board.getChessboardCorners(), dtype=float).reshape(-1, 3)


def board_picture(board: Any, size_px: tuple[int, int], margin_px: int) -> npt.NDArray[np.uint8]:
    """(h, w) uint8 the printed face: the pattern with a white margin of ``margin_px`` around it."""
    return np.asarray(board.generateImage(tuple(size_px), marginSize=int(margin_px), borderBits=1), dtype=np.uint8)


def detect(board: Any, rgb: npt.ArrayLike) -> tuple[npt.NDArray[np.int64], FloatArray]:
    """The board's corners found in a colour image (h, w, 3) uint8: their ids (k,) and pixel positions (k, 2)
    (sub-pixel, pixel centres at integers); empty arrays when the board is not found."""
    grey = cv2.cvtColor(np.asarray(rgb, dtype=np.uint8), cv2.COLOR_RGB2GRAY)
    params = cv2.aruco.CharucoParameters()
    detector = cv2.aruco.CharucoDetector(board, params)
    corners, ids, _, _ = detector.detectBoard(grey)
    if ids is None or corners is None or len(ids) == 0:
        return np.zeros(0, dtype=np.int64), np.zeros((0, 2))
    px = np.asarray(corners, dtype=np.float32).reshape(-1, 1, 2)
    # A finer sub-pixel refinement than the detector's default window, on the same grey image.
    criteria = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 50, 1e-4)
    cv2.cornerSubPix(grey, px, (5, 5), (-1, -1), criteria)
    return np.asarray(ids, dtype=np.int64).ravel(), np.asarray(px, dtype=float).reshape(-1, 2)


def solve_pnp(p_B: FloatArray, px: FloatArray, K: FloatArray) -> FloatArray:
    """X_CB (4, 4): the board's pose in the camera from its corners p_B (k, 3) [m] seen at px (k, 2), no
    distortion (IPPE for a plane, then Levenberg-Marquardt)."""
    ok, rvec, tvec = cv2.solvePnP(
        np.asarray(p_B, dtype=np.float64), np.asarray(px, dtype=np.float64), K, None, flags=cv2.SOLVEPNP_IPPE
    )
    if not ok:
        raise ValueError("solvePnP found no pose")
    rvec, tvec = cv2.solvePnPRefineLM(
        np.asarray(p_B, dtype=np.float64), np.asarray(px, dtype=np.float64), K, None, rvec, tvec
    )
    return make_pose(cv2.Rodrigues(rvec)[0], np.asarray(tvec, dtype=float).ravel())


def hand_eye(
    X_base_gripper: Sequence[FloatArray], X_cam_target: Sequence[FloatArray], method: HandEyeMethod
) -> FloatArray:
    """OpenCV's ``calibrateHandEye``: X_gripper_cam (4, 4) from the gripper's poses in the base and the target's in
    the camera (eye-in-hand; an eye-to-hand camera passes the base's poses in the gripper and gets X_base_cam)."""
    R_g = [np.asarray(X[:3, :3], dtype=np.float64) for X in X_base_gripper]
    t_g = [np.asarray(X[:3, 3], dtype=np.float64).reshape(3, 1) for X in X_base_gripper]
    R_t = [np.asarray(X[:3, :3], dtype=np.float64) for X in X_cam_target]
    t_t = [np.asarray(X[:3, 3], dtype=np.float64).reshape(3, 1) for X in X_cam_target]
    R, t = cv2.calibrateHandEye(R_g, t_g, R_t, t_t, method=_HAND_EYE[method])
    return make_pose(np.asarray(R, dtype=float), np.asarray(t, dtype=float).ravel())


def calibrate_intrinsics(
    p_B: Sequence[FloatArray], px: Sequence[FloatArray], size: tuple[int, int], K0: FloatArray, D0: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray, float]:
    """OpenCV's ``calibrateCameraExtended`` on planar views from the stated model (K0, D0), the lens' k1, k2, p1, p2
    fitted with the pinhole (k3 held at its stated value: a dozen board views cannot pin it down): K (3, 3), the
    distortion (5,), the standard deviations of (fx, fy, cx, cy, k1, k2, p1, p2, k3), the RMS reprojection [px]."""
    flags = cv2.CALIB_USE_INTRINSIC_GUESS | cv2.CALIB_FIX_K3
    obj = [np.asarray(p, dtype=np.float32).reshape(-1, 1, 3) for p in p_B]
    img = [np.asarray(u, dtype=np.float32).reshape(-1, 1, 2) for u in px]
    rms, K, D, _, _, std, _, _ = cv2.calibrateCameraExtended(
        obj, img, tuple(size), np.array(K0, dtype=np.float64), np.array(D0, dtype=np.float64), flags=flags
    )
    return (
        np.asarray(K, dtype=float),
        np.asarray(D, dtype=float).ravel()[:5],
        np.asarray(std, dtype=float).ravel()[:9],
        float(rms),
    )


def undistort_px(px: FloatArray, K: FloatArray, D: Sequence[float]) -> FloatArray:
    """(k, 2) the pixels px (k, 2) seen through the lens (K, D) moved to where a pinhole of K puts them (OpenCV's
    iterative ``undistortPointsIter``, converged to 1e-9)."""
    pts = np.asarray(px, dtype=np.float64).reshape(-1, 1, 2)
    if len(pts) == 0:
        return np.zeros((0, 2))
    criteria = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-9)
    D64 = np.asarray(D, dtype=np.float64)
    out = cv2.undistortPointsIter(pts, K, D64, np.eye(3), np.asarray(K, dtype=np.float64), criteria)
    return np.asarray(out, dtype=float).reshape(-1, 2)


def remap(image: npt.ArrayLike, map_x: FloatArray, map_y: FloatArray, nearest: bool) -> npt.NDArray[Any]:
    """OpenCV's ``remap``: out[v, u] = image at (map_x, map_y)[v, u] (bilinear, or the nearest pixel for values that
    must not blend, such as depth); 0 outside the image."""
    mode = cv2.INTER_NEAREST if nearest else cv2.INTER_LINEAR
    src = np.asarray(image)
    out = cv2.remap(
        src, map_x.astype(np.float32), map_y.astype(np.float32), mode, borderMode=cv2.BORDER_CONSTANT, borderValue=0
    )
    return np.asarray(out, dtype=src.dtype)
