"""Approach and depart lines as short as the transfer between them allows (cell/planning/short_lines.py), on the tiny
inline cell: the lengths on the knot grid, the lines the plan takes, the welds untouched, the gate passing."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from tiny_cell import HOME, OBSTACLES, SIDE_SEAM, TOP_SEAM, URDF

from cell import scenario as sc
from cell.config.motion import PlanOptions
from cell.gate import find_violations
from cell.motion.collision import CollisionChecker
from cell.motion.robot import RobotModel
from cell.planning.plan import plan_welds
from cell.planning.short_lines import _steps
from cell.process.torch import WeldProcess
from cell.types.plan import SeamTask, WeldPlan

PROCESS = WeldProcess.from_spec(sc.ProcessSpec())  # approach and depart 50 mm, knots every 5 mm
TASKS = [SeamTask(*TOP_SEAM), SeamTask(*SIDE_SEAM)]


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


@pytest.fixture(scope="module")
def plans(robot: RobotModel) -> tuple[WeldPlan, WeldPlan]:
    """The two seams planned with the shorter lines (the default) and with the process's lines only."""
    short = plan_welds(robot, TASKS, HOME, PROCESS, OBSTACLES)
    full = plan_welds(robot, TASKS, HOME, PROCESS, OBSTACLES, options=replace(PlanOptions(), short_lines=()))
    return short, full


def test_shorter_lengths_fall_on_the_knot_grid() -> None:
    assert _steps(11, 0.05, (0.01, 0.02)) == [(2, pytest.approx(0.01)), (4, pytest.approx(0.02))]
    assert _steps(11, 0.05, (0.012, 0.05, 0.07)) == [(2, pytest.approx(0.01))]  # the full length is not shorter
    assert _steps(3, 0.01, (0.002,)) == [(1, pytest.approx(0.005))]  # at least one step, never the whole line
    assert _steps(2, 0.005, (0.001,)) == []


def _lines_mm(robot: RobotModel, plan: WeldPlan) -> list[float]:
    """Every approach's and depart's programmed length [mm]: from the point the transfer meets (the move's
    programmed end) to the weld start, from the weld end (the depart starts there, at rest) to its programmed end."""
    segs, out = plan.segments, []
    for k, seg in enumerate(segs):
        if seg.kind == "approach" and k > 0:
            a, b = segs[k - 1].q_end, seg.trajectory.q[-1]
        elif seg.kind == "depart":
            a, b = seg.trajectory.q[0], seg.q_end
        else:
            continue
        out.append(float(np.linalg.norm(robot.fk(b)[:3, 3] - robot.fk(a)[:3, 3])) * 1000.0)
    return out


def test_the_transfers_meet_shorter_lines_and_the_welds_are_unchanged(robot: RobotModel, plans: tuple) -> None:
    short, full = plans
    assert short.order == full.order and all(o.feasible for o in short.seams)
    welds = [[s for s in p.segments if s.arc_on] for p in plans]
    for a, b in zip(*welds, strict=True):
        np.testing.assert_array_equal(a.trajectory.q, b.trajectory.q)
    got, planned = _lines_mm(robot, short), _lines_mm(robot, full)
    assert len(got) == len(planned) == 4
    assert np.allclose(planned, 50.0, atol=0.1)  # without shorter lengths: the process's 50 mm
    assert all(abs(d - 5.0 * round(d / 5.0)) < 0.1 and d > 4.9 for d in got) and min(got) < 49.0, got  # on the knots
    apps = [s for s in short.segments if s.kind == "approach"]
    full_apps = [s for s in full.segments if s.kind == "approach"]
    lengths = [s.trajectory.duration for s in apps]
    assert min(lengths) < min(s.trajectory.duration for s in full_apps)
    assert short.cycle_time < full.cycle_time - 0.2  # shorter lines at the reduced speed: faster
    checker = CollisionChecker(robot, OBSTACLES)
    assert find_violations(robot, short, HOME, checker=checker) == []
