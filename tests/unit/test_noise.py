"""The depth-sensor model (cell.sim.noise) against its own formulas (docs/reference.md section 2)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cell.geometry import FloatArray
from cell.scenario import ExtrinsicErrorSpec, NoiseSpec
from cell.sim.noise import apply_noise, incidence_angles, perturb_pose, sigma_z
from cell.types import CameraIntrinsics

# A 320 x 240 crop of a D415 (1280 x 720, HFOV 65 deg): same focal length, so the same sigma_z.
D415_FX = 0.5 * 1280 / math.tan(math.radians(65.0) / 2.0)  # [px]
CROP = CameraIntrinsics(320, 240, D415_FX, D415_FX, 159.5, 119.5)
NOISELESS = NoiseSpec(subpixel_px=0.0, disparity_step_px=0.0, depth_unit_m=0.0)  # only dropouts and edges


def _wall(z: float, intr: CameraIntrinsics = CROP) -> FloatArray:
    """A fronto-parallel wall at depth z [m]."""
    return np.full((intr.height, intr.width), z)


def test_sigma_z_matches_the_published_figures() -> None:
    d415 = NoiseSpec(baseline_m=0.055)
    assert sigma_z([1.0, 1.5, 2.0], d415, D415_FX) * 1e3 == pytest.approx([1.45, 3.3, 5.8], rel=0.02)
    d435 = NoiseSpec(baseline_m=0.050)
    fx_d435 = 0.5 * 848 / math.tan(math.radians(87.0) / 2.0)
    assert sigma_z([1.0, 1.5, 2.0], d435, fx_d435) * 1e3 == pytest.approx([3.6, 8.1, 14.3], rel=0.02)
    kinect = NoiseSpec(model="structured_light")
    assert sigma_z(1.0, kinect, 580.0) == pytest.approx(0.0012 + 0.0019 * 0.36)
    # the incidence term: grows with the angle, 0.0001/sqrt(z) * theta^2 / (pi/2 - theta)^2
    theta = math.radians(60.0)
    extra = 0.0001 * theta**2 / (math.pi / 2 - theta) ** 2
    assert sigma_z(1.0, kinect, 580.0, theta) == pytest.approx(0.0012 + 0.0019 * 0.36 + extra)
    assert np.all(sigma_z([1.0, 2.0], NoiseSpec(model="none"), 580.0) == 0.0)


@pytest.mark.parametrize("z", [1.0, 1.5])
def test_active_stereo_std_matches_sigma_z_on_a_flat_wall(z: float) -> None:
    spec = NoiseSpec()
    noisy = apply_noise(_wall(z), CROP, spec, np.random.default_rng(1))
    assert noisy.dtype == np.float32 and noisy.shape == (240, 320)
    err = noisy.astype(float) - z
    expected = float(sigma_z(z, spec, CROP.fx))
    assert np.all(noisy > 0)  # a flat wall seen head-on has no edges and no grazing pixels
    assert err.std() == pytest.approx(expected, rel=0.05)
    assert abs(err.mean()) < 0.1 * expected


def test_structured_light_std_matches_sigma_z_on_a_flat_wall() -> None:
    spec = NoiseSpec(model="structured_light")
    noisy = apply_noise(_wall(1.5), CROP, spec, np.random.default_rng(2))
    assert (noisy - 1.5).std() == pytest.approx(float(sigma_z(1.5, spec, CROP.fx)), rel=0.05)


def test_disparity_and_depth_are_quantised() -> None:
    # Disparity steps of 1/32 px: every output depth maps back to a multiple of the step.
    spec = NoiseSpec(depth_unit_m=0.0)
    noisy = apply_noise(_wall(1.0), CROP, spec, np.random.default_rng(3)).astype(float)
    disparity = CROP.fx * spec.baseline_m / noisy
    steps = disparity / spec.disparity_step_px
    assert np.max(np.abs(steps - np.round(steps))) < 1e-3
    levels = np.unique(noisy)
    # neighbouring depth levels at 1 m are z^2 * step / (fx B) = 0.57 mm apart
    gap = 1.0 * spec.disparity_step_px / (CROP.fx * spec.baseline_m)
    assert np.diff(levels).min() == pytest.approx(gap, rel=0.05)
    # Depth unit 1 mm: every value is a whole number of millimetres.
    mm = apply_noise(_wall(1.0), CROP, NoiseSpec(depth_unit_m=0.001), np.random.default_rng(3)).astype(float)
    assert np.max(np.abs(mm * 1000 - np.round(mm * 1000))) < 1e-3
    assert len(np.unique(mm)) > 5


def test_same_seed_same_image_other_seed_other_image() -> None:
    spec = NoiseSpec()
    a = apply_noise(_wall(1.2), CROP, spec, np.random.default_rng(42))
    b = apply_noise(_wall(1.2), CROP, spec, np.random.default_rng(42))
    c = apply_noise(_wall(1.2), CROP, spec, np.random.default_rng(43))
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


def test_none_is_identity_and_invalid_pixels_stay_invalid() -> None:
    rng = np.random.default_rng(5)
    depth = rng.uniform(0.5, 2.0, (240, 320))
    depth[rng.random(depth.shape) < 0.2] = 0.0
    out = apply_noise(depth, CROP, NoiseSpec(model="none"), rng)
    assert out.dtype == np.float32
    assert np.array_equal(out, depth.astype(np.float32))
    for model in ("active_stereo", "structured_light"):
        noisy = apply_noise(depth, CROP, NoiseSpec(model=model), rng)
        assert np.all(noisy[depth == 0] == 0)


def _tilted_plane(normal: FloatArray, point: FloatArray, intr: CameraIntrinsics) -> tuple[FloatArray, FloatArray]:
    """Depth image (H, W) [m] of the plane through ``point`` with unit ``normal`` (optical frame), and the
    true incidence angle per pixel [rad]; rays missing the plane (or beyond 20 m): 0 / NaN."""
    u, v = np.meshgrid(np.arange(intr.width), np.arange(intr.height))
    rays = np.stack([(u - intr.cx) / intr.fx, (v - intr.cy) / intr.fy, np.ones(u.shape)], axis=-1)
    denom = rays @ normal
    with np.errstate(divide="ignore"):
        z = np.where(np.abs(denom) > 1e-12, (point @ normal) / denom, -1.0)
    hit = (z > 0) & (z < 20.0)
    cos = np.abs(denom) / np.linalg.norm(rays, axis=-1)
    theta = np.where(hit, np.arccos(np.clip(cos, 0.0, 1.0)), np.nan)
    return np.where(hit, z, 0.0), theta


def test_incidence_angles_from_the_depth_image_are_exact_on_a_plane() -> None:
    a = math.radians(70.0)
    depth, theta = _tilted_plane(np.array([math.sin(a), 0.0, -math.cos(a)]), np.array([0.0, 0.0, 1.0]), CROP)
    est = incidence_angles(depth, CROP)
    ok = depth > 0
    assert np.nanmax(np.abs(est[ok] - theta[ok])) < 1e-6
    assert np.all(np.isnan(est[~ok]))


def test_grazing_pixels_drop_out_beyond_the_threshold() -> None:
    # A plane turned 80 deg from the optical axis: incidence sweeps through 80 deg across the (wide) image.
    wide = CameraIntrinsics(320, 240, 200.0, 200.0, 159.5, 119.5)
    a = math.radians(80.0)
    depth, theta = _tilted_plane(np.array([math.sin(a), 0.0, -math.cos(a)]), np.array([0.0, 0.0, 1.0]), wide)
    spec = NoiseSpec(grazing_dropout_deg=80.0, edge_invalid_fraction=0.0)
    noisy = apply_noise(depth, wide, spec, np.random.default_rng(6))
    deg = np.degrees(theta)
    grazing = deg > 80.5
    facing = deg < 79.5
    assert grazing.sum() > 1000 and facing.sum() > 1000
    assert np.all(noisy[grazing] == 0)
    assert np.all(noisy[facing] > 0)


def test_edges_come_back_invalid_or_flying_in_the_stated_fractions() -> None:
    # Foreground at 1.0 m on the left half, background at 1.5 m on the right: the two columns at the step
    # are the edge pixels.
    intr = CameraIntrinsics(200, 1000, D415_FX, D415_FX, 99.5, 499.5)
    depth = np.full((1000, 200), 1.5)
    depth[:, :100] = 1.0
    spec = NOISELESS.model_copy(update={"edge_invalid_fraction": 0.1, "edge_flying_fraction": 0.3})
    noisy = apply_noise(depth, intr, spec, np.random.default_rng(8)).astype(float)
    edge = np.zeros(depth.shape, bool)
    edge[:, 99:101] = True
    changed = noisy != depth
    assert not np.any(changed & ~edge)  # nothing happens away from the discontinuity
    n_edge = int(edge.sum())
    n_bad = round(0.1 * n_edge)
    n_flying = round(0.3 * n_bad)
    assert int(changed.sum()) == n_bad
    assert int((noisy == 0).sum()) == n_bad - n_flying
    flying = changed & (noisy > 0)
    assert int(flying.sum()) == n_flying
    assert np.all((noisy[flying] > 1.0) & (noisy[flying] < 1.5))  # between foreground and background
    # both sides of the edge are hit
    assert changed[:, 99].sum() > 0 and changed[:, 100].sum() > 0


def test_small_depth_steps_are_not_edges() -> None:
    depth = np.full((240, 320), 1.5)
    depth[:, :160] = 1.49  # a 10 mm step, below edge_jump_m = 20 mm
    spec = NOISELESS.model_copy(update={"edge_invalid_fraction": 1.0})
    noisy = apply_noise(depth, CROP, spec, np.random.default_rng(0))
    assert np.array_equal(noisy, depth.astype(np.float32))


def _rotation_angle(R: FloatArray) -> float:
    return math.acos(float(np.clip((np.trace(R) - 1.0) / 2.0, -1.0, 1.0)))


@pytest.mark.parametrize("seed", range(5))
def test_perturb_pose_moves_by_exactly_the_magnitudes(seed: int) -> None:
    from cell.geometry import look_at

    X_WC = look_at([1.0, 0.0, 2.0], [0.15, 0.0, 0.95])
    spec = ExtrinsicErrorSpec(translation_mm=0.7, rotation_deg=0.05)
    X = perturb_pose(X_WC, spec, np.random.default_rng(seed))
    assert np.linalg.norm(X[:3, 3] - X_WC[:3, 3]) == pytest.approx(0.0007, abs=1e-12)
    assert math.degrees(_rotation_angle(X_WC[:3, :3].T @ X[:3, :3])) == pytest.approx(0.05, rel=1e-6)
    assert np.allclose(X[:3, :3] @ X[:3, :3].T, np.eye(3), atol=1e-12)
    assert np.array_equal(X, perturb_pose(X_WC, spec, np.random.default_rng(seed)))
    # a rotation alone turns about the camera centre: the centre stays put
    rot_only = perturb_pose(X_WC, ExtrinsicErrorSpec(rotation_deg=0.1), np.random.default_rng(seed))
    assert np.allclose(rot_only[:3, 3], X_WC[:3, 3], atol=1e-15)
    assert not np.allclose(rot_only[:3, :3], X_WC[:3, :3], atol=1e-6)


def test_perturb_pose_directions_vary_and_zero_error_is_identity() -> None:
    X_WC = np.eye(4)
    spec = ExtrinsicErrorSpec(translation_mm=1.0)
    moves = [perturb_pose(X_WC, spec, np.random.default_rng(s))[:3, 3] for s in range(4)]
    assert len({tuple(np.round(m, 9)) for m in moves}) == 4
    assert np.array_equal(perturb_pose(X_WC, ExtrinsicErrorSpec(), np.random.default_rng(0)), X_WC)
