"""The ways into and out of a frame's opening: the torch stepped aside towards the arm, square to its axis, then
raised; the planner's last transfer strategies (tiny inline cell)."""

from __future__ import annotations

import numpy as np
import pytest
from tiny_cell import HOME, OBSTACLES, URDF

from cell import scenario as sc
from cell.config.motion import PlanOptions
from cell.motion.collision import CollisionChecker
from cell.motion.ik import solve_ik
from cell.motion.robot import RobotModel
from cell.planning.access.openings import WAYS, Aside, opening_ways
from cell.planning.transfers import DEFAULT_STRATEGIES, Transfers
from cell.process.torch import WeldProcess


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


def _mover(robot: RobotModel) -> Transfers:
    return Transfers(
        robot,
        WeldProcess.from_spec(sc.ProcessSpec()),
        CollisionChecker(robot, OBSTACLES),
        PlanOptions(),
        OBSTACLES,
        HOME,
    )


def test_the_planner_tries_the_opening_ways_after_every_other() -> None:
    ours = [s.name for s in opening_ways()]
    assert [s.name for s in WAYS] == [s.name for s in DEFAULT_STRATEGIES] + ours
    assert ours == ["aside_in", "aside_out", "aside"]


def test_the_torch_steps_aside_towards_the_arm_then_rises_keeping_its_orientation(robot: RobotModel) -> None:
    mover = _mover(robot)
    X = np.eye(4)
    X[:3, :3] = np.array([[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]) @ np.array(
        [[1.0, 0.0, 0.0], [0.0, np.cos(0.6), -np.sin(0.6)], [0.0, np.sin(0.6), np.cos(0.6)]]
    )  # the torch pointing down and away from the arm, as into a corner
    X[:3, 3] = [0.1, 0.85, 0.05]
    q = np.asarray(solve_ik(robot, X, HOME, options=mover.opt.ik))
    pieces = Aside("aside_in", 0.0, 0.10).pieces(mover, HOME, q)
    ends = [robot.fk(p.trajectory.q[-1]) for p in pieces]
    assert len(pieces) == 3 and np.allclose(ends[-1], robot.fk(q), atol=1e-6)
    high, aside = ends[0], ends[1]
    step = aside[:3, 3] - X[:3, 3]
    centre, _ = robot.reach_bound("torch_tcp")
    assert np.linalg.norm(step) == pytest.approx(0.10, abs=1e-4)
    assert abs(step @ X[:3, 2]) < 1e-4  # square to the torch axis
    assert step @ (centre - X[:3, 3]) > 0.0  # towards the arm
    for Y in (aside, high):  # the torch's orientation kept
        assert np.allclose(Y[:3, :3], X[:3, :3], atol=1e-4)
    assert np.allclose(high[:2, 3], aside[:2, 3], atol=1e-4)
    assert aside[2, 3] < high[2, 3] <= mover.lift_z + 1e-6
    # Out of the seam the same way in reverse: aside first, then up.
    out = Aside("aside_out", 0.10, 0.0).pieces(mover, q, HOME)
    assert np.allclose(robot.fk(out[0].trajectory.q[-1]), aside, atol=1e-4)
