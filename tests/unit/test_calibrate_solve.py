"""The calibration's solvers on synthetic detections: a known camera and board, corners projected with pixel noise,
the robot's poses reported exactly. The joint refinement recovers both mounts, its covariance covers its error, and
the checks refuse a degenerate pose set and a board of the wrong size."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from cell.calibrate.board import Board, Corners
from cell.calibrate.checks import check_board_size, check_diversity, depth_scale, rotation_spread_deg
from cell.calibrate.solve import WRIST_LEVER_M, hand_eye_start, held_out, pose_error, refine
from cell.calibrate.views import Mount, View
from cell.errors import CalibrationError, CalibrationFault
from cell.geometry import invert, look_at, make_pose, pose_from_xyz_rpy
from cell.scenario.calibration_specs import BoardSpec

K = np.array([[1004.0, 0.0, 639.5], [0.0, 1004.0, 359.5], [0.0, 0.0, 1.0]])
BOARD = Board(BoardSpec())
X_RC = look_at([0.9, 0.6, 1.1], [0.0, 0.9, 0.1], [0.0, 0.0, 1.0])  # a fixed camera in the robot's base frame
X_FB = pose_from_xyz_rpy([0.04, -0.10, -0.08], [0.0, 0.0, 0.0])  # the board on the flange


def _views(X_RF: list[np.ndarray], X_CB: list[np.ndarray], rng: np.random.Generator, px_sigma: float) -> list[View]:
    out = []
    for f, x in zip(X_RF, X_CB, strict=True):
        p = BOARD.p_B @ x[:3, :3].T + x[:3, 3]
        px = p[:, :2] / p[:, 2:] * K[0, 0] + K[:2, 2] + rng.normal(0.0, px_sigma, (len(p), 2))
        out.append(View(f, Corners(np.arange(len(p)), px), p[:, 2].copy()))
    return out


def _eye_to_hand(rng: np.random.Generator, n: int, rotate: bool = True) -> tuple[list[View], list[np.ndarray]]:
    """Board poses facing the camera 0.8-1.0 m away, tilted up to 25 deg about random axes (or not at all)."""
    X_RF = []
    for _ in range(n):
        centre_C = np.array([rng.uniform(-0.1, 0.1), rng.uniform(-0.08, 0.08), rng.uniform(0.8, 1.0)])
        tilt = rng.uniform(-25.0, 25.0, 3) if rotate else np.zeros(3)
        X_CB = pose_from_xyz_rpy(centre_C, np.radians(tilt)) @ make_pose(p=-BOARD.centre_B)
        X_RF.append(X_RC @ X_CB @ invert(X_FB))
    X_CB = [invert(X_RC) @ f @ X_FB for f in X_RF]
    return _views(X_RF, X_CB, rng, 0.25), X_CB


def test_the_fixed_camera_and_the_board_on_the_flange_are_recovered_within_their_stated_bounds() -> None:
    rng = np.random.default_rng(3)
    views, _ = _eye_to_hand(rng, 14)
    X0, B0 = hand_eye_start(views[:10], BOARD.p_B, K, Mount.EYE_TO_HAND)
    sol = refine(views[:10], BOARD.p_B, K, Mount.EYE_TO_HAND, X0, B0)
    t, r = pose_error(sol.X_AC, X_RC)
    t0, _ = pose_error(X0, X_RC)
    assert t < 0.5e-3 and np.degrees(r) < 0.05
    assert t <= t0 + 1e-5  # the refinement does at least as well as OpenCV's hand-eye alone
    assert t < 3.0 * sol.sigma_translation_m and r < 3.0 * sol.sigma_rotation_rad
    assert pose_error(sol.X_HB, X_FB)[0] < 0.5e-3
    px, d3 = held_out(sol, views[10:], BOARD.p_B, K, Mount.EYE_TO_HAND)
    assert 0.2 < px < 0.6 and d3 < 1.5e-3  # the pixel noise (0.25 px per axis) seen again on unseen images


def test_the_arm_camera_on_the_flange_is_recovered_from_a_board_on_the_table() -> None:
    rng = np.random.default_rng(5)
    X_FC = pose_from_xyz_rpy([0.1, 0.0, 0.08], [-90.0, 0.0, -65.0])
    X_RB = make_pose(p=[0.0, 0.9, 0.0])
    X_RF, X_CB = [], []
    for _ in range(12):
        eye = X_RB[:3, 3] + BOARD.centre_B + np.array([*rng.uniform(-0.25, 0.25, 2), rng.uniform(0.4, 0.55)])
        X_RC_i = look_at(
            eye, X_RB[:3, 3] + BOARD.centre_B + np.r_[rng.uniform(-0.03, 0.03, 2), 0.0], rng.normal(0, 1, 3)
        )
        X_RF.append(X_RC_i @ invert(X_FC))
        X_CB.append(invert(X_RC_i) @ X_RB)
    views = _views(X_RF, X_CB, rng, 0.25)
    X0, B0 = hand_eye_start(views, BOARD.p_B, K, Mount.EYE_IN_HAND, "tsai")
    sol = refine(views, BOARD.p_B, K, Mount.EYE_IN_HAND, X0, B0)
    t, r = pose_error(sol.X_AC, X_FC)
    assert t < 0.5e-3 and np.degrees(r) < 0.1
    assert t < 3.0 * sol.sigma_translation_m and r < 3.0 * sol.sigma_rotation_rad


def test_a_pose_set_without_rotation_is_refused_as_degenerate() -> None:
    views, _ = _eye_to_hand(np.random.default_rng(1), 8, rotate=False)
    assert rotation_spread_deg(views, Mount.EYE_TO_HAND)[0] < 1e-6
    with pytest.raises(CalibrationError) as e:
        check_diversity(views, Mount.EYE_TO_HAND, "cam")
    assert e.value.code == CalibrationFault.DEGENERATE and e.value.exit_code == 17


def test_rotations_about_one_axis_only_are_refused_and_two_axes_pass() -> None:
    rng = np.random.default_rng(2)
    views, _ = _eye_to_hand(rng, 8)
    check_diversity(views, Mount.EYE_TO_HAND, "cam")  # random tilts: fine
    about_z = [
        View(X_RC @ pose_from_xyz_rpy([0, 0, 0.9], [0, 0, a]) @ invert(X_FB), v.corners, v.depth_m)
        for a, v in zip(np.radians(np.linspace(-30, 30, 8)), views, strict=True)
    ]
    first, second = rotation_spread_deg(about_z, Mount.EYE_TO_HAND)
    assert first > 10.0 and second < 1e-6
    with pytest.raises(CalibrationError):
        check_diversity(about_z, Mount.EYE_TO_HAND, "cam")


def test_a_board_printed_larger_than_stated_is_caught_by_the_depth_image() -> None:
    rng = np.random.default_rng(4)
    views, _ = _eye_to_hand(rng, 8)
    scale = depth_scale(views, BOARD.p_B, K)
    assert abs(scale.ratio - 1.0) < 1e-3
    check_board_size(scale, "cam", 0.02)
    big = [View(v.X_RF, v.corners, v.depth_m * 1.05) for v in views]  # what a 5 % larger board looks like
    s = depth_scale(big, BOARD.p_B, K)
    assert s.ratio == pytest.approx(1.05, abs=2e-3)
    with pytest.raises(CalibrationError) as e:
        check_board_size(s, "cam", 0.02)
    assert e.value.code == CalibrationFault.BOARD_SIZE and e.value.value == pytest.approx(1.05, abs=2e-3)


def _repeatability_trials(rep_m: float, trials: int, stated_m: float) -> tuple[np.ndarray, np.ndarray]:
    """(trials, 2) errors and stated sigmas (translation [m], rotation [rad]) of a fixed camera over 12 board poses
    the arm reached off its reported ones by ``rep_m`` (as the simulator draws it), corners with 0.05 px of noise,
    the fit told a repeatability of ``stated_m``."""
    geo = np.random.default_rng(7)
    X_RF = []
    for _ in range(12):
        centre_C = np.array([geo.uniform(-0.1, 0.1), geo.uniform(-0.08, 0.08), geo.uniform(0.8, 1.0)])
        X_CB = pose_from_xyz_rpy(centre_C, np.radians(geo.uniform(-25.0, 25.0, 3))) @ make_pose(p=-BOARD.centre_B)
        X_RF.append(X_RC @ X_CB @ invert(X_FB))
    err, sig = [], []
    for trial in range(trials):
        rng = np.random.default_rng(100 + trial)
        off = [
            make_pose(
                Rotation.from_rotvec(rng.normal(0.0, rep_m / WRIST_LEVER_M, 3)).as_matrix(), rng.normal(0.0, rep_m, 3)
            )
            for _ in X_RF
        ]
        reached = [f @ o for f, o in zip(X_RF, off, strict=True)]
        seen = _views(reached, [invert(X_RC) @ f @ X_FB for f in reached], rng, 0.05)
        views = [View(f, v.corners, v.depth_m) for f, v in zip(X_RF, seen, strict=True)]
        X0, B0 = hand_eye_start(views, BOARD.p_B, K, Mount.EYE_TO_HAND)
        sol = refine(views, BOARD.p_B, K, Mount.EYE_TO_HAND, X0, B0, stated_m)
        err.append(pose_error(sol.X_AC, X_RC))
        sig.append((sol.sigma_translation_m, sol.sigma_rotation_rad))
    return np.array(err), np.array(sig)


def test_the_stated_sigma_follows_the_robots_repeatability_and_covers_a_monte_carlo() -> None:
    for rep_m in (0.03e-3, 0.1e-3):  # the data sheet's, and a worn robot's
        err, sig = _repeatability_trials(rep_m, 20, rep_m)
        ratio = np.median(sig, axis=0) / np.sqrt(np.mean(err**2, axis=0))  # measured 1.06-1.10
        assert np.all((ratio > 0.95) & (ratio < 1.25)), ratio
        assert np.mean(np.all(err <= 2.0 * sig, axis=1)) >= 0.9  # measured 0.95
    err, sig = _repeatability_trials(0.03e-3, 20, 0.0)  # the fit not told: the pixels' and clustered terms alone
    ratio = np.median(sig, axis=0) / np.sqrt(np.mean(err**2, axis=0))  # measured 0.81-0.83
    assert np.all(ratio < 0.9), ratio
