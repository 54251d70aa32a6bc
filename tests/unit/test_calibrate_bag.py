"""``cell calibrate --capture BAG``: a fixed camera's board images recorded as a ROS 2 bag (colour images with their
CameraInfo and its lens, depth images, the flange's pose on /tf), written from images the simulator rendered at
known poses, are solved without a simulator: the camera's pose within the calibration's bars, through the lens
the CameraInfo states; a bag whose tf has no flange is refused with its reason."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import rosbag_factory as rf
from typer.testing import CliRunner

from cell import scenario as scn
from cell.calibrate.board import Board
from cell.calibrate.file import read
from cell.calibrate.plan import board_poses
from cell.calibrate.solve import pose_error
from cell.cli import app
from cell.errors import CaptureError
from cell.geometry import invert, pose_from_xyz_rpy
from cell.pipeline.calibration import calibrate_capture
from cell.sim import SimCell

TINY = """
name: tiny-bag
seed: 4
simulation: {noise: realistic}
map: {file: dummy.dxf}
table: {center_m: [0.0, 0.0, 0.35], size_m: [1.2, 0.8, 0.1]}
cameras:
  above:
    eye_m: [0.3, 0.2, 1.75]
    target_m: [0.0, 0.0, 0.9]
    resolution: [640, 480]
    hfov_deg: 50
    distortion: {k1: -0.08, k2: 0.02}
perception:
  workspace: {min_m: [-1.0, -1.0, 0.9], max_m: [1.0, 1.0, 1.5]}
"""
X_FB = pose_from_xyz_rpy([0.04, -0.10, -0.08], [0.0, 0.0, 0.0])  # the board on its bracket under the flange


def _bag(tmp_path: Path, flange: str = "tool0", n: int = 8) -> tuple[Path, np.ndarray]:
    """``n`` board images of the camera ``above`` (the world is the robot base) as a bag; and the camera's X_RC."""
    (tmp_path / "dummy.dxf").write_text("not read by this test\n")
    s = scn.from_yaml(TINY, base_dir=tmp_path)
    board = Board(s.calibration.board)
    X_RC = s.cameras["above"].X_WC
    messages = []
    with SimCell(s, ()) as sim:
        intr = sim.intrinsics("above")
        sim.add_board("board", *board.picture())
        poses = board_poses(board, intr, (0.6, 0.85), 25.0, np.random.default_rng(7))
        for i, X_CB in zip(range(n), poses, strict=False):
            sim.place("board", X_RC @ X_CB)
            depth, rgb = sim.capture_rgbd("above")
            t = (i + 1) * 1_000_000_000
            X_RF = X_RC @ X_CB @ invert(X_FB)
            messages += [
                rf.tf([("base_link", flange, X_RF, t - 20_000_000)], static=False, t_ns=t - 20_000_000),
                rf.colour_image("/above/color/image_raw", "above_color_optical", rgb, t),
                rf.camera_info("/above/color/camera_info", "above_color_optical", intr, t, d=intr.distortion),
                rf.image("/above/depth/image_rect_raw", "above_color_optical", depth.depth, t, "32FC1"),
            ]
    return rf.write_bag(tmp_path / "calibration_bag", messages), X_RC


def test_a_fixed_camera_is_calibrated_from_a_ros2_bag(tmp_path: Path) -> None:
    bag, X_RC = _bag(tmp_path)
    run = calibrate_capture(bag, held_out=2)
    (cal,) = run.cameras
    assert cal.camera == "above" and cal.frame == "robot_base" and cal.poses == 6 and cal.held_out_images == 2
    t, r = pose_error(cal.X_AC, X_RC)
    assert t < 1e-3 and np.degrees(r) < 0.1  # six images: within the calibration's worst-case bars
    assert t < 3.0 * cal.solution.sigma_translation_m + 2e-4
    assert cal.intrinsics.lens == (-0.08, 0.02, 0.0, 0.0, 0.0) and not cal.intrinsics.flags  # the stated lens holds
    assert abs(cal.intrinsics.depth_scale - 1.0) < 0.005  # the bag's depth beside each colour image

    out = tmp_path / "cal.yaml"
    result = CliRunner().invoke(app, ["calibrate", "--capture", str(bag), "--held-out", "2", "--out", str(out)])
    assert result.exit_code == 0, result.stderr
    entry = read(out)["cameras"]["above"]
    assert np.allclose(entry["measured"]["xyz_m"], cal.X_AC[:3, 3], atol=1e-6) and "truth_error" not in entry


def test_a_bag_without_the_flanges_pose_is_refused(tmp_path: Path) -> None:
    bag, _ = _bag(tmp_path, flange="link_6", n=1)
    with pytest.raises(CaptureError, match="no flange frame 'tool0'"):
        calibrate_capture(bag, held_out=2)
