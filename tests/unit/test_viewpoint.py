"""Close-up view failures carry their data: the seam, how many candidates were tried and why each was rejected."""

from __future__ import annotations

import math

import numpy as np
import pytest
from tiny_cell import HOME, OBSTACLES, TOP_SEAM, URDF

from cell.errors import PlanError
from cell.geometry import make_pose
from cell.motion.collision import CollisionChecker
from cell.motion.robot import RobotModel
from cell.rescan.viewpoint import NoViewError, ViewRejection, ViewTarget, plan_view
from cell.sim.camera import intrinsics_for
from cell.types import Box, Part

K = intrinsics_for(1280, 720, math.radians(65.0))  # the D415 of the scenarios
TOP = ViewTarget(*TOP_SEAM)


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


def test_an_unreachable_seam_counts_its_rejected_views(robot: RobotModel) -> None:
    far = ViewTarget("far", np.array([-0.03, 2.6, 0.06]), np.array([0.03, 2.6, 0.06]), TOP.n_a, TOP.n_b)
    with pytest.raises(NoViewError) as err:
        checker = CollisionChecker(robot, OBSTACLES)
        plan_view(robot, checker, far, HOME, K, (), 0.0, rng=np.random.default_rng(0), restart_candidates=2)
    e = err.value
    assert isinstance(e, PlanError) and e.seam_id == "far" and e.tried > 0
    assert e.rejected[ViewRejection.UNREACHABLE] > 0 and sum(e.rejected.values()) == e.tried
    # The words the re-scan report gives (the counts by their ViewRejection value).
    assert e.message.startswith(f"seam far: none of {e.tried} close-up views works (")
    assert f"{e.rejected[ViewRejection.UNREACHABLE]} unreachable" in e.message


def test_no_geometric_candidate_is_a_view_error_with_nothing_tried(robot: RobotModel) -> None:
    wall = Part("WALL", Box(make_pose(p=[0.0, 0.6, 0.3]), np.array([1.0, 0.6, 0.6])))  # over the whole joint
    with pytest.raises(NoViewError) as err:
        plan_view(robot, CollisionChecker(robot, OBSTACLES), TOP, HOME, K, (wall,), 0.0, rng=np.random.default_rng(0))
    assert err.value.seam_id == "top" and err.value.tried == 0 and err.value.rejected == {}
    assert "no close-up view sees the seam" in err.value.message  # the words the re-scan report gives


class _ForbiddenBox:
    """A checker whose only obstacle is a box in joint space: a path hits when a sample's first two joints lie within
    ``half`` [rad] of ``centre`` (offsets from HOME)."""

    def __init__(self, centre: tuple[float, float], half: float) -> None:
        self.centre, self.half = np.array(centre), half

    def check_path(self, q: np.ndarray, times: np.ndarray) -> object | None:
        inside = np.all(np.abs(q[:, :2] - HOME[:2] - self.centre) < self.half, axis=1)
        return "hit" if inside.any() else None


def test_the_way_back_retraces_the_legs_the_arm_came_by_when_straight_home_collides() -> None:
    """Home -> B -> C by straight joint lines; straight from C home crosses the obstacle, from B it does not: the
    way back is C -> B -> home, never inside the obstacle. With no stop free of it, there is no way back."""
    from cell.rescan.viewpoint import way_back

    model = RobotModel.from_urdf(URDF)
    B, C = HOME + np.array([0.5, 0, 0, 0, 0, 0]), HOME + np.array([0.5, 0.5, 0, 0, 0, 0])
    checker = _ForbiddenBox((0.25, 0.25), 0.05)
    assert checker.check_path(np.linspace(C, HOME, 50), np.arange(50.0)) is not None  # straight home is not free
    back = way_back(model, checker, [HOME, B, C], HOME, 0.01)  # type: ignore[arg-type]
    assert back is not None
    assert np.allclose(back.q[0], C) and np.allclose(back.q[-1], HOME)
    assert np.min(np.linalg.norm(back.q - B, axis=1)) < 1e-9  # it passes through B
    assert checker.check_path(back.q, back.times) is None
    # The same obstacle on the leg C -> B as well: nothing the arm came by is free of it.
    assert way_back(model, _ForbiddenBox((0.5, 0.25), 0.3), [HOME, B, C], HOME, 0.01) is None  # type: ignore[arg-type]
