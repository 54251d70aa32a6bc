"""The splice as an estimate with the stated calibration as its prior, on synthetic clouds (no simulator).

A small miscalibration is recovered along the directions the overlap informs; a flat overlap and a round one move
nothing along the directions they leave free; nothing moves a camera stated exact; a disagreement beyond three
prior sigmas is a fault that drops the camera, not a correction.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from scipy.spatial.transform import Rotation

from cell.geometry import FloatArray, axis_angle_to_matrix, invert, look_at, make_pose, transform_points
from cell.perception.splicing.decision import FAULT, refusal
from cell.perception.splicing.pose_prior import (
    FAULT_SIGMAS,
    INFORMED_RATIO,
    PoseUncertainty,
    camera_covariance,
    posterior,
    relative_covariance,
)
from cell.perception.splicing.registration import register
from cell.perception.splicing.splice import splice
from cell.scenario import PerceptionSpec, WorkspaceSpec
from cell.types import CameraIntrinsics, Cloud, DepthImage

SPEC = PerceptionSpec(workspace=WorkspaceSpec(min_m=(-1.0, -1.0, -0.1), max_m=(1.0, 1.0, 1.0)))
STATED = PoseUncertainty(0.001, math.radians(0.1))  # 1 mm / 0.1 deg
EYES = {"cam_a": np.array([-0.8, -0.3, 1.0]), "cam_b": np.array([0.8, -0.3, 1.0]), "cam_c": np.array([0.0, 0.9, 1.0])}


def _noisy(p: FloatArray, n: FloatArray, rng: np.random.Generator, sigma_m: float = 0.0005) -> FloatArray:
    return p + rng.normal(0.0, sigma_m, (len(p), 1)) * n


def _plane(rng: np.random.Generator, k: int = 20000) -> tuple[FloatArray, FloatArray]:
    """Samples (k, 3) of the square z = 0, 0.6 m wide, and their normals."""
    p = np.column_stack([rng.uniform(-0.3, 0.3, k), rng.uniform(-0.3, 0.3, k), np.zeros(k)])
    return p, np.tile([0.0, 0.0, 1.0], (k, 1))


def _box_on_plane(rng: np.random.Generator) -> tuple[FloatArray, FloatArray]:
    """A 200 x 100 x 150 mm box standing on the plane: its top and four sides, and the plane (every direction
    constrained)."""
    pts, nrm = [*_plane(rng)][0:1], [*_plane(rng)][1:2]
    lo, hi = np.array([-0.1, -0.05, 0.0]), np.array([0.1, 0.05, 0.15])
    for axis, sign in ((2, 1), (0, 1), (0, -1), (1, 1), (1, -1)):
        p = rng.uniform(lo, hi, (6000, 3))
        p[:, axis] = hi[axis] if sign > 0 else lo[axis]
        n = np.zeros((6000, 3))
        n[:, axis] = sign
        pts.append(p)
        nrm.append(n)
    keep = [~((np.abs(pts[0][:, 0]) < 0.1) & (np.abs(pts[0][:, 1]) < 0.05))]  # the plane under the box is hidden
    return np.concatenate([pts[0][keep[0]], *pts[1:]]), np.concatenate([nrm[0][keep[0]], *nrm[1:]])


def _pipe(rng: np.random.Generator, k: int = 20000) -> tuple[FloatArray, FloatArray]:
    """Samples of the upper half of a pipe of radius 50 mm, 0.5 m long along x (its ends not seen)."""
    a = rng.uniform(0.0, math.pi, k)
    n = np.column_stack([np.zeros(k), np.cos(a), np.sin(a)])
    return np.column_stack([rng.uniform(-0.25, 0.25, k), 0.05 * n[:, 1], 0.05 * n[:, 2]]), n


def _off(eye: FloatArray, axis: list[float], deg: float, t_m: list[float]) -> FloatArray:
    """(4, 4) a camera's error: a rotation about its optical centre ``eye`` and a shift (its points move by it)."""
    return (
        make_pose(p=eye + np.asarray(t_m))
        @ make_pose(axis_angle_to_matrix(axis, math.radians(deg)))
        @ make_pose(p=-eye)
    )


def _prior(
    source: str = "cam_b", target: str = "cam_a", u: PoseUncertainty = STATED
) -> Callable[[FloatArray, float], FloatArray]:
    """The registration's prior: ``source`` and ``target`` both stated ``u``, the target all of one camera."""

    def prior(centre: FloatArray, lever: float) -> FloatArray:
        return relative_covariance((u, EYES[source]), [(u, EYES[target], 1.0)], centre, lever)

    return prior


def test_posterior_moves_only_where_the_data_outweigh_the_prior() -> None:
    """In the prior's whitened coordinates: a direction the data know 100 times better than the prior moves by
    the data's estimate shrunk by 100/101, one they know as well as the prior (ratio 1) or not at all stays; the
    disagreement is in prior sigmas; a zero prior moves nothing."""
    P = np.diag([4.0, 4.0, 4.0, 1.0, 1.0, 1.0]) * 1e-6  # sigmas 2, 2, 2, 1, 1, 1 mm
    info = np.diag([100.0 / 4.0, 1.0 / 4.0, 0.0, 100.0, 0.0, INFORMED_RATIO]) * 1e6
    x = np.array([2.0, 2.0, 5.0, -2.5, 9.0, 1.0]) * 1e-3
    post = posterior(x, info, P)
    assert post.informed == 3
    np.testing.assert_allclose(post.x_map, [2e-3 * 100 / 101, 0, 0, -2.5e-3 * 100 / 101, 0, 1e-3 * 10 / 11], atol=1e-12)
    np.testing.assert_allclose(post.x_informed, [2e-3, 0, 0, -2.5e-3, 0, 1e-3], atol=1e-12)
    assert abs(post.disagreement_sigmas - 2.5) < 1e-9 and not post.fault  # 9 mm along an uninformed one: no fault
    assert posterior(x * 1.5, info, P).fault  # 3.75 sigmas along an informed direction
    zero = posterior(x, info, np.zeros((6, 6)))
    assert zero.informed == 0 and not zero.x_map.any()


def test_prior_of_a_camera_rotation_reaches_the_overlap_by_its_range() -> None:
    """The centroid's displacement under the prior: hypot(t, range * theta) / sqrt(3) per axis, as a seam's
    calibration sigma (:meth:`PoseUncertainty.sigma_at`); the rotation coordinates carry lever * theta / sqrt(3)."""
    P = camera_covariance(STATED, np.array([0.0, 0.0, 1.5]), np.zeros(3), 0.2)
    across = math.sqrt(P[3, 3])  # x: the camera 1.5 m above, a rotation about y moves the centre along x
    assert abs(across - STATED.sigma_at(1.5)) < 1e-12
    assert abs(math.sqrt(P[5, 5]) - STATED.translation_m / math.sqrt(3.0)) < 1e-12  # along the line of sight
    assert abs(math.sqrt(P[0, 0]) - 0.2 * STATED.rotation_rad / math.sqrt(3.0)) < 1e-12


def test_a_small_miscalibration_is_recovered_along_informed_directions() -> None:
    """cam_b 1 mm / 0.1 deg off (its stated calibration): every direction informed by the box on its plane, the
    MAP correction takes out nearly all of it and lowers the misfit; within the prior, so no fault (applied only
    when all six directions are informed)."""
    rng = np.random.default_rng(1)
    target = _noisy(*_box_on_plane(rng), rng)
    X_off = _off(EYES["cam_b"], [0.3, -1.0, 0.5], 0.1, [0.0006, -0.0005, 0.0006])
    source = transform_points(X_off, _noisy(*_box_on_plane(rng), rng))  # other samples: another camera
    est = register(source, target, SPEC, _prior())
    assert est.informed >= 5 and est.disagreement_sigmas < FAULT_SIGMAS
    assert refusal(est) == ("" if est.informed == 6 else "partly_informed")
    probe = source[::20]
    before = np.linalg.norm(transform_points(invert(X_off), probe) - probe, axis=1).mean()
    after = np.linalg.norm(transform_points(invert(X_off), probe) - transform_points(est.X_map, probe), axis=1).mean()
    assert before > 0.0015 and after < 0.1 * before  # measured 2.0 mm -> 0.1 mm
    assert est.misfit_m < 0.5 * est.misfit_before_m


def test_a_flat_overlap_moves_nothing_along_it() -> None:
    """A plane fixes its height and its tilt: a shift of 3 mm along it and a turn about its normal are not
    followed, whatever ICP made of them; the MAP takes out the 0.8 mm of height, yet nothing is applied: the
    overlap does not fix the whole pose, and on random cells such estimates are biased by the sensor."""
    rng = np.random.default_rng(2)
    target = _noisy(*_plane(rng), rng)
    X_off = make_pose(axis_angle_to_matrix([0, 0, 1], math.radians(0.3)), [0.003, -0.002, 0.0008])
    source = transform_points(X_off, _noisy(*_plane(rng), rng))
    est = register(source, target, SPEC, _prior())
    assert est.informed == 3 and refusal(est) == "partly_informed"
    moved = transform_points(est.X_map, source) - source
    assert np.abs(moved[:, :2]).max() < 5e-5  # nothing along the plane (20 um at most at its edge)
    assert abs(moved[:, 2].mean() + 0.0008) < 5e-5  # its height recovered


def test_a_round_overlap_moves_nothing_along_or_about_its_axis() -> None:
    """A pipe seen from above fixes its axis' place and direction, not a slide along it nor a turn about it: a
    cloud 4 mm along and 1 deg about the axis off, and 0.6 mm across, is moved only across by the MAP (which is
    not applied: the overlap does not fix the whole pose)."""
    rng = np.random.default_rng(3)
    target = _noisy(*_pipe(rng), rng, 0.0015)
    X_off = make_pose(axis_angle_to_matrix([1, 0, 0], math.radians(1.0)), [0.004, 0.0006, 0.0])
    source = transform_points(X_off, _noisy(*_pipe(rng), rng, 0.0015))
    est = register(source, target, SPEC, _prior())
    assert est.informed == 4 and refusal(est) == "partly_informed"
    moved = transform_points(est.X_map, source) - source
    assert np.abs(moved[:, 0]).max() < 5e-5  # no slide along the axis (measured 1 um; 1.6 mm without the prior)
    assert abs(moved[:, 1].mean() + 0.0006) < 5e-5  # the 0.6 mm across recovered
    # The across shift of a half pipe seen from above is in part a turn about the pipe's axis in the registration's
    # coordinates (about the overlap's centroid, 32 mm above the axis): 0.05 deg, 0.04 mm at the pipe's surface.
    turn = Rotation.from_matrix(est.X_map[:3, :3]).as_rotvec()
    assert abs(math.degrees(turn[0])) < 0.1  # no turn of its own about the axis (ICP's estimate: 1.7 deg)


def _image(name: str) -> DepthImage:
    k = CameraIntrinsics(16, 16, 20.0, 20.0, 7.5, 7.5)
    return DepthImage(name, np.zeros((16, 16), np.float32), k, look_at(EYES[name].tolist(), [0.0, 0.0, 0.0]), "fixed")


def _clouds(X_off_c: FloatArray, seed: int) -> dict[str, Cloud]:
    """cam_a, cam_b exact and cam_c off by ``X_off_c``, each seeing the box on its plane with its own noise."""
    rng = np.random.default_rng(seed)
    truth, normals = _box_on_plane(rng)
    names = tuple(EYES)
    out = {}
    for i, name in enumerate(names):
        p = _noisy(truth, normals, rng)
        p = transform_points(X_off_c, p) if name == "cam_c" else p
        out[name] = Cloud(p, "R", np.full(len(p), i, np.int16), names)
    return out


def test_nothing_moves_a_camera_stated_exact() -> None:
    """With every calibration stated 0 (no priors given) nothing is registered nor applied, even for a camera
    1 mm / 0.1 deg off: the registered cloud is the calibrated one."""
    clouds = _clouds(_off(EYES["cam_c"], [1, 0.5, 0], 0.1, [0.001, 0, 0]), 4)
    images = {n: _image(n) for n in clouds}
    spliced = splice(clouds, images, np.eye(4), SPEC)
    assert [r.refused for r in spliced.registrations] == ["calibration_exact", "calibration_exact"]
    assert not any(r.accepted for r in spliced.registrations) and not spliced.faults
    calibrated = np.concatenate([clouds[n].points for n in ("cam_b", "cam_a", "cam_c")])
    np.testing.assert_array_equal(spliced.registered.points, calibrated)


def test_a_disagreement_beyond_three_prior_sigmas_is_a_fault() -> None:
    """cam_c knocked 5 mm / 0.4 deg while it states 1 mm / 0.1 deg: refused as a fault (not corrected), its
    points leave the registered cloud, with the reason; the exact cameras are not moved."""
    clouds = _clouds(_off(EYES["cam_c"], [1, 0.5, 0], 0.4, [0.003, -0.003, 0.0025]), 5)
    images = {n: _image(n) for n in clouds}
    priors = dict.fromkeys(clouds, STATED)
    spliced = splice(clouds, images, np.eye(4), SPEC, priors=priors)
    by = {r.source: r for r in spliced.registrations}
    assert by["cam_c"].refused == FAULT and by["cam_c"].fault and not by["cam_c"].accepted
    assert by["cam_c"].disagreement_sigmas > FAULT_SIGMAS and by["cam_c"].target == ("cam_b", "cam_a")
    assert not by["cam_a"].accepted  # the exact camera: its estimate explains nothing (no misfit gain)
    assert set(spliced.faults) == {"cam_c"} and "stated calibration" in spliced.faults["cam_c"]
    c = spliced.registered.cameras.index("cam_c")
    assert not np.any(spliced.registered.camera == c) and len(spliced.registered) == sum(
        len(clouds[n]) for n in ("cam_a", "cam_b")
    )
    assert spliced.kept["cam_c"] == 0 and spliced.kept["cam_a"] > 0
