"""``cell calibrate`` on fence1's cell, the real pipeline headless: one fixed camera from a few board images is
measured within its stated bounds, its file read back by a run command moves what the cell is told; a board printed
5 % larger than stated is refused with its reason (exit 17); the images kept as a capture folder solve again
without the simulator. Few images keep it to seconds."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml
from PIL import Image
from typer.testing import CliRunner

from cell import scenario as sc
from cell.calibrate.file import apply, read
from cell.cli import app
from cell.cli.common import load_scenario
from cell.geometry import invert

runner = CliRunner()


def _scenario_file(tmp_path: Path, name: str, **simulation: object) -> Path:
    """fence1 with a short calibration (6 images fitted, 2 held out) and ``simulation`` changes, as a YAML file."""
    doc = yaml.safe_load((sc.SCENARIO_DIR / "fence1.yaml").read_text(encoding="utf-8"))
    doc["calibration"] = {"poses": 6, "held_out": 2}
    doc["simulation"].update(simulation)
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(doc), encoding="utf-8")
    return path


def test_a_fixed_camera_is_measured_and_a_board_of_the_wrong_size_is_refused(tmp_path: Path) -> None:
    scenario = _scenario_file(tmp_path, "short")
    cal = tmp_path / "cal.yaml"
    folder = tmp_path / "capture"
    args = ["calibrate", str(scenario), "--cameras", "cam_right", "--out", str(cal), "--save-capture", str(folder)]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.stderr
    entry = read(cal)["cameras"]["cam_right"]
    err, stated = entry["truth_error"], entry["calibration"]
    assert err["translation_mm"] < 1.0 and err["rotation_deg"] < 0.1  # 6 images: the worst-case bar of 12
    assert err["translation_mm"] < 3.0 * stated["translation_mm"] and err["rotation_deg"] < 3.0 * stated["rotation_deg"]
    assert entry["held_out"]["images"] == 2 and entry["held_out"]["reprojection_px"] < 1.0
    assert entry["intrinsics"]["flags"] == [] and abs(entry["intrinsics"]["depth_scale"] - 1.0) < 0.005
    calibrated = load_scenario(str(scenario), cal)  # what --calibration does to a run's scenario
    X_RC = calibrated.cameras["cam_right"].measured
    assert X_RC is not None
    X_true = invert(calibrated.X_WR) @ calibrated.cameras["cam_right"].X_WC
    assert np.linalg.norm(X_RC.X[:3, 3] - X_true[:3, 3]) < 1e-3
    assert apply(calibrated, read(cal)).cameras["cam_right"].calibration.translation_mm == stated["translation_mm"]

    # The same images and flange poses from the capture folder, no simulator: the same pose, no truth to judge it by.
    again = tmp_path / "again.yaml"
    result = runner.invoke(app, ["calibrate", "--capture", str(folder), "--held-out", "2", "--out", str(again)])
    assert result.exit_code == 0, result.stderr
    replayed = read(again)["cameras"]["cam_right"]
    assert "truth_error" not in replayed
    assert np.allclose(replayed["measured"]["xyz_m"], entry["measured"]["xyz_m"], atol=2e-6)

    # A camera that sees the board in none of its images (their colour grey: a lens cap, a camera looking away).
    for png in folder.glob("cam_right_[0-9][0-9][0-9].png"):
        with Image.open(png) as im:
            size = im.size
        Image.new("RGB", size, (128, 128, 128)).save(png, format="PNG")
    result = runner.invoke(app, ["calibrate", "--capture", str(folder), "--held-out", "2", "--out", str(again)])
    assert result.exit_code == 17, result.stderr
    assert "cam_right: the board is found in 0 of the capture's images" in result.stderr

    big = _scenario_file(tmp_path, "big-board", board_scale=1.05)
    result = runner.invoke(app, ["calibrate", str(big), "--cameras", "cam_right", "--poses", "4", "--out", str(cal)])
    assert result.exit_code == 17, result.stderr
    assert "farther than its stated size" in result.stderr and "square_mm" in result.stderr
