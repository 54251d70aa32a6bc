"""An arc's timed motions are held to the joints' position limits at every sample, as the safety gate holds them:
a spline that swings past a limit between two knots fails the arc's solve where it happens (the arc trimmed or
dropped there), instead of a plan the gate refuses whole (cell/planning/curves/arc_solve.py)."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from tiny_cell import URDF

from cell.gate.position import PositionLimits
from cell.motion.robot import RobotModel
from cell.planning.curves.arc_solve import _outside_limits
from cell.planning.transfers import Piece
from cell.types.plan import PlanReason
from cell.types.trajectory import Trajectory


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


def _piece(kind: str, q: np.ndarray) -> Piece:
    t = np.arange(len(q)) * 0.001
    traj = Trajectory(t, q, np.zeros_like(q), np.zeros_like(q))
    return Piece(kind, traj, 0.01, np.eye(4))  # type: ignore[arg-type]


def _along(robot: RobotModel, overshoot_rad: float) -> np.ndarray:
    """A3 rising to its upper limit and ``overshoot_rad`` past it midway (a spline between knots held there)."""
    q = np.tile(np.radians([0.0, -60.0, 100.0, 0.0, 45.0, 0.0]), (101, 1))
    hi = robot.limits.q_max[2]
    q[:, 2] = hi - 0.01 + (0.01 + overshoot_rad) * np.sin(np.linspace(0.0, np.pi, 101))
    return q


def _gate_says(robot: RobotModel, q: np.ndarray) -> list[Any]:
    t = np.arange(len(q)) * 0.001
    gate = SimpleNamespace(robot=robot, resampled=SimpleNamespace(q=q, t=t))
    return PositionLimits().violations(gate)  # type: ignore[arg-type]


def test_a_weld_swinging_past_a_limit_between_knots_fails_where_the_gate_would_refuse_it(robot: RobotModel) -> None:
    search = SimpleNamespace(robot=robot)
    q = _along(robot, np.radians(0.04))  # tube-tee's saddle from 0.65 m: A3 0.04 deg past 158 deg
    assert _gate_says(robot, q), "the gate refuses this motion"
    got = _outside_limits(search, [_piece("approach", q[:3]), _piece("weld", q)], 0.2)  # type: ignore[arg-type]
    assert got is not None and got.code is PlanReason.TIMING, got
    assert "joint_a3" in got.where and "weld" in got.where, got.where
    assert got.progress == 0.0  # the weld's own motion: the stretch dropped, not an end trimmed
    np.testing.assert_allclose(got.p_R, robot.fk(q[int(np.flatnonzero(q[:, 2] > robot.limits.q_max[2])[0])])[:3, 3])


def test_an_approach_past_a_limit_names_the_approach_and_a_motion_within_passes(robot: RobotModel) -> None:
    search = SimpleNamespace(robot=robot)
    q = _along(robot, np.radians(0.04))
    got = _outside_limits(search, [_piece("approach", q)], 0.2)  # type: ignore[arg-type]
    assert got is not None and "approach" in got.where and got.progress == 0.2
    within = _along(robot, -np.radians(0.001))  # up to 0.001 deg short of the limit: what the gate passes
    assert not _gate_says(robot, within)
    assert _outside_limits(search, [_piece("approach", within), _piece("weld", within)], 0.2) is None  # type: ignore[arg-type]
