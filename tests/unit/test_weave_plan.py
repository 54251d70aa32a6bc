"""Weld procedures planned on the tiny cell: a two-pass seam becomes one weld segment per pass at its offset, a
weaving seam's TCP follows the weave across the seam, a vertical seam is welded upwards, and the safety gate
passes the plan."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from tiny_cell import HOME, OBSTACLES, SIDE_SEAM, TOP_SEAM, URDF

from cell import scenario as sc
from cell.config.motion import PlanOptions
from cell.gate import find_violations
from cell.geometry import point_line_distance
from cell.motion.collision import CollisionChecker
from cell.motion.robot import RobotModel
from cell.planning.plan import plan_welds
from cell.process.procedures import select_procedures
from cell.process.torch import WeldProcess
from cell.process.torch_orientations import candidate_groups
from cell.process.weave import cross_section, intended_offsets
from cell.types.plan import NoProcedure, PlanReason, SeamTask, WeldPlan
from cell.types.procedure import Weave, WeldPass, WeldProcedure

TOP = SeamTask(*TOP_SEAM)
SIDE = SeamTask(*SIDE_SEAM)
SIDE_DOWN = SeamTask("side", SIDE.p_end, SIDE.p_start, SIDE.n_a, SIDE.n_b)  # drawn downwards
PROCESS = WeldProcess.from_spec(sc.ProcessSpec())
WEAVE = WeldProcedure(
    "weave",
    position="PF",
    travel_speed_mm_s=4.0,
    travel_angle_deg=-20.0,
    weave=Weave("zigzag", 4.0, 1.0, (0.15, 0.15)),
    crater_start_s=0.2,
    crater_end_s=0.5,
)
TWO = WeldProcedure("two", position="PB", passes=(WeldPass(), WeldPass(1.0, 2.5, 8.0)))  # craters 0 / 0.3 s


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


@pytest.fixture(scope="module")
def plan(robot: RobotModel) -> WeldPlan:
    sel = select_procedures([TOP, SIDE_DOWN], {"top": "T", "side": "T"}, {"top": 4.0, "side": 4.0}, [WEAVE, TWO])
    return plan_welds(robot, [TOP, SIDE_DOWN], HOME, PROCESS, OBSTACLES, procedures=sel)


def _tcp(robot: RobotModel, q: np.ndarray) -> np.ndarray:
    return np.array([robot.fk(qi)[:3, 3] for qi in q])


def test_every_seam_planned_with_its_procedure(plan: WeldPlan) -> None:
    assert all(o.feasible for o in plan.seams), [o.reason for o in plan.seams]
    welds = [s for s in plan.segments if s.arc_on]
    assert [(s.seam_id, s.procedure.name, s.pass_index) for s in welds if s.procedure] == sorted(
        [("top", "two", 0), ("top", "two", 1), ("side", "weave", 0)], key=lambda w: plan.order.index(w[0])
    )
    assert all(s.kind == "weld" for s in welds)
    top = [s for s in plan.segments if s.seam_id == "top"]
    kinds = [s.kind for s in top]
    first_weld = kinds.index("weld")
    assert kinds[first_weld + 1 :].count("move") == 1  # one move (arc off) from pass 1's depart to pass 2
    assert [s.pass_index for s in top if s.kind == "approach"] == [0, 1]


def test_vertical_seam_welded_upwards(plan: WeldPlan, robot: RobotModel) -> None:
    assert plan.outcome("side").reversed  # drawn downwards, welded from its end (the bottom) up
    weld = next(s for s in plan.segments if s.arc_on and s.seam_id == "side")
    z = _tcp(robot, weld.trajectory.q[[0, -1]])[:, 2]
    assert z[0] < 0.002 and z[1] > 0.058


def test_passes_lie_at_their_offsets(plan: WeldPlan, robot: RobotModel) -> None:
    welds = [s for s in plan.segments if s.arc_on and s.seam_id == "top"]
    a, b = (TOP.p_end, TOP.p_start) if plan.outcome("top").reversed else (TOP.p_start, TOP.p_end)
    e, bis = cross_section(b - a, TOP.n_a, TOP.n_b)
    for seg, off in zip(welds, (np.zeros(3), 0.001 * e + 0.0025 * bis), strict=True):
        p = _tcp(robot, seg.trajectory.q[:: max(1, len(seg.trajectory.q) // 40)])
        assert point_line_distance(p - off, a, b) == pytest.approx(0.0, abs=2e-5)  # on its line within 0.02 mm
    assert welds[1].speed == pytest.approx(0.008)  # the cap pass's own travel speed
    assert welds[0].speed == pytest.approx(0.008)  # the procedure's (8 mm/s)


def test_weave_across_the_seam(plan: WeldPlan, robot: RobotModel) -> None:
    weld = next(s for s in plan.segments if s.arc_on and s.seam_id == "side")
    a, b = SIDE.p_start, SIDE.p_end  # welded upwards
    d = (b - a) / SIDE.length
    e, bis = cross_section(d, SIDE.n_a, SIDE.n_b)
    p = _tcp(robot, weld.trajectory.q)
    lateral = (p - a) @ e
    assert lateral.max() == pytest.approx(0.002, abs=5e-5) and lateral.min() == pytest.approx(-0.002, abs=5e-5)
    # one side-to-side-and-back cycle a second at 4 mm/s: the TCP crosses the seam twice a second
    t = weld.trajectory.times
    cruise = (t > 2.0) & (t < t[-1] - 2.0)
    crossings = np.count_nonzero(np.diff(np.sign(lateral[cruise])) != 0)
    assert crossings == pytest.approx(2.0 * (t[cruise][-1] - t[cruise][0]), abs=1.5)
    # against the seam plus the intended weave, the planned TCP is on the line
    off = intended_offsets(p, a, d, SIDE.length, WEAVE, 0, e, bis)
    assert float(np.max(point_line_distance(p - off, a, b))) < 5e-5


def _held_s(q: np.ndarray, dt: float) -> tuple[float, float]:
    """How long [s] a joint path stays at its first and at its last sample."""
    moved = np.flatnonzero(np.any(np.abs(q - q[0]) > 1e-12, axis=1))
    left = np.flatnonzero(np.any(np.abs(q - q[-1]) > 1e-12, axis=1))
    return moved[0] * dt, (len(q) - 1 - left[-1]) * dt


def test_craters_held_at_rest_with_the_arc_on(plan: WeldPlan) -> None:
    welds = [s for s in plan.segments if s.arc_on]
    for seg in welds:
        p = seg.procedure
        assert p is not None
        start, end = _held_s(seg.trajectory.q, PlanOptions().dt)
        # the hold, plus the first/last sample of the rest-to-rest ramp (it leaves its knot by less than 1e-12)
        assert start == pytest.approx(p.crater_start_s, abs=0.003), (seg.seam_id, seg.pass_index)
        assert end == pytest.approx(p.crater_end_s, abs=0.003), (seg.seam_id, seg.pass_index)
        assert np.all(seg.trajectory.qd[: round(p.crater_start_s / PlanOptions().dt)] == 0.0)
    side = next(s for s in welds if s.seam_id == "side")
    assert side.trajectory.duration > SIDE.length / 0.004 + 0.7  # 15 s at 4 mm/s, its ramps and the 0.7 s of craters


def test_the_gate_passes_weave_and_passes(plan: WeldPlan, robot: RobotModel) -> None:
    assert find_violations(robot, plan, HOME, checker=CollisionChecker(robot, OBSTACLES)) == []


def test_a_seam_without_a_procedure_is_a_reason(robot: RobotModel) -> None:
    sel = select_procedures([TOP], {"top": "lap"}, {"top": 4.0}, [WeldProcedure("t", joint="T")])
    assert isinstance(sel["top"], NoProcedure)
    plan = plan_welds(robot, [TOP], HOME, PROCESS, OBSTACLES, procedures=sel)
    assert plan.outcome("top").code is PlanReason.NO_PROCEDURE and not plan.segments


def test_one_direction_widens_about_the_mirrored_nominal_too() -> None:
    opt = PlanOptions()
    fixed = replace(PROCESS, reversible=False, travel_angle_tol=PROCESS.travel_angle_tol + 2 * PROCESS.travel_angle)
    groups = candidate_groups(fixed, opt)
    travel = [round(math.degrees(PROCESS.travel_angle + g[0].travel_offset)) for g in groups if g[0].work_offset == 0]
    assert travel[:2] == [10, -10]  # the nominal push first, then the same tilt dragging (the other direction's)
    assert travel.index(-20) < travel.index(25)  # -20 is 10 deg from the mirror, 25 is 15 deg from the nominal
    assert all(not c.reversed for g in groups for c in g)
    free = candidate_groups(PROCESS, opt)  # both directions: ordered by the offset alone, as before
    assert [round(math.degrees(g[0].travel_offset)) for g in free if g[0].work_offset == 0][:3] == [0, 5, -5]
