"""A lift's vertical line probed for a knot deep in a contact: stopped there while a search asks only whether a way
is free, solved in full otherwise, and the full line then collides (tiny inline cell with a roof over home)."""

from __future__ import annotations

import numpy as np
import pytest
from tiny_cell import HOME, TABLE, URDF

from cell import scenario as sc
from cell.config.motion import PlanOptions
from cell.geometry import make_pose
from cell.motion.collision import CollisionChecker
from cell.motion.robot import RobotModel
from cell.planning.moves.lifts import DEEP_KNOT_M, DeepKnotError, vertical_line
from cell.planning.plan import reach_model
from cell.planning.transfers import Lift, TransferFail, Transfers
from cell.process.torch import WeldProcess
from cell.types import Box, Part

PROCESS = WeldProcess.from_spec(sc.ProcessSpec())
RISE_M = 0.3


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


def _roofed(robot: RobotModel) -> tuple[CollisionChecker, tuple[Part, ...], float]:
    """A 0.1 m thick roof 0.1 m over home's TCP: the lift straight up from home meets it. (checker, obstacles, the
    lift's height [m])."""
    p = robot.fk(HOME)[:3, 3]
    roof = Part("ROOF", Box(make_pose(p=[p[0], p[1], p[2] + 0.15]), np.array([0.6, 0.6, 0.1])))
    obstacles = (TABLE, roof)
    return CollisionChecker(robot, obstacles), obstacles, float(p[2]) + RISE_M


def test_a_probed_lift_stops_at_its_first_deep_knot_and_the_full_line_collides(robot: RobotModel) -> None:
    checker, _, top = _roofed(robot)
    opt = PlanOptions()
    with pytest.raises(DeepKnotError) as err:
        vertical_line(robot, PROCESS, opt, reach_model(robot), HOME, top, True, checker)
    n_knots = round(RISE_M / opt.line_spacing) + 1
    assert 0 < err.value.index < n_knots // 2 and err.value.depth_m <= -DEEP_KNOT_M  # below the roof's top
    full = vertical_line(robot, PROCESS, opt, reach_model(robot), HOME, top, True)
    assert full is not None and checker.check_path(full.trajectory.q) is not None  # the timed line meets the roof


def test_a_search_stops_a_lift_at_its_deep_knot_and_the_exact_check_solves_it_in_full(robot: RobotModel) -> None:
    checker, obstacles, top = _roofed(robot)
    q_b = HOME + np.radians([20.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    tr = Transfers(robot, PROCESS, checker, PlanOptions(), obstacles, HOME, (Lift(),))
    got = tr._attempt(Lift(), HOME, q_b, np.zeros(3), exact=False)
    assert isinstance(got, TransferFail) and got.reason == "lift: collides"
    assert isinstance(tr._vertical[(HOME.tobytes(), tr.lift_z, True)], DeepKnotError)
    exact = tr._attempt(Lift(), HOME, q_b, np.zeros(3), exact=True)
    assert isinstance(exact, TransferFail) and "ROOF" in exact.reason  # where it first meets the roof
    assert tr.vertical(HOME, tr.lift_z, True) is not None  # solved in full, remembered
    assert top < tr.lift_z  # (the transfers' lift height is over the roof too)
