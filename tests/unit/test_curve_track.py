"""Curved seams on a linear track (docs/curves-welding.md section 11): the E1 values a curve is tried from, on a
made-up room profile and on a tube's fillet beside the KR 5 arc's reach (no IK: the reach pre-check's bound); a
curve no E1 brings in reach planned on the track beside a straight seam, refused with its reason, not dropped."""

from __future__ import annotations

import numpy as np
import pytest
from tiny_cell import HOME, OBSTACLES, TOP_SEAM, URDF

from cell import scenario as sc
from cell.motion.robot import RobotModel
from cell.planning.curves.track import curve_e1s, curve_probes
from cell.planning.plan import reach_model
from cell.planning.track import MARGIN, e1_grid, plan_on_track, reach_curves
from cell.process.torch import WeldProcess
from cell.types import SeamStatus
from cell.types.curve_estimate import CurveEstimate
from cell.types.plan import SeamTask
from cell.types.track import LinearTrack

TRACK = LinearTrack(np.array([1.0, 0.0, 0.0]), -0.5, 2.0, 0.8, 1.5, 6.0)


def _fillet(centre: tuple[float, float, float], radius: float = 0.03, n: int = 120) -> CurveEstimate:
    """A tube's foot on a plate: a closed circle about z, the tube's normals outward, the plate's up."""
    a = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    radial = np.stack([np.cos(a), np.sin(a), np.zeros(n)], axis=1)
    up = np.tile([0.0, 0.0, 1.0], (n, 1))
    p = np.asarray(centre) + radius * radial
    return CurveEstimate("TUBE>PLATE", SeamStatus.FOUND, p_RS=p, n_abutting_R=radial, n_receiving_R=up,
                         closed=True, sigma_m=np.full(n, 1e-4), end_sigma_m=(0.0, 0.0), confidence=1.0)  # fmt: skip


def test_a_curve_is_tried_where_a_group_stands_then_where_it_has_most_room() -> None:
    grid = np.round(np.arange(-0.5, 2.0001, 0.01), 10)
    room = 0.5 * (grid - 0.6) ** 2 - 0.3  # most room (0.3 m) at 0.6; margin (0.15 m) within 0.55 m of it
    assert curve_e1s(room, grid, [0.0], MARGIN) == pytest.approx((0.6, 0.5, 0.7))  # E1 = 0: too little room
    assert curve_e1s(room, grid, [0.0, 0.3], MARGIN) == pytest.approx((0.3, 0.6, 0.5))  # a group's E1 first
    assert curve_e1s(room, grid, [0.3, 0.2], MARGIN, tries=2) == pytest.approx((0.3, 0.6))  # the roomier group
    never = 2.0 * (grid - 0.6) ** 2 - 0.1  # never 0.15 m of room: no group's E1; 0.05 m less than its best or more
    assert curve_e1s(never, grid, [0.3, 0.0], MARGIN) == pytest.approx((0.6, 0.5, 0.7))
    assert curve_e1s(8.0 * never, grid, [0.0], MARGIN) == pytest.approx((0.6,))  # too little room 0.1 m away
    hopeless = np.full(len(grid), 0.02)  # every torch out of reach everywhere: its best E1 only
    assert curve_e1s(room, grid, [0.0], MARGIN, sure=hopeless) == pytest.approx((0.6,))


def test_a_tube_beyond_the_fixed_reach_is_tried_with_the_base_abreast_of_it() -> None:
    """A 60 mm tube 1.6 m along the track and 0.6 m out from it: no torch reaches its far side from E1 = 0 for sure;
    its first E1 puts the base within a few centimetres of abreast of it, every try with the whole fillet in reach."""
    reach = reach_model(RobotModel.from_urdf(URDF))
    assert reach is not None
    process = WeldProcess.from_spec(sc.ProcessSpec())
    curve = _fillet((1.6, 0.6, 0.01))
    probes = curve_probes(curve)
    assert 19 <= len(probes) <= 21  # every 10 mm round its 188 mm
    grid = e1_grid(TRACK)
    room = reach_curves(reach, probes, [process] * len(probes), TRACK, grid).max(axis=0)
    sure = reach_curves(reach, probes, [process] * len(probes), TRACK, np.array([0.0]), cone=True)
    assert sure.max() > 0.0  # from E1 = 0 some of it is out of reach whatever the torch
    tries = curve_e1s(room, grid, [0.0], MARGIN)
    assert len(tries) == 3 and abs(tries[0] - 1.6) <= 0.05
    assert sorted(abs(e - tries[0]) for e in tries[1:]) == pytest.approx([0.1, 0.1])
    for e in tries:
        assert room[int(np.argmin(np.abs(grid - e)))] <= -MARGIN


def test_a_curve_out_of_reach_from_every_e1_is_tried_once_and_refused_beside_the_welded_seams() -> None:
    """The tiny cell's top seam (welded from E1 = 0) and a tube 2.4 m beyond the track's end: every torch is out of
    reach of it wherever the carriage stands, so it is planned once, at its best E1, and refused with the planner's
    code; its outcome follows the straight seam's, and the plan welds the seam alone."""
    robot = RobotModel.from_urdf(URDF)
    track = LinearTrack(np.array([1.0, 0.0, 0.0]), -0.5, 1.2, 0.8, 1.5, 6.0)
    process = WeldProcess.from_spec(sc.ProcessSpec())
    sid, a, b, n_a, n_b = TOP_SEAM
    far = _fillet((3.6, 0.8, 0.05))
    plan = plan_on_track(robot, [SeamTask(sid, a, b, n_a, n_b)], HOME, process, OBSTACLES, track=track, curves=[far])
    assert [o.seam_id for o in plan.seams] == [sid, far.id]
    seam, curve = plan.seams
    assert seam.feasible and not curve.feasible and curve.code is not None
    assert "tried from E1" not in curve.reason  # one try, at its best E1
    assert {s.seam_id for s in plan.segments if s.arc_on} == {sid}
    assert plan.track is track and {s.e1_end for s in plan.segments if s.arc_on} == {0.0}


def test_a_circles_joints_are_found_with_the_base_where_the_track_has_it() -> None:
    """A weld that turns A1 alone sweeps a circle about the base's axis; on a track 0.5 m along, its planned path
    (in R) is 0.5 m off the arm's own kinematics: each circular move's joints are those of the trajectory where it
    passes the move's end, found with the base moved (without it, the nearest sample is the wrong one)."""
    from cell.export.circles import base_at, curve_moves
    from cell.geometry import make_pose
    from cell.types.plan import Segment, WeldPlan
    from cell.types.trajectory import Trajectory

    robot = RobotModel.from_urdf(URDF)
    track = LinearTrack(np.array([1.0, 0.0, 0.0]), -0.5, 1.2, 0.8, 1.5, 6.0)
    n = 301
    q = np.tile(np.asarray(HOME, dtype=float), (n, 1))
    q[:, 0] += np.linspace(-1.2, 1.2, n)  # A1 through 138 deg: a circle about the base's z axis
    tr = Trajectory(np.linspace(0.0, 3.0, n), q, np.zeros_like(q), np.zeros_like(q)).with_e1(0.5)
    d_R = track.offset_R(0.5)
    X_path = np.stack([make_pose(p=d_R) @ robot.fk(qi) for qi in q])
    seg = Segment("weld", "C", tr, 0.0, X_path[-1], speed=0.01, arc_on=True, X_path=X_path)
    plan = WeldPlan(robot.joint_names, np.asarray(HOME, dtype=float), (seg,), (), (), 0.0, track=track)
    np.testing.assert_allclose(base_at(plan, seg), d_R)
    moves = curve_moves(seg, robot, base_at(plan, seg))
    assert len(moves) == 2 and all(m.kind == "CIRC" for m in moves)  # 138 deg: two circular moves of 69
    k = int(np.argmin(np.linalg.norm(X_path[:, :3, 3] - moves[0].X_end[:3, 3], axis=1)))
    np.testing.assert_allclose(moves[0].q_end, q[k], atol=1e-9)
    assert 0.4 * n < k < 0.6 * n
    wrong = curve_moves(seg, robot)[0].q_end  # as on a fixed base: a sample far from the move's end
    assert abs(wrong[0] - q[k][0]) > 0.1
