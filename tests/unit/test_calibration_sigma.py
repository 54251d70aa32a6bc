"""A seam seen by one camera only carries that camera's calibration error in its sigma (cell.perception.calibration)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from cell.perception.calibration import (
    PoseUncertainty,
    calibration_sigma,
    closeup_sigma,
    reference_of,
    residuals_of,
    support_shares,
    with_calibration,
)
from cell.perception.splicing.decision import Registration
from cell.perception.splicing.pose_prior import PoseResidual, posterior
from cell.types import Cloud, SeamEstimate, SeamStatus

MM, DEG = 1e-3, math.radians(1.0)
ORIGINS = {"a": np.array([0.0, 0.0, 1.0]), "b": np.array([1.0, 0.0, 1.0]), "ref": np.array([0.0, -1.0, 1.0])}


def _registration(source: str, target: str, accepted: bool) -> Registration:
    return Registration(source, (target,), np.eye(4), np.eye(4), 100, 6, 1e-4, 1.0, 1e-4, 1e-4, accepted)


def _cloud(counts: dict[str, int], rng: np.random.Generator) -> Cloud:
    """Points along the x axis near a seam from (0, 0, 0) to (0.1, 0, 0), ``counts`` per camera, plus far ones."""
    names = tuple(counts)
    pts, cams = [], []
    for k, (_, n) in enumerate(counts.items()):
        p = np.column_stack([rng.uniform(0.0, 0.1, n), rng.uniform(-0.01, 0.01, n), rng.uniform(-0.01, 0.01, n)])
        pts.append(p)
        cams.append(np.full(n, k, np.int16))
    far = np.column_stack([rng.uniform(0.0, 0.1, 50), np.full(50, 0.2), np.zeros(50)])  # 20 cm away: not support
    pts.append(far)
    cams.append(np.full(50, 0, np.int16))
    return Cloud(np.vstack(pts), "R", np.concatenate(cams), names)


def test_the_per_axis_sigma_grows_with_range_as_the_rotation_error_does() -> None:
    u = PoseUncertainty(1.0 * MM, 0.1 * DEG)
    assert math.isclose(u.sigma_at(0.0), 1.0 * MM / math.sqrt(3.0))
    # 0.1 deg at 1.3 m is 2.27 mm: with the 1 mm, 2.48 mm in all, 1.43 mm along one axis
    assert math.isclose(u.sigma_at(1.3), math.hypot(1.0, 1300 * 0.1 * DEG) * MM / math.sqrt(3.0))
    assert 1.42 * MM < u.sigma_at(1.3) < 1.44 * MM
    assert PoseUncertainty().zero and PoseUncertainty().sigma_at(2.0) == 0.0


def test_support_is_counted_per_camera_near_the_segment_only() -> None:
    rng = np.random.default_rng(0)
    cloud = _cloud({"a": 300, "b": 100}, rng)
    shares = support_shares(cloud, np.zeros(3), np.array([0.1, 0.0, 0.0]))
    assert math.isclose(shares["a"], 0.75) and math.isclose(shares["b"], 0.25)  # the far 50 of "a" not counted
    assert support_shares(cloud, np.array([0.0, 1.0, 0.0]), np.array([0.1, 1.0, 0.0])) == {}


def test_one_camera_carries_all_its_error_two_independent_cameras_share_it() -> None:
    u = {"a": PoseUncertainty(1.0 * MM, 0.1 * DEG), "b": PoseUncertainty(1.0 * MM, 0.1 * DEG)}
    mid = np.zeros(3)
    alone = calibration_sigma({"a": 1.0}, mid, ORIGINS, u, {})
    assert math.isclose(alone, u["a"].sigma_at(1.0))
    halves = calibration_sigma({"a": 0.5, "b": 0.5}, mid, ORIGINS, u, {})
    expected = math.hypot(0.5 * u["a"].sigma_at(1.0), 0.5 * u["b"].sigma_at(math.sqrt(2.0)))
    assert math.isclose(halves, expected) and halves < alone


def test_a_corrected_camera_inherits_its_reference_and_an_uncorrected_one_keeps_its_own() -> None:
    u = {"a": PoseUncertainty(1.0 * MM, 0.1 * DEG), "ref": PoseUncertainty()}
    tied = reference_of([_registration("a", "ref", accepted=True)])
    assert tied == {"a": "ref"}
    assert calibration_sigma({"a": 1.0}, np.zeros(3), ORIGINS, u, tied) == 0.0  # now where the exact reference is
    refused = reference_of([_registration("a", "ref", accepted=False)])
    assert refused == {}
    assert calibration_sigma({"a": 1.0}, np.zeros(3), ORIGINS, u, refused) > 0.5 * MM


def test_found_seams_gain_the_term_in_quadrature_others_are_untouched() -> None:
    rng = np.random.default_rng(1)
    cloud = _cloud({"a": 200}, rng)
    found = SeamEstimate("s", SeamStatus.FOUND, "", np.zeros(3), np.array([0.1, 0.0, 0.0]), 0.9, sigma_m=0.05 * MM)
    lost = SeamEstimate("t", SeamStatus.NOT_FOUND, "no support")
    u = {"a": PoseUncertainty(1.0 * MM, 0.1 * DEG)}
    out = with_calibration([found, lost], cloud, ORIGINS, u, [])
    cal = u["a"].sigma_at(float(np.linalg.norm(np.array([0.05, 0.0, 0.0]) - ORIGINS["a"])))
    assert math.isclose(out[0].sigma_m, math.hypot(0.05 * MM, cal))
    assert out[1] is lost
    nothing = with_calibration([found], cloud, ORIGINS, {"a": PoseUncertainty()}, [])
    assert nothing[0] is found  # no stated uncertainty: not even computed
    close = closeup_sigma(found, np.array([0.05, 0.0, 0.3]), u["a"])
    assert math.isclose(close.sigma_m, math.hypot(0.05 * MM, u["a"].sigma_at(0.3)))


def test_a_corrected_camera_keeps_what_its_correction_left_unknown() -> None:
    # The overlap informed every direction but a slide along x: the posterior keeps the prior's 1 mm there, and the
    # overlap still disagrees by 0.2 mm after the correction; a seam seen by that camera alone carries both.
    cov = np.diag([1e-12, 1e-12, 1e-12, (1.0 * MM) ** 2, 1e-12, 1e-12])
    left = PoseResidual(cov, np.zeros(3), 0.2, 0.2 * MM)
    reg = replace(_registration("a", "ref", accepted=True), residual=left)
    u = {"a": PoseUncertainty(1.0 * MM, 0.1 * DEG), "ref": PoseUncertainty()}
    residuals = residuals_of([reg])
    sigma = calibration_sigma({"a": 1.0}, np.zeros(3), ORIGINS, u, reference_of([reg]), residuals)
    assert math.isclose(sigma, math.hypot(1.0 * MM / math.sqrt(3.0), 0.2 * MM), rel_tol=1e-3)
    # A camera registered onto it carries its residual too; a refused correction keeps the camera's own prior.
    chained = replace(_registration("b", "a", accepted=True), residual=PoseResidual(np.zeros((6, 6)), np.zeros(3), 0.2))
    assert len(residuals_of([reg, chained])["b"]) == 2
    assert residuals_of([replace(reg, accepted=False)]) == {}


def test_the_posterior_covariance_is_what_a_correction_leaves() -> None:
    # Monte Carlo of the splice's estimate: the spread of (true error - applied correction) is the covariance stated.
    rng = np.random.default_rng(3)
    A, B = rng.normal(size=(6, 6)), rng.normal(size=(6, 6))
    prior = A @ A.T * 1e-6
    information = B @ np.diag([1e8, 1e7, 3e6, 1e5, 1e4, 1e3]) @ B.T
    L_p, L_d = np.linalg.cholesky(prior), np.linalg.cholesky(np.linalg.inv(information))
    left = []
    for _ in range(3000):
        e = L_p @ rng.normal(size=6)
        post = posterior(e + L_d @ rng.normal(size=6), information, prior)
        left.append(e - post.x_map)
    ratio = np.diag(np.cov(np.array(left).T)) / np.diag(post.covariance)
    assert post.informed >= 2 and np.all((ratio > 0.85) & (ratio < 1.15))
    # Along a direction nothing informs, the prior stays whole.
    none = posterior(np.ones(6) * 1e-3, np.zeros((6, 6)), prior)
    assert np.allclose(none.covariance, prior)


def test_a_correction_that_leaves_half_the_misfit_leaves_half_the_prior() -> None:
    from cell.perception.splicing.registration import _left

    prior, posterior_cov = np.eye(6) * 1e-6, np.eye(6) * 1e-10
    assert np.allclose(_left(posterior_cov, prior, 1.0e-3, 0.5e-3), posterior_cov + 0.25 * prior)
    assert np.allclose(_left(posterior_cov, prior, 1.0e-3, 2.0e-3), posterior_cov + prior)  # worse: the prior whole
    assert np.allclose(_left(posterior_cov, prior, math.inf, 1e-3), posterior_cov + prior)  # no misfit measured


def test_a_face_seen_by_one_camera_carries_its_error_whole_into_the_line() -> None:
    # A fillet between a face in z = 0 (seen by "a" alone) and one in y = 0 (seen by "b" alone): by shares each
    # camera would count half; the line moves with each face whole.
    rng = np.random.default_rng(2)
    floor = np.column_stack([rng.uniform(0.0, 0.1, 300), rng.uniform(0.001, 0.012, 300), np.zeros(300)])
    wall = np.column_stack([rng.uniform(0.0, 0.1, 300), np.zeros(300), rng.uniform(0.001, 0.012, 300)])
    cloud = Cloud(np.vstack([floor, wall]), "R", np.repeat(np.array([0, 1], np.int16), 300), ("a", "b"))
    found = SeamEstimate("s", SeamStatus.FOUND, "", np.zeros(3), np.array([0.1, 0.0, 0.0]), 0.9, sigma_m=0.0)
    u = {"a": PoseUncertainty(1.0 * MM, 0.0), "b": PoseUncertainty(1.0 * MM, 0.0)}
    faces = {"s": (np.array([0.0, 0.0, 1.0]), 0.0, np.array([0.0, 1.0, 0.0]), 0.0)}
    by_shares = with_calibration([found], cloud, ORIGINS, u, [])[0].sigma_m
    by_faces = with_calibration([found], cloud, ORIGINS, u, [], faces)[0].sigma_m
    one = u["a"].sigma_at(0.0)
    k95 = math.sqrt(-2.0 * math.log(0.05)) / 2.0  # the lateral error is a distance over two axes
    assert math.isclose(by_shares, one / math.sqrt(2.0), rel_tol=0.05)
    assert math.isclose(by_faces, k95 * one, rel_tol=0.05)
    # One camera seeing both faces moves the line rigidly: its own sigma, by faces as by shares.
    both = Cloud(cloud.points, "R", np.zeros(600, np.int16), ("a", "b"))
    assert math.isclose(with_calibration([found], both, ORIGINS, u, [], faces)[0].sigma_m, k95 * one, rel_tol=0.05)
