"""The simulated cell (cell.sim.cell.SimCell) on a tiny inline scenario: one box on a table."""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from pinhole import deproject, pixel_rays_W

from cell import scenario as scn
from cell.errors import SensorError
from cell.geometry import FloatArray, invert, make_pose, pose_from_xyz_rpy, transform_points
from cell.sim import SimCell
from cell.sim.noise import sigma_z
from cell.types import Box, DepthImage, Part

TABLE_TOP = 0.9  # [m]
BOX = Box(pose_from_xyz_rpy([0.05, 0.02, 0.95], [0.0, 0.0, math.radians(20.0)]), np.array([0.2, 0.1, 0.1]))
BOX_TOP = 1.0  # [m]

TINY = """
name: tiny
seed: 7
simulation: {{noise: {noise}}}
map: {{file: dummy.dxf}}
table: {{center_m: [0.0, 0.0, 0.85], size_m: [1.2, 0.8, 0.1]}}
cameras:
  oblique:
    eye_m: [0.9, 0.0, 1.8]
    target_m: [0.0, 0.0, 0.9]
    resolution: [320, 240]
    extrinsic_error: {{translation_mm: {t_mm}, rotation_deg: {r_deg}}}
  odd:
    eye_m: [-0.5, 0.45, 1.6]
    target_m: [0.05, 0.0, 0.9]
    resolution: [161, 97]
    hfov_deg: 50
perception:
  workspace: {{min_m: [-1.0, -1.0, 0.9], max_m: [1.0, 1.0, 1.5]}}
"""


def tiny_scenario(tmp_path: Path, noise: str = "none", t_mm: float = 0.0, r_deg: float = 0.0) -> scn.Scenario:
    (tmp_path / "dummy.dxf").write_text("not read by these tests\n")
    return scn.from_yaml(TINY.format(noise=noise, t_mm=t_mm, r_deg=r_deg), base_dir=tmp_path)


@pytest.fixture
def noiseless(tmp_path: Path) -> Iterator[SimCell]:
    with SimCell(tiny_scenario(tmp_path), [Part("BOX", BOX)]) as sim:
        yield sim


def _horizontal_hit(image: DepthImage, z_plane: float) -> tuple[FloatArray, FloatArray]:
    """Where each pixel's ray meets the plane z = z_plane [m]: analytic depth (H, W) and point (H, W, 3)."""
    rays = pixel_rays_W(image)
    eye = image.X_WC[:3, 3]
    depth = (z_plane - eye[2]) / rays[..., 2]
    return depth, eye + depth[..., None] * rays


@pytest.mark.parametrize("camera", ["oblique", "odd"])
def test_noiseless_render_deprojects_onto_box_top_and_table_top(noiseless: SimCell, camera: str) -> None:
    image = noiseless.capture(camera)
    spec = noiseless.scenario.cameras[camera]
    assert image.depth.shape == (spec.resolution[1], spec.resolution[0])
    assert np.allclose(image.X_WC, spec.X_WC)
    p_W = deproject(image)

    # Pixels whose ray hits the box top at least 3 mm inside its edges.
    depth_top, hit_top = _horizontal_hit(image, BOX_TOP)
    top_inner = Box(BOX.X_AB, BOX.size - [0.006, 0.006, -0.01])
    on_top = top_inner.contains(hit_top.reshape(-1, 3)).reshape(depth_top.shape)
    assert on_top.sum() > 50
    err_top = np.linalg.norm(p_W[on_top] - hit_top[on_top], axis=-1)
    assert err_top.max() < 1e-4  # [m]

    # Pixels whose ray hits the table top well inside it and far from the box (no occlusion, no shadow).
    depth_table, hit_table = _horizontal_hit(image, TABLE_TOP)
    xy = hit_table[..., :2]
    inside = np.all(np.abs(xy) < [0.59, 0.39], axis=-1)
    far_from_box = np.linalg.norm(xy - BOX.center[:2], axis=-1) > 0.3
    on_table = inside & far_from_box & (depth_table > 0)
    assert on_table.sum() > 1000
    err_table = np.linalg.norm(p_W[on_table] - hit_table[on_table], axis=-1)
    assert err_table.max() < 1e-4  # [m]


def test_box_appears_where_it_should(noiseless: SimCell) -> None:
    image = noiseless.capture("oblique")
    p_W = deproject(image)[image.depth > 0]
    above_table = p_W[:, 2] > TABLE_TOP + 0.002
    assert above_table.sum() > 500
    # everything above the table is the box (within a fraction of a pixel footprint)
    assert np.all(BOX.contains(p_W[above_table], margin=0.002))
    # and the box is seen: its top and the faces turned to the camera are covered by points
    assert np.sum(np.abs(p_W[above_table, 2] - BOX_TOP) < 1e-4) > 100
    p_B = transform_points(invert(BOX.X_AB), p_W[above_table])
    assert np.sum(np.abs(p_B[:, 0] - 0.1) < 1e-4) > 20  # the +x face, turned towards the camera at x = 0.9
    # the ground (z = 0) is visible past the table and lies where it should
    ground = p_W[:, 2] < 0.5
    assert ground.sum() > 100 and np.all(np.abs(p_W[ground, 2]) < 1e-3)


def test_explicit_pose_renders_from_there(noiseless: SimCell) -> None:
    # Straight down from 0.5 m above the box centre (optical z = -world z, x along world x).
    eye = BOX.center + np.array([0.0, 0.0, 0.45])
    X_WC = make_pose(np.diag([1.0, -1.0, -1.0]), eye)
    image = noiseless.capture("oblique", X_WC=X_WC)
    assert np.array_equal(image.X_WC, X_WC)
    h, w = image.depth.shape
    centre = image.depth[h // 2 - 2 : h // 2 + 2, w // 2 - 2 : w // 2 + 2]
    assert np.allclose(centre, eye[2] - BOX_TOP, atol=1e-4)


def test_noisy_images_are_seeded(tmp_path: Path) -> None:
    scenario = tiny_scenario(tmp_path, noise="realistic")
    parts = [Part("BOX", BOX)]
    with SimCell(scenario, parts) as a, SimCell(scenario, parts) as b:
        first_a, first_b = a.capture("oblique"), b.capture("oblique")
        assert np.array_equal(first_a.depth, first_b.depth)
        # the sensor's stream continues: a second capture has new noise
        assert not np.array_equal(a.capture("oblique").depth, first_a.depth)
    with SimCell(scenario.model_copy(update={"seed": 8}), parts) as c:
        other = c.capture("oblique")
    assert not np.array_equal(other.depth, first_a.depth)
    with SimCell(scenario.with_noise("none"), parts) as clean:
        truth = clean.capture("oblique").depth
    both = (truth > 0) & (first_a.depth > 0)
    spec = scenario.cameras["oblique"]
    sigma = sigma_z(truth[both], spec.noise, first_a.intrinsics.fx)
    z_score = (first_a.depth[both] - truth[both]) / sigma
    # the median of |N(0, 1)| is 0.6745: the errors have the model's sigma
    assert np.median(np.abs(z_score)) == pytest.approx(0.6745, rel=0.05)
    assert np.all(first_a.depth[truth == 0] == 0)  # no depth appears out of nothing


def test_believed_pose_carries_the_extrinsic_error(tmp_path: Path) -> None:
    scenario = tiny_scenario(tmp_path, t_mm=0.8, r_deg=0.1)
    with SimCell(scenario, [Part("BOX", BOX)]) as sim:
        image = sim.capture("oblique")
        again = sim.capture("oblique")
        true_X = scenario.cameras["oblique"].X_WC
        assert np.linalg.norm(image.X_WC[:3, 3] - true_X[:3, 3]) == pytest.approx(0.0008, abs=1e-12)
        R = true_X[:3, :3].T @ image.X_WC[:3, :3]
        assert math.degrees(math.acos(np.clip((np.trace(R) - 1) / 2, -1, 1))) == pytest.approx(0.1, rel=1e-6)
        assert np.array_equal(again.X_WC, image.X_WC)  # a calibration error is fixed, not drawn per capture
        assert np.array_equal(sim.capture("odd").X_WC, scenario.cameras["odd"].X_WC)  # no error there


def test_unknown_camera_and_closed_cell_raise_sensor_error(tmp_path: Path) -> None:
    sim = SimCell(tiny_scenario(tmp_path), [Part("BOX", BOX)])
    with pytest.raises(SensorError, match="oblique, odd"):
        sim.capture("cam_top")
    assert set(sim.capture_all()) == {"oblique", "odd"}
    assert set(sim.bodies) == {"ground", "table", "BOX"}
    with pytest.raises(KeyError, match="BOX"):
        sim.body_id("box")
    sim.close()
    sim.close()  # idempotent
    with pytest.raises(SensorError, match="closed"):
        sim.capture("oblique")


def test_two_cells_do_not_share_a_client(tmp_path: Path) -> None:
    scenario = tiny_scenario(tmp_path)
    with SimCell(scenario, [Part("BOX", BOX)]) as with_box, SimCell(scenario, []) as empty:
        assert with_box.client.getNumBodies() == 3 and empty.client.getNumBodies() == 2
        assert "BOX" not in empty.bodies
        assert not np.array_equal(with_box.capture("oblique").depth, empty.capture("oblique").depth)
