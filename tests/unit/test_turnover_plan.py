"""Which turn exposes the seams side A leaves against the table (cell.planning.turnover, cell.resting): fence1's half
turn about its long axis, a flat pair of bars that turns without leaning, a part that cannot rest after any turn,
a forbidden turn; the operator's placement error drawn from the seed."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cell import scenario as sc
from cell.geometry import invert, make_pose
from cell.pipeline.detect import read_weldmap, table_z_R
from cell.planning.turnover import pivot, plan_turnover
from cell.resting import axis_rotation, set_down
from cell.scenario.turnover_specs import TurnoverPlacementSpec
from cell.seams.joint import fillet_bisector, find_joints
from cell.seams.visibility import visibility
from cell.sim.turnover import operator_error
from cell.types import Box, MapSeam, Part, WeldMap
from cell.types.turnover import TurnoverPlan


def _underside(w: WeldMap, joints: dict, table_z: float) -> list[str]:
    return [s.id for s in w.seams if not visibility(w, joints[s.id], table_z)[0]]


@pytest.fixture(scope="module")
def fence1() -> tuple[WeldMap, dict, float, np.ndarray]:
    scn = sc.load("fence1")
    X_RM = invert(scn.X_WR) @ scn.X_WM
    wm = read_weldmap(scn)
    return wm.transformed(X_RM, "R"), find_joints(wm), table_z_R(scn), X_RM


def test_fence1_turns_half_about_its_long_axis_and_exposes_its_four_underside_seams(fence1: tuple) -> None:
    w, joints, tz, X_RM = fence1
    left = _underside(w, joints, tz)
    assert len(left) == 4 and all(s.endswith(":-z") for s in left)
    plan = plan_turnover(w, joints, tz, left, X_RM)
    assert plan.go and plan.axis == "x" and plan.angle_rad == pytest.approx(math.pi)
    assert set(plan.exposed) == set(left) and not plan.left
    # The rails are 100 and 60 mm tall, the posts 80: upside down it rests on the top rail's face and the posts'
    # far ends, leaning about 1.6 deg (atan(20 mm / 700 mm)).
    assert 1.0 < math.degrees(plan.tilt_rad) < 2.5
    turned = w.transformed(plan.X_R_turn, "R")
    assert np.allclose(plan.X_R_turn @ X_RM, plan.X_RM_after)
    for sid in plan.exposed:
        assert fillet_bisector(turned, joints[sid])[2] > 0.5  # the seam now faces up
    low = min(float(p.vertices()[:, 2].min()) for p in turned.parts)
    assert low == pytest.approx(tz, abs=1e-9)  # set down on the table
    # Set down at the same place: the middle of its extent stays over the same point of the table.
    assert np.linalg.norm((pivot(turned) - pivot(w))[:2]) < 1e-3


def test_the_same_map_gives_the_same_plan(fence1: tuple) -> None:
    w, joints, tz, X_RM = fence1
    a = plan_turnover(w, joints, tz, _underside(w, joints, tz), X_RM)
    b = plan_turnover(w, joints, tz, _underside(w, joints, tz), X_RM)
    assert a.exposed == b.exposed and np.array_equal(a.X_RM_after, b.X_RM_after)


def _bars() -> WeldMap:
    """Two bars of one height flat on the table (z up from 0), B abutting A's +y face: a T with a seam on each of
    B's four side faces."""
    a = Part("A", Box(make_pose(p=(0.0, 0.0, 0.02)), np.array([0.6, 0.05, 0.04])))
    b = Part("B", Box(make_pose(p=(0.0, 0.176, 0.02)), np.array([0.04, 0.3, 0.04])))
    y = 0.025 + 0.001
    seams = (
        MapSeam("B:+z", np.array([-0.02, y, 0.04]), np.array([0.02, y, 0.04])),
        MapSeam("B:-z", np.array([-0.02, y, 0.0]), np.array([0.02, y, 0.0])),
        MapSeam("B:+x", np.array([0.02, y, 0.0]), np.array([0.02, y, 0.04])),
    )
    return WeldMap(parts=(a, b), seams=seams, units="m", source="test", frame="R")


def test_bars_of_one_height_turn_without_leaning() -> None:
    w = _bars()
    joints = find_joints(w)
    left = _underside(w, joints, 0.0)
    assert left == ["B:-z"]
    plan = plan_turnover(w, joints, 0.0, left, np.eye(4))
    assert plan.go and plan.exposed == ("B:-z",)
    assert plan.tilt_rad == pytest.approx(0.0, abs=1e-9)


def test_a_part_that_cannot_rest_after_any_turn_lists_every_seam_with_why(fence1: tuple) -> None:
    w, joints, tz, X_RM = fence1
    left = _underside(w, joints, tz)
    plan = plan_turnover(w, joints, tz, left, X_RM, max_tilt_rad=math.radians(1.0))
    assert not plan.go and not plan.stable and plan.exposed == ()
    assert set(plan.left) == set(left)
    assert all("lean" in why and "at most 1.0" in why for why in plan.left.values())


def test_a_forbidden_turn_keeps_the_seams_with_the_reason(fence1: tuple) -> None:
    w, joints, tz, X_RM = fence1
    left = _underside(w, joints, tz)
    plan = plan_turnover(w, joints, tz, left, X_RM, allowed=False)
    assert isinstance(plan, TurnoverPlan) and not plan.go and not plan.allowed
    assert set(plan.left) == set(left) and all("flip.allowed" in why for why in plan.left.values())
    assert "forbids" in plan.reason


def test_nothing_left_means_no_turn(fence1: tuple) -> None:
    w, joints, tz, X_RM = fence1
    plan = plan_turnover(w, joints, tz, [], X_RM)
    assert not plan.go and plan.reason


def test_a_cube_turned_upside_down_rests_level_and_stable() -> None:
    box = Box(make_pose(p=(0.3, 0.2, 0.05)), np.array([0.1, 0.1, 0.1]))
    pts = box.corners()
    X, tilt, margin = set_down(pts, box.center, axis_rotation(np.array([1.0, 0.0, 0.0]), math.pi), box.center, 0.0)
    assert tilt == pytest.approx(0.0, abs=1e-9) and margin == pytest.approx(0.05, abs=1e-6)
    moved = pts @ X[:3, :3].T + X[:3, 3]
    assert moved[:, 2].min() == pytest.approx(0.0, abs=1e-12)
    assert np.allclose(moved.mean(axis=0)[:2], box.center[:2])


def test_the_operators_error_has_the_asked_size_and_comes_from_the_seed() -> None:
    spec = TurnoverPlacementSpec(offset_mm=30.0, rotation_deg=5.0)
    centre = np.array([0.1, 1.0, 0.05])
    scn = sc.load("fence1")
    a = operator_error(spec, scn.rng("flip"), centre)
    b = operator_error(spec, scn.rng("flip"), centre)
    assert np.array_equal(a, b)
    assert abs(math.degrees(math.atan2(a[1, 0], a[0, 0]))) == pytest.approx(5.0)
    moved = a[:3, :3] @ centre + a[:3, 3]
    assert np.linalg.norm((moved - centre)[:2]) == pytest.approx(0.030)
