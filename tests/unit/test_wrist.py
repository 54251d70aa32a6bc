"""The wrist: equivalent configurations hold the torch alike, the hose package's A6 window steers each seam's free
spin, and a seam whose A6 cannot stay in the window is refused with the reason."""

from __future__ import annotations

import math

import numpy as np
import pytest
from tiny_cell import HOME, OBSTACLES, SIDE_SEAM, TOP_SEAM, URDF

from cell import scenario as sc
from cell.config.motion import PlanOptions
from cell.motion.robot import RobotModel
from cell.motion.wrist import HoseWindow, flip_wrist, flipped, nearest_wrist, wrist_cost, wrist_equivalents
from cell.planning.plan import plan_welds
from cell.process.torch import WeldProcess
from cell.types.plan import PlanReason, SeamTask

PROCESS = WeldProcess.from_spec(sc.ProcessSpec())


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


def test_equivalent_wrists_hold_the_torch_alike(robot: RobotModel) -> None:
    rng = np.random.default_rng(3)
    for _ in range(20):
        q = robot.limits.sample(rng, margin=0.2)
        np.testing.assert_allclose(robot.fk(flip_wrist(q)), robot.fk(q), atol=1e-12)  # KR 5 arc: A4, A6 coaxial
        eq = wrist_equivalents(robot, q)
        assert np.array_equal(eq[0], q) and len(eq) >= 2
        assert any(abs(e[3] - q[3]) > 3.0 for e in eq)  # the flip (or a turn of A4) is among them
        for e in eq:
            assert robot.limits.contains(e)
            np.testing.assert_allclose(robot.fk(e), robot.fk(q), atol=1e-9)
        window = HoseWindow(0.0, math.radians(185.0))
        best = nearest_wrist(robot, q, HOME, window)
        assert window.excess(best) == 0.0 and abs(best[3]) <= math.pi and abs(best[5]) <= math.pi
        same_side = [e for e in eq if window.excess(e) == 0.0 and not flipped(e, HOME)]
        assert same_side and not flipped(best, HOME)  # A5 on home's side: no flip against any other seam
        assert wrist_cost(best, HOME) == min(wrist_cost(e, HOME) for e in same_side)


def test_window_excess() -> None:
    w = HoseWindow(math.radians(10.0), math.radians(185.0))
    q = np.zeros((3, 6))
    q[:, 5] = np.radians([0.0, 195.0, -180.0])
    assert w.excess(q[:2]) <= 1e-12
    assert w.excess(q) == pytest.approx(math.radians(5.0))
    assert HoseWindow(0.0, math.inf).excess(q) == 0.0


def test_the_hose_window_steers_the_free_spin(robot: RobotModel) -> None:
    tasks = [SeamTask(*TOP_SEAM), SeamTask(*SIDE_SEAM)]
    free = plan_welds(robot, tasks, HOME, PROCESS, OBSTACLES)
    a6_free = np.concatenate([s.trajectory.q[:, 5] for s in free.segments])
    assert all(o.feasible for o in free.seams)
    centre, half = math.radians(30.0), math.radians(60.0)  # home's A6 (0) inside, the free plan's outside
    assert np.min(a6_free) < centre - half  # measured -82 deg
    steered = plan_welds(robot, tasks, HOME, PROCESS, OBSTACLES, options=PlanOptions(a6_window=half, a6_center=centre))
    assert all(o.feasible for o in steered.seams)
    assert {o.spin for o in steered.seams} != {o.spin for o in free.seams}  # other spins keep A6 in the window
    for s in steered.segments:  # every motion, transfers and lifts too
        assert np.all(np.abs(s.trajectory.q[:, 5] - centre) <= half + 1e-9), s.kind


def test_a_seam_that_cannot_keep_a6_in_the_window_is_refused(robot: RobotModel) -> None:
    fixed = WeldProcess.from_spec(sc.ProcessSpec(work_angle_tol_deg=0.0, travel_angle_tol_deg=0.0))
    tight = PlanOptions(a6_window=math.radians(3.0), a6_center=math.radians(170.0))  # no spin lands there
    out = plan_welds(robot, [SeamTask(*TOP_SEAM)], HOME, fixed, OBSTACLES, options=tight).outcome("top")
    assert not out.feasible and out.code is PlanReason.HOSE_WINDOW and "hose package window" in out.reason
