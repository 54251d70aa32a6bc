"""Close-up re-scan on a tiny inline cell: view planning (distance, looking into the joint, reachable, clear of the
torch and of collisions), fusion weights and which seams are re-scanned. On fence1: tests/scenario/test_closeup.py."""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np
import pytest
from tiny_cell import HOME, OBSTACLES, SIDE_SEAM, TOP_SEAM, URDF

from cell.geometry import invert, make_pose, transform_points
from cell.motion.collision import CollisionChecker
from cell.motion.robot import RobotModel
from cell.motion.views.viewpoint import (
    ViewOptions,
    ViewTarget,
    _segments_hit_box,
    plan_view,
    torch_axis_in_camera,
)
from cell.rescan import (
    estimate_sigma,
    fuse,
    seams_to_rescan,
    within_tolerance,
)
from cell.seams.sigma import PAPER_SIGMA_M, PAPER_SIGMA_UNSEEN_M, SE_INFLATION, ours_sigma, paper_sigma
from cell.sim.camera import intrinsics_for
from cell.types import Box, Part, SeamEstimate, SeamStatus

K = intrinsics_for(1280, 720, math.radians(65.0))  # the D415 of the scenarios
TOP = ViewTarget(*TOP_SEAM)
SIDE = ViewTarget(*SIDE_SEAM)


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


@pytest.fixture(scope="module")
def checker(robot: RobotModel) -> CollisionChecker:
    return CollisionChecker(robot, OBSTACLES)


# -- view planning ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("target", [TOP, SIDE], ids=["top", "side"])
def test_view_looks_into_the_joint_from_its_distance_and_is_reached_without_collision(
    robot: RobotModel, checker: CollisionChecker, target: ViewTarget
) -> None:
    opt = ViewOptions()
    vp = plan_view(robot, checker, target, HOME, K, (), 0.0, rng=np.random.default_rng(0), options=opt)
    eye = vp.X_RC[:3, 3]
    # Distance: one of the candidate distances (IK reaches the pose to 0.01 mm).
    assert min(abs(vp.distance_m - d) for d in opt.distances_m) < 1e-4
    # Looking into the joint: the camera is out along the fillet's bisector, within the tilt/slant grid.
    to_eye = (eye - target.mid) / np.linalg.norm(eye - target.mid)
    assert to_eye @ target.bisector > math.cos(math.radians(60.0))
    # Both weld faces seen at an acceptable incidence; the seam's midpoint ahead of the camera, near the axis.
    assert max(vp.incidence_deg) <= opt.max_incidence_deg
    p_C = transform_points(invert(vp.X_RC), target.mid)
    off_axis = math.degrees(math.atan2(math.hypot(p_C[0], p_C[1]), p_C[2]))
    assert p_C[2] > 0.0 and off_axis == pytest.approx(opt.image_offset_deg, abs=0.1)
    # The whole seam in the image, above the torch (which rides on the optical axis, lower half of the image).
    for p in (target.p_start, target.p_end):
        q_C = transform_points(invert(vp.X_RC), p)
        u, v = K.fx * q_C[0] / q_C[2] + K.cx, K.fy * q_C[1] / q_C[2] + K.cy
        assert 0.0 < u < K.width and 0.0 < v < K.cy
    # Reachable: the joint values put the camera there; the move starts here, ends there and is collision-free.
    np.testing.assert_allclose(robot.fk(vp.q, opt.camera_frame), vp.X_RC, atol=1e-6)
    np.testing.assert_allclose(vp.move.q[0], HOME, atol=1e-12)
    np.testing.assert_allclose(vp.move.q[-1], vp.q, atol=1e-12)
    assert robot.limits.contains(vp.q)
    assert checker.check_path(vp.move.q, vp.move.times) is None


def test_torch_lies_ahead_of_the_camera_on_its_axis(robot: RobotModel) -> None:
    axis = torch_axis_in_camera(robot)
    tip = axis[-1]
    assert 0.25 < tip[2] < 0.35  # the TCP about 0.3 m ahead of the camera
    assert math.hypot(tip[0], tip[1]) < 0.01  # on the optical axis: why views put the seam off-centre


def test_segment_box_test() -> None:
    box = Part("B", Box(make_pose(p=[0.0, 0.0, 0.0]), np.array([0.2, 0.2, 0.2])))
    p0 = np.array([-1.0, 0.0, 0.0])
    ends = np.array([[1.0, 0.0, 0.0], [-0.5, 0.0, 0.0], [1.0, 0.5, 0.0], [-0.11, 0.0, 0.0], [1.0, 0.0, 0.099]])
    np.testing.assert_array_equal(_segments_hit_box(p0, ends, box, 0.0), [True, False, False, False, True])


# -- uncertainty and fusion ------------------------------------------------------------------------------


def _est(
    p0: Any, p1: Any, conf: float, status: SeamStatus = SeamStatus.FOUND, sigma_m: float = math.inf
) -> SeamEstimate:
    if status is not SeamStatus.FOUND:
        return SeamEstimate("s", status, "not seen")
    return SeamEstimate("s", status, "", np.asarray(p0, float), np.asarray(p1, float), conf, sigma_m=sigma_m)


def test_sigma_models_and_the_fusion_reads_the_locators_sigma() -> None:
    s = [ours_sigma(se, 5e-5) for se in (0.0, 1e-5, 1e-4, 1e-3)]
    assert all(a < b for a, b in itertools.pairwise(s))
    assert s[0] == pytest.approx(5e-5) and s[-1] == pytest.approx(math.hypot(SE_INFLATION * 1e-3, 5e-5))
    assert math.isinf(ours_sigma(math.inf, 5e-5))
    assert paper_sigma(1.0) == paper_sigma(0.9) == PAPER_SIGMA_M
    assert paper_sigma(0.75) == paper_sigma(0.5) == PAPER_SIGMA_UNSEEN_M
    assert estimate_sigma(_est([0, 0, 0], [0.1, 0, 0], 0.2, sigma_m=3e-4)) == 3e-4  # not from the confidence
    assert math.isinf(estimate_sigma(None)) and math.isinf(estimate_sigma(_est(None, None, 0.0, SeamStatus.NOT_FOUND)))


def test_fusion_weights_by_inverse_variance_and_turns_a_reversed_closeup_round() -> None:
    first = _est([0, 0, 0], [0.1, 0, 0], 0.5)
    close = _est([0.1, 0.003, 0], [0, 0.003, 0], 0.9)  # reported the other way round, 3 mm off
    fused, w = fuse(first, close, 3e-4, 1e-4, 2e-4)
    assert w == pytest.approx(0.9)  # 9e-8 / (9e-8 + 1e-8)
    np.testing.assert_allclose(fused.p_start, [0, 0.0027, 0], atol=1e-12)
    np.testing.assert_allclose(fused.p_end, [0.1, 0.0027, 0], atol=1e-12)
    sigma = math.sqrt(9e-8 * 1e-8 / 1e-7)
    assert fused.confidence == pytest.approx(1.0 / (1.0 + (sigma / 2e-4) ** 2))
    assert fused.sigma_m == pytest.approx(sigma)  # what the weld gate reads
    even, w_even = fuse(first, _est([0, 0.002, 0], [0.1, 0.002, 0], 0.5), 1e-4, 1e-4, 2e-4)
    assert w_even == pytest.approx(0.5) and even.p_start[1] == pytest.approx(0.001)


def test_failed_or_weak_closeup_keeps_the_first_estimate() -> None:
    first = _est([0, 0, 0], [0.1, 0, 0], 0.8)
    s1 = math.hypot(1e-4, 2e-4)
    for failed in (None, _est(None, None, 0.0, SeamStatus.NOT_FOUND)):
        fused, w = fuse(first, failed, s1, 1e-5, 2e-4)
        assert fused is first and w == 0.0
    weak = _est([0, 0.01, 0], [0.1, 0.01, 0], 0.001)  # a 10 mm wrong close-up the locator barely believes
    fused, w = fuse(first, weak, s1, 6e-4, 2e-4)
    assert w < 0.2 and fused.p_start[1] < 0.002
    # A visible seam the fixed cameras missed: the close-up alone.
    alone = _est([0, 0, 0], [0.1, 0, 0], 0.8, sigma_m=1e-4)
    only, w_only = fuse(_est(None, None, 0.0, SeamStatus.NOT_FOUND), alone, math.inf, 1e-4, 2e-4)
    assert w_only == 1.0 and only.status is SeamStatus.FOUND and only.sigma_m == 1e-4


def test_seams_to_rescan_takes_low_confidence_and_missed_visible_seams() -> None:
    estimates = (
        SeamEstimate("a", SeamStatus.FOUND, "", np.zeros(3), np.ones(3), 0.9),
        SeamEstimate("b", SeamStatus.FOUND, "", np.zeros(3), np.ones(3), 0.3),
        SeamEstimate("c", SeamStatus.NOT_FOUND, "too few points"),
        SeamEstimate("d", SeamStatus.NOT_VISIBLE, "underside"),
    )
    assert seams_to_rescan(estimates, 0.55) == ["b", "c"]
    assert seams_to_rescan(estimates, math.inf) == ["a", "b", "c"]


def test_a_seam_whose_bound_exceeds_the_tolerance_is_rescanned_whatever_its_confidence() -> None:
    sure = SeamEstimate("a", SeamStatus.FOUND, "", np.zeros(3), np.ones(3), 1.0, sigma_m=1e-4)
    vague = SeamEstimate("b", SeamStatus.FOUND, "", np.zeros(3), np.ones(3), 1.0, sigma_m=9e-4)  # the paper's
    max_sigma = 0.5e-3 / 3.0  # 0.5 mm at 3 sigma
    assert within_tolerance(sure, max_sigma) and not within_tolerance(vague, max_sigma)
    assert seams_to_rescan((sure, vague), 0.55, max_sigma) == ["b"]
    assert seams_to_rescan((sure, vague), 0.55) == []  # no tolerance given: the confidence alone
