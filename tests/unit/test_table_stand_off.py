"""The table stand-off: a vertical seam whose lower end lies on the table, where the nozzle meets the table for
every torch the process allows, is welded shortened at that end (by no more than the maximum), not refused; a seam
off the table is welded whole."""

from __future__ import annotations

import numpy as np
import pytest
from tiny_cell import HOME, OBSTACLES, SIDE_SEAM, TOP_SEAM, URDF

from cell import scenario as sc
from cell.config.motion import PlanOptions
from cell.motion.collision import CollisionChecker
from cell.motion.robot import RobotModel
from cell.planning.plan import plan_welds, unplaceable
from cell.planning.stand_off import shortened, table_end, table_top
from cell.process.torch import WeldProcess
from cell.types.plan import PlanReason, SeamTask, WeldPlan

# No travel or work angle freedom: the nozzle cannot tilt away from the table at the side seam's foot.
STIFF = WeldProcess.from_spec(sc.ProcessSpec(travel_angle_tol_deg=0.0, work_angle_tol_deg=0.0))
TASKS = (SeamTask(*SIDE_SEAM), SeamTask(*TOP_SEAM))


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


@pytest.fixture(scope="module")
def plans(robot: RobotModel) -> tuple[WeldPlan, WeldPlan]:
    """(without the stand-off, with the default one)."""
    off = plan_welds(robot, TASKS, HOME, STIFF, OBSTACLES, options=PlanOptions(table_stand_off_max=0.0))
    on = plan_welds(robot, TASKS, HOME, STIFF, OBSTACLES)
    return off, on


def test_refused_without_the_stand_off(plans: tuple[WeldPlan, WeldPlan]) -> None:
    o = plans[0].outcome("side")
    assert not o.feasible and o.code is PlanReason.COLLISION
    assert "torch vs TABLE at the weld" in o.reason
    assert plans[0].outcome("top").feasible and plans[0].outcome("top").trimmed == 0.0


def test_welded_from_the_stand_off(robot: RobotModel, plans: tuple[WeldPlan, WeldPlan]) -> None:
    o = plans[1].outcome("side")
    assert o.feasible and o.code is None
    assert 0.0 < o.trimmed <= PlanOptions().table_stand_off_max + 1e-12  # measured 8 mm
    assert o.trimmed <= 0.06 / 3.0
    weld = [s for s in plans[1].segments if s.seam_id == "side" and s.arc_on]
    assert len(weld) == 1
    q = weld[0].trajectory.q
    p0, p1 = robot.fk(q[0])[:3, 3], robot.fk(q[-1])[:3, 3]
    assert float(np.linalg.norm(p1 - p0)) == pytest.approx(0.06 - o.trimmed, abs=1e-4)  # the rest is welded
    top = plans[1].outcome("top")
    assert top.feasible and top.trimmed == 0.0  # off the table: welded whole


def test_unplaceable_knows_the_stand_off(robot: RobotModel) -> None:
    checker = CollisionChecker(robot, OBSTACLES, PlanOptions().collision)
    z = table_top(OBSTACLES, "TABLE")
    assert z == pytest.approx(0.0)
    assert set(unplaceable(robot, TASKS, HOME, STIFF, checker)) == {"side"}
    assert unplaceable(robot, TASKS, HOME, STIFF, checker, table_z=z) == {}


def test_which_end_lies_on_the_table() -> None:
    side, top = TASKS
    assert table_end(side, 0.0) == "start"
    assert table_end(SeamTask("down", side.p_end, side.p_start, side.n_a, side.n_b), 0.0) == "end"
    assert table_end(top, 0.0) is None  # along the post's top, 60 mm up
    assert table_end(shortened(side, "start", 0.005), 0.0) is None  # 5 mm above the table: off it
    short = shortened(side, "start", 0.008)
    assert short.length == pytest.approx(0.052) and short.p_end[2] == pytest.approx(0.06)
