"""The calibration board in the simulated cell: rendered in colour, found by OpenCV's ChArUco detector where it truly
lies; a calibration file read back over a scenario, and the measured pose is then what the cell is told."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from cell import scenario as scn
from cell.calibrate import solve
from cell.calibrate.board import Board
from cell.calibrate.file import FORMAT, apply, flagged, read
from cell.errors import UsageError
from cell.geometry import invert, make_pose, matrix_to_rpy, pose_from_xyz_rpy
from cell.sim import SimCell

TINY = """
name: tiny-board
seed: 3
simulation: {{noise: {noise}}}
map: {{file: dummy.dxf}}
table: {{center_m: [0.0, 0.0, 0.85], size_m: [1.2, 0.8, 0.1]}}
robot: {{X_WR: {{xyz_m: [0.0, -0.9, 0.9]}}}}
cameras:
  above:
    eye_m: [0.3, 0.2, 1.75]
    target_m: [0.0, 0.0, 0.9]
    resolution: [640, 480]
    hfov_deg: 50
    extrinsic_error: {{translation_mm: 2.0, rotation_deg: 0.2}}
perception:
  workspace: {{min_m: [-1.0, -1.0, 0.9], max_m: [1.0, 1.0, 1.5]}}
"""


def _scenario(tmp_path: Path, noise: str = "realistic") -> scn.Scenario:
    (tmp_path / "dummy.dxf").write_text("not read by these tests\n")
    return scn.from_yaml(TINY.format(noise=noise), base_dir=tmp_path)


def test_the_rendered_board_is_found_where_it_lies(tmp_path: Path) -> None:
    s = _scenario(tmp_path)
    board = Board(s.calibration.board)
    X_WB = pose_from_xyz_rpy([-0.1, -0.1, 1.05], np.radians([160.0, 15.0, 10.0]))  # facing up, tilted
    with SimCell(s, ()) as sim:
        picture, face_m, origin_m = board.picture()
        sim.add_board("board", picture, face_m, origin_m)
        sim.place("board", X_WB)
        depth, rgb = sim.capture_rgbd("above")
        intr = sim.intrinsics("above")
    assert rgb.shape == (480, 640, 3) and rgb.dtype == np.uint8
    corners = board.detect(rgb)
    assert len(corners) == len(board.p_B)  # every inner corner, with the colour noise and blur on
    X_CB_true = invert(s.cameras["above"].X_WC) @ X_WB
    p = board.p_B[corners.ids] @ X_CB_true[:3, :3].T + X_CB_true[:3, 3]
    px_true = p[:, :2] / p[:, 2:] * intr.fx + [intr.cx, intr.cy]
    rms = float(np.sqrt(np.mean(np.sum((corners.px - px_true) ** 2, axis=1))))
    assert rms < 0.3  # the corners where the board truly is, to a fraction of a pixel
    X_CB = solve.pnp_poses([_view(corners, depth)], board.p_B, intr.K)[0]
    t, r = solve.pose_error(X_CB, X_CB_true)
    assert t < 2e-3 and math.degrees(r) < 1.0  # one image at 0.8 m with 640 px: PnP's own spread
    z = (board.p_B @ X_CB[:3, :3].T + X_CB[:3, 3])[:, 2]
    assert np.nanmedian(_view(corners, depth).depth_m / z) == pytest.approx(1.0, abs=0.005)


def _view(corners: object, depth: object) -> solve.View:
    from cell.pipeline.calibration import depth_at

    return solve.View(np.eye(4), corners, depth_at(depth.depth, corners.px))  # type: ignore[arg-type, attr-defined]


def test_a_calibration_file_puts_its_measured_pose_in_place_of_the_perturbed_one(tmp_path: Path) -> None:
    s = _scenario(tmp_path, noise="none")
    X_RC = invert(s.X_WR) @ s.cameras["above"].X_WC @ make_pose(p=[0.0004, 0.0, 0.0])
    rpy = np.degrees(matrix_to_rpy(X_RC[:3, :3]))
    doc = {
        "format": FORMAT,
        "cameras": {
            "above": {
                "frame": "robot_base",
                "measured": {"xyz_m": X_RC[:3, 3].tolist(), "rpy_deg": rpy.tolist()},
                "calibration": {"translation_mm": 0.1, "rotation_deg": 0.01},
            }
        },
    }
    with SimCell(s, ()) as sim:
        told_before = sim.capture("above").X_WC
    calibrated = apply(s, doc)
    assert calibrated.cameras["above"].calibration.translation_mm == 0.1
    with SimCell(calibrated, ()) as sim:
        told = sim.capture("above").X_WC
    assert np.allclose(told, s.X_WR @ X_RC, atol=1e-9)  # the measured pose, not the seeded error
    assert solve.pose_error(told_before, s.cameras["above"].X_WC)[0] == pytest.approx(2e-3)
    assert flagged(doc) == {}
    doc["cameras"]["above"]["intrinsics"] = {"flags": ["depth_scale"]}
    assert flagged(doc) == {"above": ["depth_scale"]}
    with pytest.raises(UsageError, match="not in scenario"):
        apply(s, {"format": FORMAT, "cameras": {"nowhere": doc["cameras"]["above"]}})
    bad = tmp_path / "bad.yaml"
    bad.write_text("cameras: {}\n")
    with pytest.raises(UsageError, match="not a calibration file"):
        read(bad)


def test_a_board_printed_at_another_scale_is_what_the_simulation_renders(tmp_path: Path) -> None:
    s = _scenario(tmp_path, noise="none")
    stated, printed = Board(s.calibration.board), Board(s.calibration.board, scale=1.05)
    assert printed.pattern_m[0] == pytest.approx(1.05 * stated.pattern_m[0])
    assert np.allclose(printed.p_B, 1.05 * stated.p_B)
    picture, face_m, origin_m = printed.picture()
    assert face_m[0] == pytest.approx(1.05 * stated.picture()[1][0]) and origin_m[0] == pytest.approx(-0.0105)
    assert picture.shape == stated.picture()[0].shape  # the same picture, printed larger


def test_a_camera_that_sees_the_board_at_no_pose_is_refused_with_its_reason() -> None:
    import yaml

    from cell.errors import CalibrationError, CalibrationFault
    from cell.pipeline.calibration import calibrate

    # fence1's right camera with its near plane beyond every planned board distance (0.7 to 1.1 m): the board is
    # never drawn in its images. Four poses wanted, a small image: four renders, then the refusal.
    _, doc = _fence1()
    doc["cameras"]["cam_right"].update(near_m=1.5, resolution=[320, 240])
    s = scn.from_yaml(yaml.safe_dump(doc), base_dir=scn.SCENARIO_DIR)
    with pytest.raises(CalibrationError) as e:
        calibrate(s, ["cam_right"])
    assert e.value.code == CalibrationFault.NOT_SEEN and e.value.exit_code == 17
    assert e.value.value == 0 and e.value.needed == 4
    assert "cannot see the board at any pose" in str(e.value) and "0 of 4 images" in str(e.value)


def _fence1(**calibration: object) -> scn.Scenario:
    import yaml

    doc = yaml.safe_load((scn.SCENARIO_DIR / "fence1.yaml").read_text(encoding="utf-8"))
    doc["calibration"] = {"poses": 4, "held_out": 0, **calibration}
    return scn.from_yaml(yaml.safe_dump(doc), base_dir=scn.SCENARIO_DIR), doc  # type: ignore[return-value]


def test_calibration_poses_that_collide_with_the_cell_or_the_part_are_dropped() -> None:
    from cell.calibrate.views import Mount
    from cell.geometry import pose_from_xyz_rpy
    from cell.pipeline.calibration.images import PoseScreen
    from cell.pipeline.geometry import robot_arm

    s, _ = _fence1()
    arm = robot_arm(s)
    assert arm is not None
    board = Board(s.calibration.board)
    X_FB = pose_from_xyz_rpy(s.calibration.mount.X_FB_xyz_m, np.radians(s.calibration.mount.X_FB_rpy_deg))
    screen = PoseScreen(s, arm, board, X_FB)
    home = arm.q_home
    X_RF = arm.model.fk(home, "tool0")
    assert not screen.collides(home, Mount.EYE_TO_HAND, X_RF)  # the arm over the table, torch well above the parts
    bent = np.array(home, dtype=float)
    bent[1] += np.radians(80.0)  # the shoulder down: the flange below the table top
    assert screen.collides(bent, Mount.EYE_TO_HAND, arm.model.fk(bent, "tool0"))
    # The board on the flange sunk into the top rail's place, the arm itself clear: the plate counts.
    top = next(p for p in s_parts(s) if p.name == "TOP_RAIL")
    X_RB = make_pose(p=top.vertices().mean(axis=0) - board.centre_B)
    assert screen.collides(home, Mount.EYE_TO_HAND, X_RB @ invert(X_FB))
    assert not screen.collides(home, Mount.EYE_IN_HAND, X_RB @ invert(X_FB))  # the board then lies where the part would


def s_parts(s: scn.Scenario) -> tuple:  # type: ignore[type-arg]
    from cell.pipeline.detect import read_weldmap

    return read_weldmap(s).transformed(invert(s.X_WR) @ s.X_WM, "R").parts


def test_too_few_poses_clear_of_the_cell_is_refused_with_its_reason() -> None:
    import yaml

    from cell.errors import CalibrationError, CalibrationFault
    from cell.pipeline.calibration import calibrate

    # The table's collision box grown 1.5 m on every side: every reachable pose collides, none is rendered.
    _, doc = _fence1()
    doc.setdefault("motion", {}).setdefault("plan", {})["collision"] = {"table_inflation": 1.5}
    s = scn.from_yaml(yaml.safe_dump(doc), base_dir=scn.SCENARIO_DIR)
    with pytest.raises(CalibrationError) as e:
        calibrate(s, ["cam_right"])
    assert e.value.code == CalibrationFault.COLLIDING and e.value.exit_code == 17
    assert e.value.value == 0 and e.value.needed == 4 and "keep the arm clear of the cell" in str(e.value)
