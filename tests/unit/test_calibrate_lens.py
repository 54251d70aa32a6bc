"""A lens' distortion end to end: the simulated camera renders through it (the board's corners found where the
lens puts them), perception makes its depth image a pinhole's again, the calibration's intrinsics check measures
the lens with its uncertainty and flags a stated model that is wrong; the calibration file tells runs the lens."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from cell import scenario as scn
from cell.calibrate.board import Board, Corners
from cell.calibrate.checks import depth_scale
from cell.calibrate.file import apply
from cell.calibrate.intrinsics import IntrinsicsFlag, check_intrinsics
from cell.calibrate.lens import to_pinhole
from cell.calibrate.views import View, undistorted
from cell.geometry import invert, make_pose, pose_from_xyz_rpy
from cell.perception import deproject
from cell.perception.lens import undistort
from cell.sim import SimCell
from cell.types import CameraIntrinsics

LENS = {"k1": -0.18, "k2": 0.06, "p1": 0.0008, "p2": -0.0006}  # a wide lens' barrel, slightly off-centre
TINY = """
name: tiny-lens
seed: 5
simulation: {noise: none}
map: {file: dummy.dxf}
table: {center_m: [0.0, 0.0, 0.85], size_m: [1.2, 0.8, 0.1]}
cameras:
  above:
    eye_m: [0.3, 0.2, 1.75]
    target_m: [0.0, 0.0, 0.9]
    resolution: [640, 480]
    hfov_deg: 60
    distortion: {k1: -0.18, k2: 0.06, p1: 0.0008, p2: -0.0006}
perception:
  workspace: {min_m: [-1.0, -1.0, 0.8], max_m: [1.0, 1.0, 1.5]}
"""


def _scenario(tmp_path: Path, lens: bool = True) -> scn.Scenario:
    (tmp_path / "dummy.dxf").write_text("not read by these tests\n")
    text = TINY if lens else TINY.replace("    distortion: {k1: -0.18, k2: 0.06, p1: 0.0008, p2: -0.0006}\n", "")
    return scn.from_yaml(text, base_dir=tmp_path)


def _project(k: CameraIntrinsics, p_C: np.ndarray) -> np.ndarray:
    x, y = k.distort(p_C[:, 0] / p_C[:, 2], p_C[:, 1] / p_C[:, 2])
    return np.column_stack([x * k.fx + k.cx, y * k.fy + k.cy])


def test_the_simulated_lens_bends_the_board_where_the_model_says(tmp_path: Path) -> None:
    s = _scenario(tmp_path)
    board = Board(s.calibration.board)
    X_WB = pose_from_xyz_rpy([0.15, -0.05, 1.0], np.radians([165.0, 10.0, 20.0]))  # near the image's edge
    with SimCell(s, ()) as sim:
        picture, face_m, origin_m = board.picture()
        sim.add_board("board", picture, face_m, origin_m)
        sim.place("board", X_WB)
        depth, rgb = sim.capture_rgbd("above")
    k = depth.intrinsics
    assert k.distortion == (-0.18, 0.06, 0.0008, -0.0006, 0.0)  # the image tells its lens
    corners = board.detect(rgb)
    assert len(corners) == len(board.p_B)
    X_CB = invert(s.cameras["above"].X_WC) @ X_WB
    p_C = board.p_B[corners.ids] @ X_CB[:3, :3].T + X_CB[:3, 3]
    bent = _project(k, p_C)
    pinhole = _project(replace(k, distortion=(0.0,) * 5), p_C)
    r = corners.px - bent
    # Where the lens puts them: unbiased, and as close as a pinhole camera finds this tilted board at the image's
    # edge without a lens (0.53 px RMS, the renderer's aliasing).
    assert np.all(np.abs(r.mean(axis=0)) < 0.1) and np.sqrt(np.mean(np.sum(r**2, axis=1))) < 0.6
    assert np.max(np.linalg.norm(bent - pinhole, axis=1)) > 5.0  # which is pixels away from a pinhole's
    back = to_pinhole(corners.px, k.K, k.distortion)
    assert np.sqrt(np.mean(np.sum((back - pinhole) ** 2, axis=1))) < 0.6


def test_perception_makes_the_lens_image_a_pinholes_again(tmp_path: Path) -> None:
    with SimCell(_scenario(tmp_path), ()) as sim:
        bent = sim.capture("above")
    with SimCell(_scenario(tmp_path, lens=False), ()) as sim:
        straight = sim.capture("above")
    top = 0.9  # the table's top [m]: every point seen on it
    flat = undistort(bent)
    assert not flat.intrinsics.distorted and flat.depth.shape == bent.depth.shape
    assert undistort(straight) is straight
    for image, bound in ((flat, 1e-3), (straight, 1e-3)):
        z = deproject(image)[:, 2]
        on = np.abs(z - top) < 0.05
        assert on.mean() > 0.6 and np.percentile(np.abs(z[on] - top), 99) < bound
    raw = replace(bent, intrinsics=flat.intrinsics)  # the lens' image taken for a pinhole's
    z = deproject(raw)[:, 2]
    assert np.percentile(np.abs(z[np.abs(z - top) < 0.2] - top), 99) > 5e-3  # a bowl, not a table
    same = (flat.depth > 0) & (straight.depth > 0)
    assert same.mean() > 0.85 and np.median(np.abs(flat.depth[same] - straight.depth[same])) < 1e-4


def _views(k: CameraIntrinsics, rng: np.random.Generator, n: int = 14) -> list[View]:
    board = Board(scn.calibration_specs.BoardSpec())
    out = []
    for _ in range(n):
        centre = np.array([rng.uniform(-0.15, 0.15), rng.uniform(-0.1, 0.1), rng.uniform(0.6, 0.9)])
        X_CB = pose_from_xyz_rpy(centre, np.radians(rng.uniform(-30.0, 30.0, 3))) @ make_pose(p=-board.centre_B)
        p = board.p_B @ X_CB[:3, :3].T + X_CB[:3, 3]
        px = _project(k, p) + rng.normal(0.0, 0.15, (len(p), 2))
        out.append(View(np.eye(4), Corners(np.arange(len(p)), px), p[:, 2].copy()))
    return out


def test_the_intrinsics_check_measures_the_lens_and_flags_a_wrong_stated_one() -> None:
    spec = scn.calibration_specs.CalibrationRunSpec()
    p_B = Board(spec.board).p_B
    lens = (LENS["k1"], LENS["k2"], LENS["p1"], LENS["p2"], 0.0)
    true = CameraIntrinsics(640, 480, 554.3, 554.3, 319.5, 239.5, lens)
    views = _views(true, np.random.default_rng(11))
    told_wrong = replace(true, distortion=(0.0,) * 5)  # a lens stated as a pinhole
    scale = depth_scale(undistorted(views, true.K, lens), p_B, true.K)
    right = check_intrinsics(views, p_B, true, scale, spec)
    wrong = check_intrinsics(views, p_B, told_wrong, scale, spec)
    for ic in (right, wrong):
        for i in range(4):
            assert abs(ic.distortion[i] - lens[i]) < 4.0 * ic.distortion_sigma[i] + 1e-6
        assert 0.0 < ic.distortion_sigma[0] < 0.05 and abs(ic.fx - true.fx) < 4.0 * ic.sigma_px[0]
    assert IntrinsicsFlag.DISTORTION not in right.flags and right.lens == lens  # confirmed: the stated lens kept
    assert right.distortion_shift_px < 1.0 + 2.0 * right.distortion_shift_sigma_px
    assert IntrinsicsFlag.DISTORTION in wrong.flags and wrong.distortion_shift_px > 2.0
    assert wrong.lens == wrong.distortion  # runs are told the measured lens
    assert abs(scale.ratio - 1.0) < 1e-3  # the depth scale through the lens stated right


def test_a_calibration_file_tells_runs_the_measured_lens(tmp_path: Path) -> None:
    s = _scenario(tmp_path, lens=False)
    measured = [-0.17, 0.05, 0.0007, -0.0005, 0.0]
    entry = {"frame": "robot_base", "measured": {"xyz_m": [0.0, 0.0, 1.0], "rpy_deg": [180.0, 0.0, 0.0]}}
    entry |= {"calibration": {"translation_mm": 0.1, "rotation_deg": 0.01}, "intrinsics": {"lens": measured}}
    calibrated = apply(s, {"format": "cell-calibration/1", "cameras": {"above": entry}})
    assert calibrated.cameras["above"].told_distortion == tuple(measured)
    assert calibrated.cameras["above"].distortion.coefficients == (0.0,) * 5  # the simulation's lens is unchanged
    with SimCell(calibrated, ()) as sim:
        assert sim.capture("above").intrinsics.distortion == tuple(measured)
    entry["intrinsics"] = {"lens": [0.1, 0.2]}
    with pytest.raises(Exception, match="five numbers"):
        apply(s, {"format": "cell-calibration/1", "cameras": {"above": entry}})
