"""Perception: deprojection, crop, splice (ICP, prioritised merge), preprocessing, map alignment, PLY I/O.

No simulator: depth images are ray-cast analytically (boxes, a table plane), clouds are sampled directly.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from cell.errors import AlignmentError, SensorError
from cell.geometry import (
    axis_angle_to_matrix,
    invert,
    look_at,
    make_pose,
    matrix_to_rpy,
    rot_z,
    transform_points,
)
from cell.perception import (
    _open3d,
    align_map,
    clouds_in_robot_frame,
    crop,
    deproject,
    downsample,
    load_ply,
    perceive,
    preprocess,
    sample_map,
    save_ply,
    splice,
)
from cell.perception.merge import predicted_noise, prioritised_merge
from cell.perception.perceive import perceive_then
from cell.perception.preprocess import radius_outlier_mask, z_range_R
from cell.perception.splicing.decision import MIN_MISFIT_DROP, MIN_SHIFT_M, REFUSALS, refusal
from cell.perception.splicing.pose_prior import PoseUncertainty, camera_covariance
from cell.perception.splicing.registration import MIN_OVERLAP, Estimate, register, registration_settings
from cell.perception.splicing.splice import splice_order, stacked
from cell.scenario import PerceptionSpec, WorkspaceSpec
from cell.types import Box, CameraIntrinsics, Cloud, DepthImage, Part, WeldMap
from cell.voxels import voxel_order

TABLE_Z = 0.90  # table top in W [m]
X_WR = make_pose(p=[0.15, -1.1, 1.9])  # the paper's robot base (eq. 3)
WORKSPACE = WorkspaceSpec(min_m=(-0.7, -0.55, 0.905), max_m=(1.0, 0.55, 1.2))
SPEC = PerceptionSpec(workspace=WORKSPACE)


# ----------------------------------------------------------------------------------------------- helpers
def intrinsics(width: int = 320, height: int = 240, hfov_deg: float = 65.0) -> CameraIntrinsics:
    f = 0.5 * width / math.tan(math.radians(hfov_deg) / 2)
    return CameraIntrinsics(width, height, f, f, (width - 1) / 2, (height - 1) / 2)


def render(boxes_W: list[Box], X_WC: np.ndarray, k: CameraIntrinsics, table_z: float | None = TABLE_Z) -> np.ndarray:
    """Analytic depth image (optical-axis depth, 0 = no hit) of boxes and the horizontal table plane."""
    u, v = np.meshgrid(np.arange(k.width), np.arange(k.height))
    d_C = np.stack([(u - k.cx) / k.fx, (v - k.cy) / k.fy, np.ones_like(u, dtype=float)], -1).reshape(-1, 3)
    d_W = d_C @ X_WC[:3, :3].T  # ray parameter s along d_W equals the optical depth (d_C.z = 1)
    o_W = X_WC[:3, 3]
    depth = np.full(len(d_W), np.inf)
    if table_z is not None:
        with np.errstate(divide="ignore", invalid="ignore"):
            s = (table_z - o_W[2]) / d_W[:, 2]
        depth = np.where(s > 0, np.minimum(depth, s), depth)
    for box in boxes_W:
        X_BW = invert(box.X_AB)
        o_B = transform_points(X_BW, o_W)
        d_B = d_W @ X_BW[:3, :3].T
        half = box.size / 2
        with np.errstate(divide="ignore", invalid="ignore"):
            t1 = (-half - o_B) / d_B
            t2 = (half - o_B) / d_B
        t_near = np.nanmax(np.minimum(t1, t2), axis=1)
        t_far = np.nanmin(np.maximum(t1, t2), axis=1)
        hit = (t_far >= t_near) & (t_near > 0)
        depth = np.where(hit, np.minimum(depth, t_near), depth)
    depth[~np.isfinite(depth)] = 0.0
    return depth.reshape(k.height, k.width).astype(np.float32)


def fence_W() -> list[Box]:
    """Four box tubes lying on the table, 1 mm gaps: two rails along x, two posts between them."""
    z = TABLE_Z + 0.02
    rail = np.array([1.2, 0.04, 0.04])
    post = np.array([0.04, 0.5 - 0.04 - 0.002, 0.04])
    return [
        Box(make_pose(p=[0.15, -0.25, z]), rail),
        Box(make_pose(p=[0.15, 0.25, z]), rail),
        Box(make_pose(p=[-0.40, 0.0, z]), post),
        Box(make_pose(p=[0.70, 0.0, z]), post),
    ]


def fence_map_R() -> WeldMap:
    X_RW = invert(X_WR)
    names = ("BOTTOM_RAIL", "TOP_RAIL", "POST_L", "POST_R")
    parts = tuple(Part(n, b.transformed(X_RW)) for n, b in zip(names, fence_W(), strict=True))
    return WeldMap(parts=parts, seams=(), units="mm", source="<test>", frame="R")


def paper_images(size: tuple[int, int] = (320, 240)) -> dict[str, DepthImage]:
    """The paper's three cameras (two fixed, one eye-in-hand) looking at the test fence."""
    k = intrinsics(*size)
    eyes = {"cam_right": (1.0, 0.0, 2.0), "cam_left": (-0.7, 0.0, 2.0), "eye_in_hand": (0.15, -1.0, 2.5)}
    images = {}
    for name, eye in eyes.items():
        X_WC = look_at(eye, (0.15, 0.0, 0.95))
        mount = "eye_in_hand" if name == "eye_in_hand" else "fixed"
        images[name] = DepthImage(name, render(fence_W(), X_WC, k), k, X_WC, mount)
    return images


def rotation_angle(R: np.ndarray) -> float:
    return float(np.arccos(np.clip((np.trace(R) - 1) / 2, -1.0, 1.0)))


# ----------------------------------------------------------------------------------------------- 3.2
def test_deproject_round_trip() -> None:
    rng = np.random.default_rng(1)
    k = intrinsics(64, 48)
    X_WC = look_at((0.3, -0.8, 1.7), (0.1, 0.2, 0.9))
    u = rng.integers(0, k.width, 200)
    v = rng.integers(0, k.height, 200)
    flat = np.unique(v * k.width + u)  # deproject returns pixels in row-major order
    u, v = flat % k.width, flat // k.width
    z = rng.uniform(0.4, 3.0, len(flat)).astype(np.float32).astype(np.float64)
    p_C = np.stack([(u - k.cx) * z / k.fx, (v - k.cy) * z / k.fy, z], 1)
    p_W = transform_points(X_WC, p_C)
    # The points project back onto their pixels (checks the test's own convention).
    q = transform_points(invert(X_WC), p_W) @ k.K.T
    np.testing.assert_allclose(q[:, :2] / q[:, 2:], np.stack([u, v], 1), atol=1e-9)
    depth = np.zeros((k.height, k.width), np.float32)
    depth[v, u] = z
    depth[0, 0] = np.nan  # invalid pixels are skipped, never deprojected
    image = DepthImage("c", depth, k, X_WC)
    got = deproject(image)
    assert got.shape == p_W.shape
    assert np.abs(got - p_W).max() < 1e-6


def test_crop_keeps_inside_and_bounds() -> None:
    p = np.array([[0.0, 0.0, 1.0], [-0.7, -0.55, 0.905], [1.0, 0.55, 1.2], [1.01, 0.0, 1.0], [0.0, 0.0, 0.9]])
    assert crop(p, WORKSPACE).tolist() == [True, True, True, False, False]
    with pytest.raises(ValueError, match=r"\(n, 3\)"):
        crop(np.zeros((3, 2)), WORKSPACE)


def test_clouds_in_robot_frame_crop_transform_and_camera_indices() -> None:
    images = paper_images((160, 120))
    clouds = clouds_in_robot_frame(images, X_WR, WORKSPACE)
    assert list(clouds) == list(images)
    for i, (name, cloud) in enumerate(clouds.items()):
        assert cloud.frame == "R" and cloud.cameras == tuple(images)
        assert len(cloud) > 100 and np.all(cloud.camera == i), name
        p_W = transform_points(X_WR, cloud.points)
        assert crop(p_W, WORKSPACE).all()
        assert p_W[:, 2].min() > TABLE_Z  # the table is cropped away; only the fence is left
        # Every point lies on the surface of one of the boxes.
        on_box = np.zeros(len(p_W), bool)
        for box in fence_W():
            on_box |= box.contains(p_W, 1e-6)
        assert on_box.all()


# ----------------------------------------------------------------------------------------------- 3.3
def _fence_samples(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Jittered (not gridded) samples (n, 3) of the fence's visible faces in R, their normals (n, 3) and the
    fence's centre (3,)."""
    p, n = sample_map(fence_map_R(), 0.003, 0.002)
    target = p + rng.uniform(-0.0015, 0.0015, p.shape) * (1 - np.abs(n))
    return target, n, target.mean(axis=0)


def _about(centre: np.ndarray, R: np.ndarray, t: np.ndarray) -> np.ndarray:
    """(4, 4) rotation R about ``centre`` then shift t: a calibration error seen at the fence, not R's origin."""
    return make_pose(p=centre) @ make_pose(R, t) @ make_pose(p=-centre)


def _error_at(X: np.ndarray, X_true: np.ndarray, p: np.ndarray) -> float:
    """Mean distance [m] between the points p (n, 3) moved by X and by X_true."""
    return float(np.linalg.norm(transform_points(X, p) - transform_points(X_true, p), axis=1).mean())


def _loose(centre: np.ndarray, lever: float) -> np.ndarray:
    """The prior of a camera 1.5 m above the overlap stated at 10 mm / 1 deg (a registration's ``prior``)."""
    eye = centre + np.array([0.0, 0.0, 1.5])
    return camera_covariance(PoseUncertainty(0.01, math.radians(1.0)), eye, centre, lever)


def test_register_recovers_a_known_rigid_transform_robust() -> None:
    """Open3D's point-to-plane ICP with a Tukey kernel (the default) undoes 3 mm / 0.3 deg about the fence."""
    rng = np.random.default_rng(7)
    target, _, centre = _fence_samples(rng)
    X_true = _about(centre, axis_angle_to_matrix(rng.normal(size=3), math.radians(0.3)), rng.uniform(-3e-3, 3e-3, 3))
    source = transform_points(invert(X_true), target)
    est = register(source, target, SPEC, _loose)
    assert est.informed == 6 and est.overlap > 1000 and est.disagreement_sigmas < 3.0
    for X in (est.X_icp, est.X_map):  # a prior of 10 mm / 1 deg hardly shrinks what the data fix this well
        assert _error_at(X, X_true, source) < 1e-4  # [m]
        assert math.degrees(rotation_angle(X[:3, :3] @ X_true[:3, :3].T)) < 0.01
    assert est.misfit_m < 0.1 * est.misfit_before_m


def test_register_paper_mode_is_point_to_point_within_1_mm() -> None:
    """The paper's ICP (point-to-point, 1 mm) recovers a shift below its correspondence distance, and cannot
    see one beyond it: the source then has no point within 1 mm of the target and the estimate stays put."""
    rng = np.random.default_rng(8)
    target, normals, centre = _fence_samples(rng)
    paper = SPEC.model_copy(update={"splice_icp": "paper"})
    assert registration_settings(paper, 0.001).max_correspondence_m == 0.001  # the paper's 1 mm, whatever the noise
    assert registration_settings(SPEC, 0.001).max_correspondence_m == SPEC.voxel_m
    X_small = _about(centre, axis_angle_to_matrix([0.2, 1.0, -0.4], math.radians(0.01)), np.array([4e-4, -3e-4, 2e-4]))
    source = transform_points(invert(X_small), target)
    X = register(source, target, paper, _loose).X_icp
    assert _error_at(X, X_small, source) < 2e-5  # the same points: point-to-point pairs them exactly
    X_far = make_pose(p=[0.0, 0.0, 0.004])  # the top faces 4 mm too low: no pair within 1 mm
    far_source = transform_points(invert(X_far), target[normals[:, 2] > 0.9])
    X = register(far_source, target, paper, _loose).X_icp
    assert _error_at(X, X_far, far_source) > 3e-3
    X = register(far_source, target, SPEC, _loose).X_icp  # the robust mode pairs within a voxel and takes it out
    assert _error_at(X, X_far, far_source) < 1e-4


def test_predicted_noise_active_stereo() -> None:
    """Range and a short focal length rank worse; an oblique view ranks slightly *better* (depth noise runs along
    the ray, so it spreads less across a face seen obliquely), but only up to the grazing cut-off."""
    assert predicted_noise(2.0, 1.0, 900.0) > predicted_noise(1.0, 1.0, 900.0)
    assert predicted_noise(1.0, 1.0, 450.0) > predicted_noise(1.0, 1.0, 900.0)
    oblique = predicted_noise(1.0, math.cos(math.radians(60)), 900.0)
    assert oblique < predicted_noise(1.0, 1.0, 900.0)
    assert oblique == pytest.approx(predicted_noise(1.0, 1.0, 900.0) * math.sqrt(0.5))
    # Past the cut-off (80 deg) a view earns nothing more.
    assert predicted_noise(1.0, 0.01, 900.0) == predicted_noise(1.0, math.cos(math.radians(80)), 900.0)
    # The same surface seen off the optical axis: the ray is longer than the optical depth.
    assert predicted_noise(1.0, 1.0, 900.0, 0.8) > predicted_noise(1.0, 1.0, 900.0, 1.0)


def test_prioritised_merge_takes_each_region_from_the_camera_that_sees_it_best() -> None:
    rng = np.random.default_rng(3)
    X_RC = {0: look_at((-1.0, 0.0, 1.0), (0.0, 0.0, 0.0)), 1: look_at((1.0, 0.0, 1.0), (0.0, 0.0, 0.0))}
    fx = {0: 900.0, 1: 900.0}

    def floor(n: int) -> np.ndarray:  # about 2 mm point spacing, like a D415 at 1.5 m
        return np.column_stack([rng.uniform(-0.5, 0.5, n), rng.uniform(-0.05, 0.05, n), np.zeros(n)])

    # Both cameras see the floor; only the right camera (at +x) sees the wall facing +x at x = -0.3.
    wall = np.column_stack([np.full(4000, -0.3), rng.uniform(-0.05, 0.05, 4000), rng.uniform(0.0, 0.1, 4000)])
    points = np.concatenate([floor(25000), floor(25000), wall])
    camera = np.repeat([0, 1, 1], [25000, 25000, 4000])
    keep = prioritised_merge(points, camera, X_RC, fx, 0.05, 0.01)
    on_floor = points[:, 2] == 0.0
    x = points[:, 0]
    left = on_floor & (x < -0.05) & (np.abs(x + 0.3) > 0.01)  # away from the middle and the wall's foot
    right = on_floor & (x > 0.05)
    assert np.all(keep[left] == (camera[left] == 0))  # left half from the left camera only
    assert np.all(keep[right] == (camera[right] == 1))  # right half from the right camera only
    assert keep[~on_floor].mean() > 0.97  # a surface only one camera sees is kept where the other one wins
    assert 0.45 < keep[on_floor].mean() < 0.55  # the floor is not doubled


def test_splice_order_and_diagnostics() -> None:
    images = paper_images((320, 240))  # 160 x 120 puts points a voxel apart: too coarse for normals
    # The eye-in-hand camera (calibrated to the robot) is the reference, then the paper's fixed order.
    assert splice_order(images, tuple(images)) == ("eye_in_hand", "cam_left", "cam_right")
    clouds = clouds_in_robot_frame(images, X_WR, WORKSPACE)
    spliced = splice(clouds, images, X_WR, SPEC)
    assert [(r.source, r.target) for r in spliced.registrations] == [
        ("cam_left", ("eye_in_hand",)),
        ("cam_right", ("eye_in_hand", "cam_left")),
    ]
    for r in spliced.registrations:  # stated exact (no priors): not registered, nothing applied
        assert not r.accepted and np.array_equal(r.X_corr, np.eye(4))
        assert r.refused == "calibration_exact" and r.shift_m == 0.0
    assert spliced.dense.frame == "R" and set(spliced.dense.camera.tolist()) == {0, 1, 2}
    assert sum(spliced.kept.values()) == len(spliced.dense) < sum(len(c) for c in clouds.values())
    # The registered cloud keeps every point of every camera, each with its camera index.
    assert len(spliced.registered) == sum(len(c) for c in clouds.values())
    for name, cloud in clouds.items():
        assert np.count_nonzero(spliced.registered.camera == cloud.cameras.index(name)) == len(cloud)
    one = splice({"cam_left": clouds["cam_left"]}, images, X_WR, SPEC)  # a single camera works too
    assert len(one.dense) == len(clouds["cam_left"]) and one.registrations == ()


STATED = PoseUncertainty(0.0015, math.radians(0.1))  # a calibration report's statement: 1.5 mm / 0.1 deg


def _noisy_images(size: tuple[int, int], seed: int) -> dict[str, DepthImage]:
    """The paper's cameras with 1.5 mm of depth noise (about a D415 at 1.2 m)."""
    rng = np.random.default_rng(seed)
    out = {}
    for name, im in paper_images(size).items():
        depth = np.where(im.depth > 0, im.depth + rng.normal(0.0, 0.0015, im.depth.shape), 0.0)
        out[name] = DepthImage(name, depth.astype(np.float32), im.intrinsics, im.X_WC, im.mount)
    return out


@pytest.mark.parametrize("mode", ["robust", "paper"])
def test_splice_takes_out_a_real_miscalibration_and_applies_no_noise(mode: str) -> None:
    """cam_left's calibration is off by 1.5 mm and 0.1 deg (1.6 mm on average at the fence), every camera
    stated at 1.5 mm / 0.1 deg: the robust registration removes most of it, the paper's ICP (point-to-point, 1 mm)
    only part of it. With exact extrinsics (the same statement) and the same noise, neither applies a correction
    (the paper's ICP moved exact cameras by up to 0.6 mm, and still estimates such moves)."""
    spec = SPEC.model_copy(update={"splice_icp": mode})
    images = _noisy_images((640, 480), 5)
    priors = dict.fromkeys(images, STATED)
    exact = splice(clouds_in_robot_frame(images, X_WR, WORKSPACE), images, X_WR, spec, priors=priors)
    for r in exact.registrations:
        assert not r.accepted and np.array_equal(r.X_corr, np.eye(4)) and r.refused in REFUSALS and not r.fault
        if mode == "robust":
            assert 0.0007 < r.noise_m < 0.003  # of the order of the 1.5 mm depth noise
    X_err = make_pose(axis_angle_to_matrix([0.3, -1.0, 0.5], math.radians(0.1)), [0.0012, -0.0006, 0.0006])
    left = images["cam_left"]
    images["cam_left"] = DepthImage("cam_left", left.depth, left.intrinsics, left.X_WC @ X_err, left.mount)
    clouds = clouds_in_robot_frame(images, X_WR, WORKSPACE)
    spliced = splice(clouds, images, X_WR, spec, priors=priors)
    reg = next(r for r in spliced.registrations if r.source == "cam_left")
    assert reg.accepted and reg.misfit_m < (1.0 - MIN_MISFIT_DROP) * reg.misfit_before_m
    # The ideal correction in R undoes the error; compare the two at the fence's points.
    X_RW = invert(X_WR)
    ideal = X_RW @ left.X_WC @ invert(left.X_WC @ X_err) @ X_WR
    p = clouds["cam_left"].points[::50]
    before = np.linalg.norm(transform_points(ideal, p) - p, axis=1).mean()
    after = np.linalg.norm(transform_points(ideal, p) - transform_points(reg.X_corr, p), axis=1).mean()
    assert before > 0.0015 and after < (0.2 if mode == "robust" else 0.8) * before


def test_perceive_then_answers_from_the_registered_cloud_with_or_without_a_correction() -> None:
    """The next stage starts beside the splice on the cloud as calibrated; its answer is kept only when the
    splice applies no correction, else it is made again from the corrected cloud (never from stale points)."""
    images = _noisy_images((640, 480), 5)
    seen: list[np.ndarray] = []

    def then(cloud: Cloud, proceed: object) -> np.ndarray:
        seen.append(np.array(cloud.points))
        return np.array(cloud.points)

    exact = perceive_then(images, X_WR, SPEC, None, then)
    assert not any(r.accepted for r in exact.perceived.spliced.registrations)
    assert len(seen) == 1  # the speculation was kept
    np.testing.assert_array_equal(exact.answer, exact.perceived.registered.points)
    assert 0.0 < exact.then_s <= exact.answer_s and 0.0 < exact.cloud_s <= exact.answer_s
    X_err = make_pose(axis_angle_to_matrix([0.3, -1.0, 0.5], math.radians(0.1)), [0.0012, -0.0006, 0.0006])
    left = images["cam_left"]
    images["cam_left"] = DepthImage("cam_left", left.depth, left.intrinsics, left.X_WC @ X_err, left.mount)
    seen.clear()
    priors = dict.fromkeys(images, STATED)  # the calibration stated: the splice may correct it
    off = perceive_then(images, X_WR, SPEC, None, then, priors)
    assert any(r.accepted for r in off.perceived.spliced.registrations)
    np.testing.assert_array_equal(off.answer, off.perceived.registered.points)
    again = perceive(images, X_WR, SPEC, None, priors)
    np.testing.assert_array_equal(off.perceived.registered.points, again.registered.points)
    # ... and not the guess's answer: the calibrated cloud, filtered and ordered as the speculation had it.
    guess = preprocess(stacked(clouds_in_robot_frame(images, X_WR, WORKSPACE), images), WORKSPACE, X_WR, SPEC)
    stale = voxel_order(guess, SPEC.voxel_m)[0].points
    assert off.answer.shape != stale.shape or not np.array_equal(off.answer, stale)
    assert 1 <= len(seen) <= 2  # a speculation that had started before the correction was stopped or ignored


# ----------------------------------------------------------------------------------------------- 3.4
def test_downsample_count_extent_and_camera() -> None:
    rng = np.random.default_rng(5)
    p = rng.uniform([0.0, 0.0, 0.0], [0.1, 0.05, 0.02], (20000, 3))
    cloud = Cloud(p, "R", (p[:, 0] > 0.05).astype(np.int16), ("a", "b"))
    down = downsample(cloud, 0.01)
    occupied = {tuple(ijk) for ijk in np.floor(p / 0.01).astype(int)}
    assert len(down) == len(occupied) == 10 * 5 * 2
    assert np.all(down.points >= p.min(0)) and np.all(down.points <= p.max(0))
    cells = {tuple(ijk) for ijk in np.floor(down.points / 0.01).astype(int)}
    assert cells == occupied  # each centroid lies in its own voxel
    assert set(down.camera.tolist()) == {0, 1}  # x = 0.05 is a voxel boundary: no voxel is mixed
    mixed = downsample(Cloud(p, "R", rng.integers(0, 2, len(p)).astype(np.int16), ("a", "b")), 0.01)
    assert np.all(mixed.camera == -1)


def test_radius_outlier_mask_matches_open3d_on_the_whole_cloud() -> None:
    rng = np.random.default_rng(11)
    surface = np.column_stack([rng.uniform(0, 0.3, 30000), rng.uniform(0, 0.3, 30000), np.zeros(30000)])
    grid = np.stack(np.meshgrid(np.arange(10), np.arange(10), np.arange(1, 4), indexing="ij"), -1).reshape(-1, 3)
    strays = grid * 0.03 + rng.uniform(-0.003, 0.003, grid.shape)  # 3 cm apart, 3 cm and more above the surface
    pairs = strays[:50] + 0.002  # two strays close together: still isolated (fewer than 3 neighbours)
    p = np.concatenate([surface, strays, pairs])
    fast = radius_outlier_mask(p, 0.01, 3)
    assert np.array_equal(fast, _open3d.radius_outlier_mask(p, 0.01, 3))
    assert fast[:30000].all() and not fast[30000:].any()


def test_preprocess_z_passthrough_and_outliers() -> None:
    z_lo, z_hi = z_range_R(WORKSPACE, X_WR)
    assert (z_lo, z_hi) == pytest.approx((0.905 - 1.9, 1.2 - 1.9))
    rng = np.random.default_rng(2)
    top = np.column_stack([rng.uniform(0, 0.2, 5000), rng.uniform(0, 0.2, 5000), np.full(5000, -0.9)])
    below = top[:100] - [0, 0, 0.2]  # under the workspace
    stray = np.array([[0.5, 0.5, -0.85]])  # inside the z range but alone
    cloud = Cloud(np.concatenate([top, below, stray]), "R")
    out = preprocess(cloud, WORKSPACE, X_WR, SPEC)
    assert len(out) == 5000 and np.allclose(out.points[:, 2], -0.9)


# ----------------------------------------------------------------------------------------------- 3.5
def _surface_cloud(weldmap: WeldMap, rng: np.random.Generator, noise_m: float = 0.0005) -> Cloud:
    p, n = sample_map(weldmap, 0.004, 0.002)
    p = p + rng.uniform(-0.002, 0.002, p.shape) * (1 - np.abs(n))  # off the sampling grid, in the face
    return Cloud(p + rng.normal(0.0, noise_m, p.shape) * np.abs(n), "R")


def test_align_map_recovers_offset_and_yaw() -> None:
    rng = np.random.default_rng(4)
    nominal = fence_map_R()
    centre = np.mean([part.box.center for part in nominal.parts], axis=0)
    X_true = (
        make_pose(p=centre + np.array([0.010, -0.004, 0.0]))
        @ make_pose(rot_z(math.radians(0.5)))
        @ make_pose(p=-centre)
    )
    cloud = _surface_cloud(nominal.transformed(X_true, "R"), rng)
    a = align_map(nominal, cloud, SPEC)
    corners = np.concatenate([part.box.corners() for part in nominal.parts])
    err = transform_points(a.X_RR_corr, corners) - transform_points(X_true, corners)
    assert np.linalg.norm(err, axis=1).max() < 3e-4  # [m] over every corner of the fence
    assert abs(math.degrees(matrix_to_rpy(a.X_RR_corr[:3, :3])[2]) - 0.5) < 0.01
    assert a.fitness > 0.9 and a.rmse_m < 1e-3


def test_align_map_refuses_junk_and_tilt() -> None:
    rng = np.random.default_rng(6)
    nominal = fence_map_R()
    lo = np.min([p.box.corners().min(0) for p in nominal.parts], axis=0)
    hi = np.max([p.box.corners().max(0) for p in nominal.parts], axis=0)
    junk = Cloud(rng.uniform(lo - 0.05, hi + 0.1, (20000, 3)), "R")
    with pytest.raises(AlignmentError, match="fitness"):
        align_map(nominal, junk, SPEC)
    # The whole fence tilted by 3 degrees about x: fits well, but a part on the table cannot be tilted.
    centre = np.mean([p.box.center for p in nominal.parts], axis=0)
    tilt = make_pose(p=centre) @ make_pose(axis_angle_to_matrix([1, 0, 0], math.radians(3))) @ make_pose(p=-centre)
    with pytest.raises(AlignmentError, match="tilt"):
        align_map(nominal, _surface_cloud(nominal.transformed(tilt, "R"), rng), SPEC)


def test_sample_map_skips_faces_down_and_contacts() -> None:
    nominal = fence_map_R()
    p, n = sample_map(nominal, 0.005, 0.002)
    assert np.all(n[:, 2] > -0.5)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0)
    post_l, bottom = nominal.part("POST_L").box, nominal.part("BOTTOM_RAIL").box
    assert not np.any(bottom.contains(p, 1e-9) & post_l.contains(p, 0.0015))  # rail face under the post's end


# ------------------------------------------------------------------------------------------ PLY, perceive
def test_ply_round_trip(tmp_path: Path) -> None:
    rng = np.random.default_rng(8)
    cloud = Cloud(rng.normal(size=(500, 3)), "R", rng.integers(-1, 3, 500).astype(np.int16), ("a", "b", "c"))
    path = tmp_path / "cloud.ply"
    save_ply(cloud, path)
    back = load_ply(path)
    assert back.frame == "R" and back.cameras == cloud.cameras
    np.testing.assert_array_equal(back.points, cloud.points)
    np.testing.assert_array_equal(back.camera, cloud.camera)
    plain = tmp_path / "plain.ply"  # a PLY from elsewhere: float32, no camera property
    header = "ply\nformat ascii 1.0\nelement vertex 3\n" + "".join(f"property float {c}\n" for c in "xyz")
    header += "end_header\n"
    plain.write_text(header + "0 0 0\n1 2 3\n0.5 0.25 0.125\n")
    got = load_ply(plain, frame="W")
    assert got.frame == "W" and len(got) == 3 and np.all(got.camera == -1)
    np.testing.assert_allclose(got.points[1], [1, 2, 3])
    with pytest.raises(SensorError, match="does not exist"):
        load_ply(tmp_path / "missing.ply")


def test_perceive_end_to_end_and_lost_camera() -> None:
    images = paper_images((240, 180))
    # The left camera looks away from the table (at a wall 1 m off): it gives no point inside the workspace.
    k = images["cam_left"].intrinsics
    away = look_at((-0.7, 0.0, 2.0), (-3.0, 0.0, 3.0))
    images["cam_left"] = DepthImage("cam_left", np.ones((k.height, k.width), np.float32), k, away)
    result = perceive(images, X_WR, SPEC)
    assert result.lost == ("cam_left",)
    # The paper's merged cloud is made only when it is read (ours reads the registered cloud alone).
    assert set(result.timings) == {"clouds", "splice", "preprocess", "downsample"}
    assert len(result.clouds["cam_left"]) == 0 and len(result.dense) > 1000
    assert set(result.timings) == {"clouds", "splice", "preprocess", "downsample", "merge"}
    assert len(result.dense) < len(result.registered)  # the merge keeps one camera per region
    assert len(result.downsampled) < len(result.dense)
    assert set(result.dense.camera.tolist()) == {0, 2}  # cam_right and eye_in_hand
    # The downsampled cloud is good enough to align the map to.
    assert align_map(fence_map_R(), result.downsampled, SPEC).fitness > 0.5
    dark = {
        n: DepthImage(n, np.zeros((k.height, k.width), np.float32), k, im.X_WC, im.mount) for n, im in images.items()
    }
    with pytest.raises(SensorError, match=r"cam_right.*cam_left.*eye_in_hand"):
        perceive(dark, X_WR, SPEC)


def test_refusal_names_the_first_failing_test() -> None:
    eye = np.eye(4)
    ok = Estimate(eye, eye, eye, 5000, 0.001, 6, 1.5, 0.001, 0.001, 0.0006, 0.0004)
    assert refusal(ok) == ""
    assert refusal(replace(ok, overlap=MIN_OVERLAP - 1)) == "no_overlap"
    assert refusal(replace(ok, informed=0)) == "not_informed"
    assert refusal(replace(ok, informed=5)) == "partly_informed"  # the overlap does not fix the whole pose
    gross = replace(ok, informed=5, disagreement_sigmas=3.5, misfit_m=0.0001)  # the move explains 5/6 of the misfit
    assert refusal(gross) == "beyond_prior" and refusal(replace(gross, misfit_m=0.0003)) == "partly_informed"
    strong = replace(ok, informed=5, disagreement_sigmas=3.5, strong_sigmas=3.2)  # along a strongly informed one
    assert refusal(strong) == "beyond_prior" and refusal(replace(strong, misfit_m=0.00058)) == "partly_informed"
    assert refusal(replace(ok, map_shift_m=0.0004)) == "too_small"  # under half the overlap's 1 mm of noise
    assert refusal(replace(ok, map_shift_m=MIN_SHIFT_M / 2)) == "too_small"
    assert refusal(replace(ok, misfit_m=0.00058)) == "no_misfit_gain"  # 3 % lower: explains nothing
    assert refusal(replace(ok, disagreement_sigmas=3.5)) == "beyond_prior"  # a fault, not a correction
    assert refusal(replace(ok, disagreement_sigmas=3.5, misfit_m=0.0006)) == "no_misfit_gain"
    assert {refusal(replace(ok, informed=0)), "beyond_prior", "calibration_exact"} <= set(REFUSALS)
