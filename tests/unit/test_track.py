"""The linear track (docs/track.md): grouping seams along it and each group's E1, the track's jerk-limited move, the
arm's IK and collisions with its base moved, a plan on the track (the safety gate with the base where E1 puts it)
and E1 in the KRL and RAPID programs. The tiny cell moved 1.6 m along x: out of reach from the base at R."""

from __future__ import annotations

import re

import numpy as np
import pytest
from tiny_cell import HOME, OBSTACLES, SIDE_SEAM, TOP_SEAM, URDF

from cell import scenario as sc
from cell.config.motion import PlanOptions
from cell.errors import IKError, ScenarioError
from cell.export.krl import krl_program
from cell.export.program import ProgramJob
from cell.export.rapid import rapid_text
from cell.gate import find_violations
from cell.geometry import make_pose
from cell.motion.collision import CollisionChecker
from cell.motion.ik import solve_ik
from cell.motion.robot import RobotModel
from cell.planning.plan import plan_welds, reach_model
from cell.planning.reach import seam_reach
from cell.planning.track import MARGIN, e1_grid, group_seams, plan_on_track, reach_curves, track_move
from cell.planning.track_moves import TrackMoves
from cell.process.torch import WeldProcess
from cell.types import Box, Part
from cell.types.plan import PlanReason, SeamTask
from cell.types.track import LinearTrack

SHIFT = np.array([1.6, 0.0, 0.0])  # [m] the tiny cell's part moved along the track's axis (out of the fixed reach)
TRACK = LinearTrack(np.array([1.0, 0.0, 0.0]), -0.5, 1.2, 0.8, 1.5, 6.0)
PROCESS = WeldProcess.from_spec(sc.ProcessSpec())


def _moved(seam: tuple[str, np.ndarray, np.ndarray, np.ndarray, np.ndarray], d: np.ndarray) -> SeamTask:
    sid, a, b, n_a, n_b = seam
    return SeamTask(sid, a + d, b + d, n_a, n_b)


def _moved_part(p: Part, d: np.ndarray) -> Part:
    if p.name == "TABLE":  # a table long enough for both places
        return Part("TABLE", Box(make_pose(p=[0.8, 1.05, -0.05]), np.array([3.6, 1.2, 0.1])))
    return Part(p.name, Box(make_pose(p=np.asarray(p.box.X_AB)[:3, 3] + d), np.asarray(p.box.size)))


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


@pytest.fixture(scope="module")
def far_plan(robot: RobotModel) -> tuple[object, CollisionChecker]:
    """The tiny cell's two seams, 0.9 m along the track, planned on it (one plan, shared)."""
    obstacles = tuple(_moved_part(p, SHIFT) for p in OBSTACLES)
    checker = CollisionChecker(robot, obstacles)
    tasks = [_moved(TOP_SEAM, SHIFT), _moved(SIDE_SEAM, SHIFT)]
    plan = plan_on_track(robot, tasks, HOME, PROCESS, obstacles, track=TRACK, checker=checker)
    return plan, checker


def test_groups_cover_every_seam_with_the_fewest_e1(robot: RobotModel) -> None:
    reach = reach_model(robot)
    assert reach is not None
    grid = e1_grid(TRACK)
    assert grid[0] == pytest.approx(-0.5) and grid[-1] == pytest.approx(1.2) and 0.0 in grid
    xs = [-0.5, 0.0, 0.5, 1.6, 2.0, 2.4, 3.2]  # seams along the axis; the last beyond the track's reach too
    tasks = [_moved(TOP_SEAM, np.array([x, 0.0, 0.0])) for x in xs]
    curves = reach_curves(reach, tasks, [PROCESS] * len(tasks), TRACK, grid)
    groups = group_seams([t.id + str(i) for i, t in enumerate(tasks)], curves, grid)
    e1 = {sid: g.e1 for g in groups for sid in g.seam_ids}
    assert sorted(e1) == sorted(t.id + str(i) for i, t in enumerate(tasks))  # every seam in one group
    assert [e1[f"top{i}"] for i in range(3)] == [0.0] * 3  # 0 where it serves: planned as without a track
    assert len(groups) == 2 and groups[1].e1 == pytest.approx(1.2)  # one more E1 for the three far ones
    for i, t in enumerate(tasks[:6]):  # at its group's E1 every reachable seam passes the reach pre-check
        shifted = reach_model(robot.shifted(TRACK.offset_R(e1[t.id + str(i)])))
        assert shifted is not None and seam_reach(shifted, t, PROCESS) is None, t.id + str(i)
        assert (curves[i, list(grid).index(0.0)] <= -MARGIN) == (i < 3)  # room at E1 = 0 for the first three
    sure = reach_curves(reach, tasks[6:], [PROCESS], TRACK, grid, cone=True)
    assert sure.min() > 0.0 and e1["top6"] == groups[1].e1  # out of reach for sure: refused where least out


def test_track_move_is_jerk_limited_rest_to_rest() -> None:
    tr = track_move(TRACK, HOME, 0.2, -0.4, 0.004)
    e, t = np.asarray(tr.e1), tr.times
    assert e[0] == 0.2 and e[-1] == -0.4 and np.all(tr.q == HOME)
    v = np.diff(e) / np.diff(t)
    a = np.diff(v) / np.diff(t[1:])
    assert np.abs(v).max() <= TRACK.v_max * 1.001 and np.abs(a).max() <= TRACK.a_max * 1.05
    assert abs(v[0]) < 1e-3 and abs(v[-1]) < 1e-3  # from rest to rest
    # 0.6 m at 0.8 m/s, 1.5 m/s^2, 6 m/s^3: longer than the cruise alone, shorter than a triangle at a_max
    assert 0.6 / 0.8 < tr.duration < 0.6 / 0.8 + 0.8 / 1.5 + 1.5 / 6.0 + 0.01


def test_ik_and_collisions_with_the_base_moved(robot: RobotModel) -> None:
    X = robot.fk(HOME)
    X_far = X.copy()
    X_far[:3, 3] += SHIFT + np.array([0.0, 0.35, -0.2])  # far out along the track
    with pytest.raises(IKError):
        solve_ik(robot, X_far, HOME)
    moved = robot.shifted(SHIFT)
    q = solve_ik(moved, X_far, HOME)
    assert np.allclose(moved.fk(q)[:3, 3], X_far[:3, 3], atol=1e-4)
    assert np.allclose(moved.fk(q)[:3, 3] - robot.fk(q)[:3, 3], SHIFT)  # the same joints, the base moved
    d = np.array([0.9, 0.0, 0.0])
    box = Part("BOX", Box(make_pose(p=robot.fk(HOME, "link_3")[:3, 3] + d), np.array([0.1, 0.1, 0.1])))
    checker = CollisionChecker(robot, (box,))
    assert checker.check(HOME) is None  # the box stands where the arm's elbow will be
    checker.set_base(d)
    hit = checker.check(HOME)
    assert hit is not None and hit.b == "BOX"
    checker.set_base(np.zeros(3))
    track = LinearTrack(np.array([1.0, 0.0, 0.0]), 0.0, 1.0, 0.8, 1.5, 6.0)
    ride = checker.check_trajectory(track_move(track, HOME, 0.0, 0.9, 0.004), track)  # the track carries it in
    assert ride is not None and ride.b == "BOX" and 0.0 < ride.t < 2.0 and ride.q.shape == (6,)
    assert np.all(checker.base_offset_R == 0.0)  # the base is left where it was


def test_plan_on_the_track_welds_what_the_fixed_base_cannot(robot: RobotModel, far_plan: tuple) -> None:
    plan, checker = far_plan
    obstacles = tuple(_moved_part(p, SHIFT) for p in OBSTACLES)
    tasks = [_moved(TOP_SEAM, SHIFT), _moved(SIDE_SEAM, SHIFT)]
    fixed = plan_welds(robot, tasks, HOME, PROCESS, obstacles)
    assert [o.code for o in fixed.seams] == [PlanReason.BEYOND_REACH] * 2
    assert [o.feasible for o in plan.seams] == [True, True] and plan.track == TRACK
    moving = [s for s in plan.segments if s.trajectory.e1 is not None and np.ptp(s.trajectory.e1) > 0.0]
    track_moves = [s for s in moving if s.kind == "move"]
    assert len(track_moves) == 2 and track_moves[-1].e1_end == 0.0  # out and back home
    for move in track_moves:  # the arm and the carriage together (one PTP over A1..A6 and E1), not one then the other
        tr = move.trajectory
        assert float(np.ptp(tr.q, axis=0).max()) > 0.5
        v = np.diff(np.asarray(tr.e1)) / np.diff(tr.times)
        assert np.abs(v).max() <= TRACK.v_max * 1.001 and abs(v[0]) < 1e-3
        assert abs(v[-1]) < 1e-3 or move.zone_m > 0.0  # at rest at its end, or approximated there
    out = plan.segments.index(track_moves[0])  # blended into the approach: E1 still moving as the arm joins it
    nxt = plan.segments[out + 1]
    assert track_moves[0].zone_m > 0.0 and nxt.kind == "approach" and nxt.link_s > 0.0 and nxt in moving
    assert track_moves[0].e1_target == pytest.approx(nxt.e1_end) and nxt.e1_end != track_moves[0].trajectory.e1[-1]
    assert track_moves[0] is plan.segments[0] and track_moves[0].seam_id == plan.order[0]
    e_weld = {s.e1_end for s in plan.segments if s.arc_on}
    assert len(e_weld) == 1 and 0.8 < e_weld.pop() <= 1.2
    traj, _ = plan.joint_trajectory()
    assert traj.e1 is not None and traj.e1[0] == 0.0 and traj.e1[-1] == 0.0 and np.all(traj.q[0] == HOME)
    for seg in plan.segments:  # the welds' poses are in R, the base where E1 put it
        if seg.kind == "weld":
            arm = robot.shifted(TRACK.offset_R(seg.e1_end))
            assert np.allclose(arm.fk(seg.trajectory.q[-1]), seg.X_end, atol=1e-4)  # IK: 0.01 mm
    assert find_violations(robot, plan, HOME, checker=checker) == []


def test_krl_and_rapid_carry_e1(robot: RobotModel, far_plan: tuple) -> None:
    plan, _ = far_plan
    src, dat = krl_program(plan, robot, "TRACK")
    assert ";- Linear track E1 (KL-style, mathematically coupled): axis [1.0000, 0.0000, 0.0000]" in src
    assert "software limits -500.0 .. 1200.0 mm" in src
    e1 = [float(m) for m in re.findall(r"DECL E6(?:POS|AXIS) XP\d+=\{.*?E1 ([-\d.]+)", dat)]
    weld_e1 = {round(s.e1_end * 1000.0, 1) for s in plan.segments if s.arc_on}
    assert e1 and set(e1) == weld_e1 and "(ABS(XHOME.E1 - XHOME_PLAN.E1) > 0.5)" in src
    assert "track to E1 = " in src
    mod = rapid_text(ProgramJob(plan, robot, "TRACK"))
    eax = {float(m) for m in re.findall(r"robtarget p\d+ := \[.*\],\[([-\d.]+),9E9", mod)}
    assert eax == weld_e1 and "jHome := [[" in mod and ",[0.000,9E9" in mod


def test_the_scenario_states_the_track() -> None:
    text = (sc.SCENARIO_DIR / "fence1.yaml").read_text()
    anchor = "  X_WR: {xyz_m: [0.15, -1.05, 0.90]}"
    assert anchor in text
    ok = sc.from_yaml(text.replace(anchor, anchor + "\n  track: {min_mm: -300, max_mm: 1500}"), sc.SCENARIO_DIR)
    assert ok.robot.track is not None
    track = ok.robot.track.track(ok.X_WR)
    assert (track.e1_min, track.e1_max, track.v_max) == (-0.3, 1.5, 0.5) and np.allclose(track.axis_R, [1, 0, 0])
    with pytest.raises(ScenarioError, match="min_mm"):  # E1 = 0 (the base at X_WR) must lie on the track
        sc.from_yaml(text.replace(anchor, anchor + "\n  track: {min_mm: 100, max_mm: 1500}"), sc.SCENARIO_DIR)


def test_between_groups_the_arm_lifts_over_what_the_straight_move_would_cross(robot: RobotModel) -> None:
    # The torch low over the table at both ends, a low wall across its way along the track: the seven-axis move
    # straight along would drag it through; up above the wall, along with the carriage, down is free.
    X = robot.fk(HOME)
    X[:3, 3] = [X[0, 3], 0.95, 0.06]
    q_low = solve_ik(robot, X, HOME, rng=np.random.default_rng(0))
    wall = Part("WALL", Box(make_pose(p=[X[0, 3] + 0.3, 0.95, 0.05]), np.array([0.02, 0.4, 0.1])))
    table = Part("TABLE", Box(make_pose(p=[0.8, 1.05, -0.05]), np.array([3.6, 1.2, 0.1])))
    checker = CollisionChecker(robot, (table, wall))
    moves = TrackMoves(robot, TRACK, checker, (table, wall), PROCESS.stickout, HOME, PlanOptions(dt=0.004))
    straight = moves.move(q_low, 0.0, q_low, 0.6)
    assert not moves.free(straight)
    lifted = moves.lifted(q_low, 0.0, q_low, 0.6)
    assert lifted is not None and [float(np.ptp(np.asarray(tr.e1))) for tr in lifted] == [0.0, 0.6, 0.0]
    top = TRACK.X_R_Re(0.0) @ robot.fk(lifted[0].q[-1])
    assert top[2, 3] == pytest.approx(0.1 + 0.05, abs=1e-4)  # 50 mm over the wall, the lowest via tried
    assert np.allclose(lifted[-1].q[-1], q_low) and all(moves.free(tr) for tr in lifted)
