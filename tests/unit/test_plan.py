"""Welding plans on a tiny inline cell: feasibility and reasons, torch spin, travel speed, limits at 1 kHz, and
the safety gate refusing each injected fault with its reason."""

from __future__ import annotations

import math
import re
from dataclasses import replace

import numpy as np
import pytest
from tiny_cell import HOME, OBSTACLES, SIDE_SEAM, TABLE, TOP_SEAM, URDF

from cell import scenario as sc
from cell.errors import PlanError
from cell.gate import (
    DEFAULT_CHECKS,
    Check,
    GateInput,
    GateOptions,
    GateRefusedError,
    ViolationKind,
    check_plan,
    find_violations,
)
from cell.geometry import make_pose, point_line_distance
from cell.motion.collision import CollisionChecker
from cell.motion.robot import RobotModel
from cell.motion.scan import scan_configuration
from cell.planning.plan import plan_welds
from cell.process.torch import WeldProcess, torch_poses
from cell.types import Box, Part
from cell.types.plan import PlanReason, SeamTask, WeldPlan
from cell.types.trajectory import Trajectory

TOP = SeamTask(*TOP_SEAM)
SIDE = SeamTask(*SIDE_SEAM)
FAR = SeamTask(
    "far", np.array([0.0, 2.2, 0.06]), np.array([0.06, 2.2, 0.06]), np.array([0, 0, 1.0]), np.array([0, -1.0, 0])
)
PROCESS = WeldProcess.from_spec(sc.ProcessSpec())


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


@pytest.fixture(scope="module")
def plan(robot: RobotModel) -> WeldPlan:
    return plan_welds(robot, [TOP, SIDE, FAR], HOME, PROCESS, OBSTACLES)


@pytest.fixture(scope="module")
def checker(robot: RobotModel) -> CollisionChecker:
    return CollisionChecker(robot, OBSTACLES)


def test_unreachable_seam_is_reported_and_the_others_planned(plan: WeldPlan) -> None:
    far = plan.outcome("far")
    assert not far.feasible
    assert far.code is PlanReason.BEYOND_REACH
    # the report's text: refused by the reach pre-check, before any IK
    assert far.reason.startswith("unreachable: beyond reach: at 0.0 mm along the seam the wrist centre lies")
    assert np.linalg.norm(far.p_fail - FAR.p_start) < 0.03  # the failing point, in R
    assert plan.outcome("top").feasible and plan.outcome("side").feasible
    assert plan.outcome("top").code is None and plan.outcome("side").code is None
    assert set(plan.order) == {"top", "side"}
    assert [s.kind for s in plan.segments if s.seam_id == "top" and s.kind != "move"][-3:] == [
        "approach",
        "weld",
        "depart",
    ]
    assert 0.0 < plan.arc_time < plan.cycle_time
    assert plan.arc_time == pytest.approx((TOP.length + SIDE.length) / PROCESS.travel_speed, rel=0.02)


def test_vertical_seam_at_the_table_uses_the_angle_tolerance(plan: WeldPlan) -> None:
    side = plan.outcome("side")
    # The nozzle would hit the table at the nominal 10 deg; the planner widens the travel angle (and reports it).
    assert abs(side.travel_angle) > PROCESS.travel_angle
    assert abs(side.travel_angle) <= PROCESS.travel_angle + PROCESS.travel_angle_tol + 1e-9
    assert side.reversed  # welded downwards, pushing: the torch body stays above the table


def test_seam_reachable_only_with_a_rotated_torch(robot: RobotModel) -> None:
    # Angles fixed at nominal: at spin 0 the elbow (A3) would need to fold past its limit, turned half round the
    # torch's flange offset points away from the robot and the seam is reachable.
    fixed = {"work_angle_tol_deg": 0.0, "travel_angle_tol_deg": 0.0}
    no_spin = WeldProcess.from_spec(sc.ProcessSpec(spin_tol_deg=0.0, **fixed))
    free = WeldProcess.from_spec(sc.ProcessSpec(spin_tol_deg=180.0, **fixed))
    out = plan_welds(robot, [TOP], HOME, no_spin, OBSTACLES).outcome("top")
    assert not out.feasible and out.code is PlanReason.IK_FAILED
    p = plan_welds(robot, [TOP], HOME, free, OBSTACLES)
    got = p.outcome("top")
    assert got.feasible and abs(got.spin) > math.radians(30.0)
    weld = next(s for s in p.segments if s.kind == "weld")
    z_torch = robot.fk(weld.trajectory.q[0])[:3, 2]
    # Same torch axis, only turned about it: within the IK's rotation tolerance (0.01 deg = 1.7e-4 rad; the wrist
    # that keeps A6 in its hose window is solved to that tolerance, measured 1e-5).
    np.testing.assert_allclose(z_torch, weld.X_end[:3, 2], atol=2e-4)


def test_weld_runs_on_the_seam_at_the_travel_speed(robot: RobotModel, plan: WeldPlan) -> None:
    for seg in (s for s in plan.segments if s.kind == "weld"):
        task = {"top": TOP, "side": SIDE}[seg.seam_id]
        tr = seg.trajectory
        p = np.array([robot.fk(q)[:3, 3] for q in tr.q])
        assert np.max(point_line_distance(p, task.p_start, task.p_end)) < 1e-4  # within 0.1 mm of the seam
        a, b = (task.p_end, task.p_start) if plan.outcome(seg.seam_id).reversed else (task.p_start, task.p_end)
        np.testing.assert_allclose(p[[0, -1]], [a, b], atol=2e-5)  # IK tolerance 0.01 mm
        speed = np.linalg.norm(np.diff(p, axis=0), axis=1) / np.diff(tr.times)
        cruise = (tr.times[1:] > 0.1 * tr.duration) & (tr.times[1:] < 0.9 * tr.duration)
        assert np.all(np.abs(speed[cruise] / PROCESS.travel_speed - 1.0) < 0.02)
        assert np.max(speed) <= PROCESS.travel_speed * 1.02
        assert seg.arc_on and seg.speed == PROCESS.travel_speed
        assert np.all(tr.qd[0] == 0.0) and np.all(tr.qd[-1] == 0.0)  # arc on and off at exact stops


def test_no_limit_is_violated_when_resampled_at_1khz(robot: RobotModel, plan: WeldPlan) -> None:
    traj, arc = plan.joint_trajectory()
    t = np.arange(0.0, traj.duration, 0.001)
    q, qd, qdd = traj.sample(t)
    lim = robot.limits
    assert np.all(q >= lim.q_min - 1e-9) and np.all(q <= lim.q_max + 1e-9)
    assert np.all(np.abs(qd) <= lim.v_max * 1.01)
    assert np.all(np.abs(qdd) <= lim.a_max * 1.01)
    assert np.all(np.abs(np.diff(qdd, axis=0)) / 0.001 <= lim.j_max * 1.05)
    np.testing.assert_allclose(traj.q[0], HOME, atol=1e-12)
    np.testing.assert_allclose(traj.q[-1], HOME, atol=1e-12)
    # arc flags: on exactly over the weld segments
    weld_time = sum(s.trajectory.duration for s in plan.segments if s.arc_on)
    assert float(np.sum(np.diff(traj.times)[arc[:-1]])) == pytest.approx(weld_time, rel=1e-6)


def test_clean_plan_passes_the_gate(robot: RobotModel, plan: WeldPlan, checker: CollisionChecker) -> None:
    assert find_violations(robot, plan, HOME, checker=checker) == []
    check_plan(robot, plan, HOME, checker=checker)


@pytest.mark.parametrize("check", DEFAULT_CHECKS, ids=lambda c: type(c).__name__)
def test_every_gate_check_passes_the_clean_plan(
    robot: RobotModel, plan: WeldPlan, checker: CollisionChecker, check: Check
) -> None:
    assert check.violations(GateInput(robot, plan, HOME, checker, GateOptions())) == []


def test_the_gate_runs_only_the_checks_it_is_given(robot: RobotModel, plan: WeldPlan) -> None:
    q_now = HOME + np.array([0.0, 0.01, 0.0, 0.0, 0.0, 0.0])
    others = tuple(c for c in DEFAULT_CHECKS if type(c).__name__ != "StartState")
    assert find_violations(robot, plan, q_now, checks=others) == []


def _with_segment(plan: WeldPlan, k: int, tr: Trajectory) -> WeldPlan:
    """The plan with segment k's trajectory replaced and the start times after it shifted to match."""
    segs, t = [], 0.0
    for i, s in enumerate(plan.segments):
        s = replace(s, trajectory=tr if i == k else s.trajectory, t0=t)
        segs.append(s)
        t += s.trajectory.duration
    return replace(plan, segments=tuple(segs))


def _first_move(plan: WeldPlan) -> int:
    return next(i for i, s in enumerate(plan.segments) if s.kind == "move" and s.trajectory.duration > 0.3)


def test_gate_refuses_a_start_state_off_the_current_state(robot: RobotModel, plan: WeldPlan) -> None:
    q_now = HOME + np.array([0.0, 0.01, 0.0, 0.0, 0.0, 0.0])
    found = find_violations(robot, plan, q_now)
    assert [(v.kind, v.joint) for v in found] == [(ViolationKind.START_STATE, "joint_a2")]
    assert found[0].excess == pytest.approx(0.01)
    with pytest.raises(PlanError, match=re.escape("start_state joint_a2 at t = 0.000 s")) as refused:
        check_plan(robot, plan, q_now)
    assert isinstance(refused.value, GateRefusedError) and list(refused.value.violations) == found


def test_gate_refuses_a_move_over_the_velocity_limit(robot: RobotModel, plan: WeldPlan) -> None:
    k = _first_move(plan)
    tr = plan.segments[k].trajectory
    fast = _with_segment(plan, k, Trajectory(tr.times / 1.5, tr.q, tr.qd * 1.5, tr.qdd * 2.25))
    found = find_violations(robot, fast, HOME)
    vel = [v for v in found if v.kind is ViolationKind.VELOCITY]
    assert vel and all(fast.segments[k].t0 <= v.t <= fast.segments[k].t1 for v in vel)
    worst = max(vel, key=lambda v: v.excess / robot.limits.v_max[robot.joint_names.index(v.joint)])
    j = robot.joint_names.index(worst.joint)
    assert worst.excess == pytest.approx(np.max(np.abs(tr.qd[:, j])) * 1.5 - robot.limits.v_max[j] * 1.01, rel=0.05)
    with pytest.raises(GateRefusedError) as refused:
        check_plan(robot, fast, HOME)
    assert list(refused.value.violations) == found and "velocity" in refused.value.message


def test_gate_refuses_a_collision(robot: RobotModel, plan: WeldPlan) -> None:
    k = _first_move(plan)
    seg = plan.segments[k]
    q_mid = seg.trajectory.q[len(seg.trajectory.q) // 2]
    box = Part("INTRUDER", Box(make_pose(p=robot.fk(q_mid, "tool0")[:3, 3]), np.array([0.1, 0.1, 0.1])))
    found = find_violations(robot, plan, HOME, checker=CollisionChecker(robot, (*OBSTACLES, box)))
    hits = [v for v in found if v.kind is ViolationKind.COLLISION]
    assert hits and "INTRUDER" in hits[0].what and seg.t0 <= hits[0].t <= seg.t1
    assert all(v.kind is ViolationKind.COLLISION for v in found)


def test_gate_refuses_a_joint_jump(robot: RobotModel, plan: WeldPlan) -> None:
    k = _first_move(plan)
    tr = plan.segments[k].trajectory
    q = np.array(tr.q)
    q[len(q) // 2, 3] += 0.2  # A4 jumps 11.5 deg within one 1 ms sample
    jumped = _with_segment(plan, k, Trajectory(tr.times, q, tr.qd, tr.qdd))
    found = find_violations(robot, jumped, HOME, options=GateOptions())
    jumps = [v for v in found if v.kind is ViolationKind.JUMP]
    assert [v.joint for v in jumps] == ["joint_a4"] and jumps[0].what.startswith("moves 11.")
    # The spike has two edges (into the bad sample and out of it, 1 ms apart); which is the larger step depends on
    # which way A4 is moving there.
    t_spike = jumped.segments[k].t0 + tr.times[len(q) // 2]
    assert t_spike - 1e-9 <= jumps[0].t <= t_spike + 0.0011


def test_gate_refuses_arc_on_while_moving(robot: RobotModel, plan: WeldPlan) -> None:
    k = _first_move(plan)
    bad = replace(plan, segments=tuple(replace(s, arc_on=True) if i == k else s for i, s in enumerate(plan.segments)))
    found = [v for v in find_violations(robot, bad, HOME) if v.kind is ViolationKind.ARC]
    assert found[0].what == "arc on during a move segment"
    # the move is blended into the next motion: its arc would also go off while moving
    blended = bad.segments[k].zone_m > 0.0
    assert [v.what.startswith("arc off while moving") for v in found[1:]] == ([True] if blended else [])
    # a weld that does not start at rest: arc on while moving
    w = next(i for i, s in enumerate(plan.segments) if s.kind == "weld")
    tr = plan.segments[w].trajectory
    moving = _with_segment(plan, w, Trajectory(tr.times[5:] - tr.times[5], tr.q[5:], tr.qd[5:], tr.qdd[5:]))
    whats = [v.what for v in find_violations(robot, moving, HOME) if v.kind is ViolationKind.ARC]
    assert any(w.startswith("arc on while moving") for w in whats)


def test_scan_configuration_puts_the_camera_on_its_viewpoint(robot: RobotModel) -> None:
    s = sc.load("fence1")
    cam = s.cameras["eye_in_hand"]
    X_RC = np.linalg.inv(s.X_WR) @ cam.X_WC
    q = scan_configuration(robot, X_RC, HOME, rng=np.random.default_rng(0))
    X = robot.fk(q, "camera_optical")
    np.testing.assert_allclose(X[:3, 3], X_RC[:3, 3], atol=1e-4)
    assert float(X[:3, 2] @ X_RC[:3, 2]) > math.cos(math.radians(0.1))  # looking at the fence centre
    assert 1.0 <= math.dist(cam.eye_m, cam.target_m) <= 1.3
    assert CollisionChecker(robot, (TABLE,)).check(q) is None


def test_collisions_are_found_between_waypoints(robot: RobotModel) -> None:
    # Two clear configurations whose joint-space segment sweeps the torch through a thin plate between them.
    q_a = HOME + np.radians([-20.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    q_b = HOME + np.radians([20.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    p_mid = robot.fk(HOME)[:3, 3]
    plate = Part("PLATE", Box(make_pose(p=p_mid), np.array([0.01, 0.3, 0.3])))
    cc = CollisionChecker(robot, (plate,))
    assert cc.check(q_a) is None and cc.check(q_b) is None
    hit = cc.check_path(np.array([q_a, q_b]), np.array([0.0, 1.0]))
    assert hit is not None and hit.b == "PLATE" and 0.0 < hit.t < 1.0
    assert abs(float(hit.q[0] - HOME[0])) < np.radians(5.0)  # found near the middle of the sweep
    # the bound used to space the checks really bounds the motion of the torch tip
    dq = q_b - q_a
    moved = np.linalg.norm(robot.fk(q_b)[:3, 3] - robot.fk(q_a)[:3, 3])
    assert cc.motion_bound(dq) >= moved


def test_self_collision_and_the_tcp_clearance_zone(robot: RobotModel) -> None:
    cc = CollisionChecker(robot, OBSTACLES)
    folded = np.radians([0.0, -90.0, 158.0, 0.0, 130.0, 0.0])  # torch folded back onto the upper arm
    hit = cc.check(folded)
    assert hit is not None and {hit.a, hit.b} == {"link_2", "torch"}
    # The wire tip in the fillet is allowed (the nozzle's front is not checked) ...
    X = torch_poses(TOP.p_start, TOP.p_end, TOP.n_a, TOP.n_b, PROCESS)[0]
    assert cc.torch_clear(X, HOME) is None
    # ... but the torch pushed 40 mm into the joint hits the parts.
    X_in = X.copy()
    X_in[:3, 3] += 0.04 * X[:3, 2]
    deep = cc.torch_clear(X_in, HOME)
    assert deep is not None and deep.b in {"RAIL", "POST"}
