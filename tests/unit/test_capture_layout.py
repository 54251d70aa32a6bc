"""The capture folder (docs/capture.md): written and read back bit for bit; every bad folder one CaptureError line."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from typer.testing import CliRunner

from cell.cli import app
from cell.errors import CaptureError, UsageError
from cell.geometry import look_at, pose_from_xyz_rpy
from cell.recorded import read_capture, write_capture
from cell.recorded.cell_file import replay_scenario
from cell.recorded.layout import INDEX, RecordedCapture
from cell.station.recorded import RecordedStation
from cell.types import Box, CameraIntrinsics, DepthImage, Part
from cell.weldmap import read_map

REPO = Path(__file__).resolve().parents[2]
UNIT = 0.0001  # [m] the simulated D415's depth unit
X_WR = pose_from_xyz_rpy([0.15, -1.05, 0.9], [0.0, 0.0, 0.3])


def images(
    rng: np.random.Generator, *, on_grid: bool = True, names: tuple[str, str] = ("left", "hand")
) -> dict[str, DepthImage]:
    """Two small cameras (fixed, eye-in-hand) with depths on the 0.1 mm grid as the noise model leaves them."""
    out = {}
    for name, mount, eye in ((names[0], "fixed", [-0.7, 0.0, 2.0]), (names[1], "eye_in_hand", [0.15, -0.45, 2.05])):
        intr = CameraIntrinsics(32, 24, 30.5, 30.5, 15.5, 11.5)
        z = rng.uniform(0.8, 2.5, (24, 32))
        z = np.round(z / UNIT) * UNIT if on_grid else z  # what cell.sim.noise does, float64 then float32
        z[rng.random(z.shape) < 0.1] = 0.0  # invalid pixels
        out[name] = DepthImage(name, z.astype(np.float32), intr, look_at(eye, [0.15, 0.0, 0.95]), mount)
    return out


def parts() -> tuple[Part, ...]:
    return (Part("TOP_RAIL", Box(pose_from_xyz_rpy([0.1, 0.3, 0.95], [0, 0, 0.0066]), np.array([1.42, 0.1, 0.099]))),)


def test_a_capture_reads_back_bit_identical(tmp_path: Path) -> None:
    imgs = images(np.random.default_rng(1))
    X_RF = pose_from_xyz_rpy([0.0, 0.6, 1.1], [3.1, 0.0, 0.0])
    folder = write_capture(tmp_path / "cap", imgs, X_WR, truth_parts_W=parts(), flange={"hand": X_RF})
    rec = read_capture(folder)
    assert list(rec.images) == ["left", "hand"]
    for name, im in imgs.items():
        back = rec.images[name]
        assert back.depth.dtype == np.float32 and np.array_equal(back.depth, im.depth)
        assert np.array_equal(back.X_WC, im.X_WC) and back.intrinsics == im.intrinsics and back.mount == im.mount
    assert np.array_equal(rec.X_WR, X_WR) and np.array_equal(rec.X_RF["hand"], X_RF) and "left" not in rec.X_RF
    assert rec.truth_parts_W is not None and rec.truth_parts_W[0].name == "TOP_RAIL"
    assert np.array_equal(rec.truth_parts_W[0].box.X_AB, parts()[0].box.X_AB)
    assert isinstance(rec, RecordedCapture) and np.allclose(rec.X_RC("left"), np.linalg.inv(X_WR) @ imgs["left"].X_WC)
    assert rec.cell_yaml is None and rec.provenance is not None and rec.provenance["tool"] == "cell"
    png = Image.open(folder / "left.depth.png")
    assert png.mode == "I;16" and png.size == (32, 24)  # a 16-bit PNG any viewer or ROS tool reads
    index = json.loads((folder / INDEX).read_text())
    info = index["cameras"][0]["camera_info"]
    assert info["distortion_model"] == "plumb_bob" and info["D"] == [0.0] * 5 and info["K"][2] == 15.5
    assert np.allclose(np.array(index["cameras"][0]["X_RC"]), np.linalg.inv(X_WR) @ imgs["left"].X_WC)


def test_depths_off_the_grid_or_too_far_are_said_not_hidden(tmp_path: Path) -> None:
    imgs = images(np.random.default_rng(2), on_grid=False)
    far = np.array(imgs["left"].depth)
    far[0, :3] = 7.0  # beyond 65535 units of 0.1 mm
    imgs["left"] = DepthImage("left", far, imgs["left"].intrinsics, imgs["left"].X_WC)
    said: list[str] = []
    rec = read_capture(write_capture(tmp_path, imgs, X_WR, warn=said.append))
    assert any("left" in s and "replay differs" in s for s in said) and any("3 depths beyond" in s for s in said)
    back, orig = rec.images["left"].depth, imgs["left"].depth
    assert np.all(back[0, :3] == 0.0)
    valid = (orig > 0) & (orig < 6.5)
    assert np.max(np.abs(back[valid] - orig[valid])) <= UNIT / 2 + 1e-7  # half a unit at most (float32)
    assert not np.array_equal(back[valid], orig[valid])


def _edit(folder: Path, change: object) -> None:
    data = json.loads((folder / INDEX).read_text())
    change(data)  # type: ignore[operator]
    (folder / INDEX).write_text(json.dumps(data))


def _bad_png(folder: Path, mode: str) -> None:
    if mode == "8bit":
        Image.fromarray(np.zeros((24, 32), np.uint8)).save(folder / "left.depth.png")
    elif mode == "size":
        Image.fromarray(np.zeros((12, 16), np.uint16)).save(folder / "left.depth.png")
    elif mode == "text":
        (folder / "left.depth.png").write_text("not an image")
    else:
        (folder / "left.depth.png").unlink()


BAD = {
    "no index": (lambda d: (d / INDEX).unlink(), "capture index"),
    "index not JSON": (lambda d: (d / INDEX).write_text("{"), "not JSON"),
    "unknown version": (lambda d: _edit(d, lambda j: j.update(version=2)), "version 2; valid: 1"),
    "unknown format": (lambda d: _edit(d, lambda j: j.update(format="x")), "format 'x'"),
    "png missing": (lambda d: _bad_png(d, "missing"), "is missing"),
    "8-bit png": (lambda d: _bad_png(d, "8bit"), "pixel mode L"),
    "not a png": (lambda d: _bad_png(d, "text"), "not an image"),
    "size vs CameraInfo": (lambda d: _bad_png(d, "size"), "16 x 12 px, its CameraInfo says 32 x 24"),
    "distortion": (
        lambda d: _edit(d, lambda j: j["cameras"][0]["camera_info"].update(D=[0.1, 0, 0, 0, 0])),
        "distortion",
    ),
    "bad mount": (lambda d: _edit(d, lambda j: j["cameras"][0].update(mount="tripod")), "mount 'tripod'"),
    "no pose": (lambda d: _edit(d, lambda j: j["cameras"][0].pop("X_RC")), "X_RC is missing"),
    "X_WC off": (lambda d: _edit(d, lambda j: j["cameras"][0]["X_WC"][0].__setitem__(3, 9.0)), "disagrees"),
    "truth missing": (lambda d: (d / "truth.json").unlink(), "truth file"),
}


@pytest.mark.parametrize("case", list(BAD))
def test_a_bad_folder_is_one_line_naming_what_is_wrong(tmp_path: Path, case: str) -> None:
    folder = write_capture(tmp_path / "cap", images(np.random.default_rng(3)), X_WR, truth_parts_W=parts())
    spoil, words = BAD[case]
    spoil(folder)
    with pytest.raises(CaptureError) as e:
        read_capture(folder)
    assert words in e.value.message and "\n" not in e.value.message and e.value.exit_code == 16


def test_the_recorded_station_serves_the_images_and_refuses_to_move(tmp_path: Path) -> None:
    imgs = images(np.random.default_rng(4))
    station = RecordedStation.open(write_capture(tmp_path, imgs, X_WR))
    assert station.arm is None and station.truth() is None
    assert np.array_equal(station.capture()["hand"].depth, imgs["hand"].depth)
    with pytest.raises(UsageError, match="cannot move the arm"):
        station.execute([0.0], [[0.0] * 6], [False])
    with pytest.raises(UsageError, match="cannot move the arm"):
        station.capture_eye_in_hand("hand")


def test_a_capture_without_its_cell_needs_map_and_place_and_gets_a_cell_around_them(tmp_path: Path) -> None:
    rec = read_capture(write_capture(tmp_path, images(np.random.default_rng(5)), X_WR))
    with pytest.raises(UsageError, match="--map and --place"):
        replay_scenario(rec)
    X_RM = pose_from_xyz_rpy([-0.7, 0.65, 0.0], [0.0, 0.0, 0.0])
    scn = replay_scenario(rec, map_path=REPO / "maps" / "fence1.dxf", X_RM=X_RM)
    assert np.allclose(scn.X_WM, X_WR @ X_RM) and np.allclose(scn.X_WR, X_WR)
    assert set(scn.cameras) == {"left", "hand"} and scn.cameras["hand"].mount == "eye_in_hand"
    lowest = min(p.transformed(scn.X_WM).vertices()[:, 2].min() for p in read_map(scn.map_path).parts)
    assert abs(scn.table.top_z - lowest) < 1e-9  # the part rests on the table
    assert scn.perception.workspace.min_m[2] > scn.table.top_z  # the table is cropped away


def test_detect_on_a_bad_capture_is_one_line_and_its_exit_code(tmp_path: Path) -> None:
    runner = CliRunner()
    result = runner.invoke(app, ["detect", "--capture", str(tmp_path / "nowhere")])
    assert result.exit_code == 16 and "does not exist" in result.stderr and "Traceback" not in result.stderr
    write_capture(tmp_path / "cap", images(np.random.default_rng(6)), X_WR)
    result = runner.invoke(app, ["detect", "--capture", str(tmp_path / "cap")])
    assert result.exit_code == 2 and "--map and --place" in result.stderr
    result = runner.invoke(app, ["detect", "fence1", "--capture", str(tmp_path / "cap")])
    assert result.exit_code == 2 and "both given" in result.stderr
    result = runner.invoke(app, ["detect"])
    assert result.exit_code == 2


def test_the_cell_file_gives_back_the_scenario_and_takes_a_new_placement(tmp_path: Path) -> None:
    from cell import scenario as sc
    from cell.recorded.cell_file import cell_yaml

    fence1 = sc.load("fence1")
    imgs = images(np.random.default_rng(8), names=("cam_left", "eye_in_hand"))
    folder = write_capture(tmp_path, imgs, fence1.X_WR, cell_yaml=cell_yaml(fence1), map_file=fence1.map_path)
    assert (folder / "fence1.dxf").read_bytes() == fence1.map_path.read_bytes()  # the map beside cell.yaml
    rec = read_capture(folder)
    scn = replay_scenario(rec)
    assert "\nsimulation:" not in (rec.cell_yaml or "") and scn.map_path == (folder / "fence1.dxf").resolve()
    told = fence1.model_dump(exclude={"simulation", "base_dir", "map"})
    assert (
        scn.model_dump(exclude={"simulation", "base_dir", "map"}) == told and scn.X_WM.tolist() == fence1.X_WM.tolist()
    )
    X_RM = pose_from_xyz_rpy([-0.69, 0.66, 0.0], [0.0, 0.0, 0.02])
    moved = replay_scenario(rec, X_RM=X_RM)
    assert np.allclose(moved.X_WM, fence1.X_WR @ X_RM, atol=1e-12)
    other = read_capture(write_capture(tmp_path / "b", rec.images, X_WR, cell_yaml=rec.cell_yaml))
    with pytest.raises(CaptureError, match="X_WR disagrees"):  # cell.yaml's robot is not where the capture says
        replay_scenario(other, map_path=fence1.map_path)
    stranger = read_capture(
        write_capture(tmp_path / "c", images(np.random.default_rng(9)), fence1.X_WR, cell_yaml=rec.cell_yaml)
    )
    with pytest.raises(CaptureError, match="left, hand of the capture are not in its cameras"):
        replay_scenario(stranger, map_path=fence1.map_path)  # a camera the cell does not know: no calibration, refused


def test_what_cannot_be_read_back_is_not_written(tmp_path: Path) -> None:
    imgs = images(np.random.default_rng(10))
    odd = imgs["left"]
    with pytest.raises(CaptureError, match="mount"):
        write_capture(tmp_path / "a", {"left": DepthImage("left", odd.depth, odd.intrinsics, odd.X_WC, "tripod")}, X_WR)
    with pytest.raises(CaptureError, match="cannot name a file"):
        write_capture(tmp_path / "b", {"left/../x": odd}, X_WR)
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists()
