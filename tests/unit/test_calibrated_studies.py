"""``cell sweep`` and ``cell bench`` over a calibrated cell (``--calibration``): the file's measured poses stay the
cell's belief, the study's extrinsic error moves the true cameras off them by exactly its size (the arm's camera:
its told pose, the truth being the robot model's); without a measured pose the scenario's own model is used."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from cell import scenario as sc
from cell.bench import Extrinsics, with_extrinsics
from cell.calibrate.file import FORMAT, apply
from cell.calibrate.solve import pose_error
from cell.cli import app
from cell.geometry import invert, make_pose, matrix_to_rpy
from cell.scenario import ExtrinsicErrorSpec
from cell.sim.calibrated import off_calibration
from cell.sim.noise import believed_pose
from cell.sweep import varied
from cell.sweep.variations import Variation


def _calibrated() -> tuple[sc.Scenario, dict[str, np.ndarray]]:
    """fence1 told a calibration 0.4 mm off each fixed camera's truth, and the arm camera's true X_FC."""
    s = sc.load("fence1")
    cams, measured = {}, {}
    for name, cam in s.cameras.items():
        if cam.mount == "fixed":
            X = invert(s.X_WR) @ cam.X_WC @ make_pose(p=[0.0004, 0.0, 0.0])
            frame = "robot_base"
        else:
            X = make_pose(p=[0.01, 0.02, 0.1])  # the arm camera's measured X_FC (its truth is the URDF's)
            frame = "flange"
        measured[name] = X
        pose = {"xyz_m": X[:3, 3].tolist(), "rpy_deg": np.degrees(matrix_to_rpy(X[:3, :3])).tolist()}
        cams[name] = {"frame": frame, "measured": pose, "calibration": {"translation_mm": 0.2, "rotation_deg": 0.02}}
    return apply(s, {"format": FORMAT, "cameras": cams}), measured


def test_the_true_cameras_move_off_the_calibrated_belief_by_the_drawn_error() -> None:
    s, measured = _calibrated()
    err = ExtrinsicErrorSpec(translation_mm=1.5, rotation_deg=0.2)
    off = off_calibration(s, {"cam_left": err, "eye_in_hand": err})
    left = off.cameras["cam_left"]
    told = believed_pose(left, left.X_WC, off.X_WR, None, np.random.default_rng(0))
    assert np.allclose(told, s.X_WR @ measured["cam_left"], atol=1e-9)  # the cell still believes its calibration
    t, r = pose_error(left.X_WC, told)  # the truth it renders from: exactly the error off that belief
    assert math.isclose(t, 1.5e-3, rel_tol=1e-6) and math.isclose(math.degrees(r), 0.2, rel_tol=1e-6)
    assert off.cameras["cam_right"] == s.cameras["cam_right"]  # not named: untouched
    arm = off.cameras["eye_in_hand"]
    assert arm.measured is not None and arm.eye_m == s.cameras["eye_in_hand"].eye_m
    t, r = pose_error(arm.measured.X, measured["eye_in_hand"])
    assert math.isclose(t, 1.5e-3, rel_tol=1e-5) and math.isclose(math.degrees(r), 0.2, rel_tol=1e-5)
    plain = off_calibration(sc.load("fence1"), {"cam_left": err})  # no calibration: the scenario's own model
    assert plain.cameras["cam_left"].extrinsic_error == err and plain.cameras["cam_left"].measured is None


def test_a_sweep_and_a_bench_over_a_calibrated_cell_use_its_belief() -> None:
    s, measured = _calibrated()
    v = Variation(3, None, None, {"cam_left": (1.0, 0.1), "cam_right": (0.5, 0.05), "eye_in_hand": (0.0, 0.0)}, None)
    run = varied(s, v)
    for name, (t_mm, r_deg) in (("cam_left", (1.0, 0.1)), ("cam_right", (0.5, 0.05))):
        t, r = pose_error(run.cameras[name].X_WC, s.X_WR @ measured[name])
        assert math.isclose(t * 1e3, t_mm, rel_tol=1e-6) and math.isclose(math.degrees(r), r_deg, rel_tol=1e-6)
        assert run.cameras[name].calibration == s.cameras[name].calibration  # the file's stated residual kept
    bench = with_extrinsics(s, Extrinsics(1.0, 0.1))
    for name in ("cam_left", "cam_right"):
        t, _ = pose_error(bench.cameras[name].X_WC, s.X_WR @ measured[name])
        assert math.isclose(t, 1e-3, rel_tol=1e-6) and bench.cameras[name].calibration.translation_mm == 1.0
    assert bench.cameras["eye_in_hand"] == s.cameras["eye_in_hand"]  # bench moves the fixed cameras only
    assert with_extrinsics(s, Extrinsics()) is s  # exact: the calibration as measured


def test_sweep_and_bench_read_the_calibration_file(tmp_path: Path) -> None:
    bad = tmp_path / "cal.yaml"
    bad.write_text("cameras: {}\n")
    runner = CliRunner()
    sweep = ["sweep", "fence1", "--out", str(tmp_path / "s"), "--n", "1"]
    for args in (sweep, ["bench", "fence1", "--methods", "ours", "--out", str(tmp_path / "b")]):
        result = runner.invoke(app, [*args, "--calibration", str(bad)])
        assert result.exit_code == 2 and "is not a calibration file" in result.stderr, result.stderr
