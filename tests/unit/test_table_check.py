"""Every run's own check of a camera's depth scale and focal length on the table's top (no board in view): exact
on a synthetic plane, a scale or focal error found with its sigma and flagged beyond the tolerance, square-on views
never flagged on the focal length they cannot see, the told pose's uncertainty widening the bounds; the simulated
sensor's errors found in rendered images."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from cell import scenario as scn
from cell.geometry import look_at, make_pose
from cell.perception.table_check import check_on_table
from cell.sim import SimCell
from cell.types import CameraIntrinsics, DepthImage

TOP = 0.9
LO, HI = (-1.0, -0.6), (1.0, 0.6)
K = CameraIntrinsics(640, 480, 554.3, 554.3, 319.5, 239.5)


def _image(
    eye: tuple[float, float, float], depth_scale: float = 1.0, focal_scale: float = 1.0, noise_m: float = 0.0
) -> DepthImage:
    """A camera at ``eye`` looking at the table's centre; its depth of the plane z = TOP, as a sensor whose depth
    and focal length are the given scales off the stated K."""
    X_WC = look_at(eye, (0.0, 0.0, TOP), (0.0, 1.0, 0.0))
    v, u = np.mgrid[0 : K.height, 0 : K.width].astype(float)
    f = K.fx * focal_scale
    x, y = (u - K.cx) / f, (v - K.cy) / f
    R, c = X_WC[:3, :3], X_WC[:3, 3]
    z = (TOP - c[2]) / (R[2, 0] * x + R[2, 1] * y + R[2, 2])
    z = np.where(z > 0, z, 0.0) * depth_scale
    z = z + np.random.default_rng(1).normal(0.0, noise_m, z.shape) * (z > 0)
    return DepthImage("cam", z.astype(np.float32), K, X_WC)


@pytest.mark.parametrize("ds, fs", [(1.0, 1.0), (1.008, 1.0), (1.0, 0.99), (0.995, 1.006)])
def test_the_table_tells_the_depth_scale_and_the_focal_length(ds: float, fs: float) -> None:
    image = _image((1.0, 0.0, 2.0), ds, fs, noise_m=0.001)
    c = check_on_table(image, TOP, LO, HI, (0.0, 0.0), (0.005, 0.005))
    assert c is not None and c.pixels > 2000
    assert abs(c.depth_scale - ds) < max(4.0 * c.depth_scale_sigma, 2e-4)
    assert abs(c.focal_scale - fs) < max(4.0 * c.focal_scale_sigma, 5e-4)
    assert ("depth_scale" in c.flags) == (abs(ds - 1.0) > 0.0055)
    assert ("focal" in c.flags) == (abs(fs - 1.0) > 0.0055)
    assert (c.reason() == "") == (not c.flags)


def test_a_square_on_view_does_not_pretend_to_know_its_focal_length() -> None:
    image = _image((0.0, 0.0001, 2.0), focal_scale=1.02, noise_m=0.001)  # looking straight down
    c = check_on_table(image, TOP, LO, HI, (0.0, 0.0), (0.005, 0.005))
    assert c is not None and abs(c.depth_scale - 1.0) < 1e-3
    assert "focal" not in c.flags and c.focal_scale_sigma > 0.01  # its slope is nil: unknown, not flagged


def test_the_told_poses_uncertainty_widens_the_bounds_and_a_bump_is_flagged() -> None:
    image = _image((1.0, 0.0, 2.0), noise_m=0.001)
    exact = check_on_table(image, TOP, LO, HI, (0.0, 0.0), (0.005, 0.005))
    loose = check_on_table(image, TOP, LO, HI, (0.001, np.radians(0.1)), (0.005, 0.005))
    assert exact is not None and loose is not None
    assert loose.depth_scale_sigma > 3.0 * exact.depth_scale_sigma and loose.focal_scale_sigma > 1e-3
    bumped = replace(image, X_WC=make_pose(p=[0.0, 0.0, 0.02]) @ image.X_WC)
    c = check_on_table(bumped, TOP, LO, HI, (0.001, np.radians(0.1)), (0.005, 0.005))
    assert c is not None and c.flags  # 20 mm off its told pose: the table says the camera is not as told
    assert "or its pose is that far off" in c.reason()


def test_too_little_table_in_view_gives_no_check() -> None:
    image = _image((1.0, 0.0, 2.0))
    assert check_on_table(image, TOP, (0.0, 0.0), (0.05, 0.05), (0.0, 0.0), (0.005, 0.005)) is None


TINY = """
name: tiny-sensor
seed: 2
simulation: {noise: realistic}
map: {file: dummy.dxf}
table: {center_m: [0.0, 0.0, 0.85], size_m: [1.6, 1.2, 0.1]}
cameras:
  skewed:
    eye_m: [0.9, 0.0, 1.9]
    target_m: [0.0, 0.0, 0.9]
    resolution: [424, 240]
    sensor_error: {depth_scale: 1.01, focal_scale: 0.99}
  good:
    eye_m: [-0.9, 0.0, 1.9]
    target_m: [0.0, 0.0, 0.9]
    resolution: [424, 240]
perception:
  workspace: {min_m: [-1.0, -1.0, 0.8], max_m: [1.0, 1.0, 1.5]}
"""


def test_the_simulated_sensors_errors_are_found_in_its_rendered_image(tmp_path: Path) -> None:
    (tmp_path / "dummy.dxf").write_text("not read by this test\n")
    s = scn.from_yaml(TINY, base_dir=tmp_path)
    with SimCell(s, ()) as sim:
        images = {name: sim.capture(name) for name in s.cameras}
    assert images["skewed"].intrinsics == images["good"].intrinsics  # both told the stated model
    found = {n: check_on_table(im, s.table.top_z, LO, HI, (0.0, 0.0), (0.005, 0.005)) for n, im in images.items()}
    off, good = found["skewed"], found["good"]
    assert off is not None and good is not None
    assert abs(off.depth_scale - 1.01) < 1e-3 and abs(off.focal_scale - 0.99) < 2e-3
    assert set(off.flags) == {"depth_scale", "focal"} and good.flags == ()
    assert abs(good.depth_scale - 1.0) < 1e-3 and abs(good.focal_scale - 1.0) < 2e-3


def test_a_flagged_camera_is_lost_with_its_reason_and_its_figures_kept() -> None:
    from test_perception import SPEC, X_WR, paper_images

    from cell.perception.perceive import perceive_then
    from cell.perception.table_check import SensorCheck

    images = paper_images()
    checks = {
        "cam_left": SensorCheck("cam_left", 5000, 1.012, 0.0002, 1.0, 0.001, ("depth_scale",)),
        "cam_right": SensorCheck("cam_right", 5000, 1.0001, 0.0002, 1.0, 0.001, ()),
    }
    done = perceive_then(images, X_WR, SPEC, None, lambda cloud, proceed: len(cloud), None, checks)
    p = done.perceived
    assert p.lost == ("cam_left",) and "the table plane says its depth reads 1.0120" in p.lost_reasons["cam_left"]
    assert len(p.clouds["cam_left"]) == 0 and set(p.sensor_checks) == {"cam_left", "cam_right"}
    assert done.answer == len(p.registered) and done.answer > 0
