"""A curved seam planned from its reach map (cell/planning/curves/reach.py, arcs.py): the fewest stretches that
cover a loop with the restart overlap, the share of a loop no setting reaches, and on the KR 5 arc a tube's foot
welded whole (its arcs' torch on the circle, covering it with the overlap) or, with a gusset across it, refused
with the share reached; a second pass laid and measured at its offset."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from tiny_cell import HOME, TABLE, URDF

import cell.planning.curves.reach as reach_module
from cell import scenario as sc
from cell.config.motion import PlanOptions
from cell.geometry import make_pose
from cell.motion.collision import CollisionChecker
from cell.motion.ik import solve_ik
from cell.motion.robot import RobotModel
from cell.planning.curves.arcs import _gap, _windows, plan_arcs
from cell.planning.curves.reach import Miss, Run, cover, pinch, share
from cell.planning.memo import IKMemo
from cell.planning.plan import reach_model
from cell.planning.seam_search import SeamSearch
from cell.process.curve_quality import pass_truth
from cell.process.torch import WeldProcess
from cell.process.torch_orientations import Candidate
from cell.types import Box, Part, SeamStatus
from cell.types.curve_estimate import CurveEstimate
from cell.types.plan import PlanReason
from cell.types.procedure import WeldPass, WeldProcedure

OVERLAP_M = 0.01
C0 = Candidate(False, 0.0, 0.0, 0.0)
C1 = Candidate(True, 0.5, 0.0, 0.0)
CENTRE_R = np.array([0.1, 0.85, 0.0])  # the tube's foot, on the table in front of the robot
R_M = 0.04


def _run(a: float, b: float, cand: Candidate = C0) -> Run:
    return Run(cand, a, b, np.zeros(6))


def test_the_fewest_stretches_cover_the_loop_each_restarting_over_the_last() -> None:
    runs = [_run(0.0, 0.3), _run(0.25, 0.7, C1), _run(0.6, 0.95), _run(0.65, 1.05), _run(0.1, 0.2)]
    got = cover(runs, 1.0, True, OVERLAP_M, 4)
    assert got is not None and len(got) == 3
    for prev, nxt in itertools.pairwise(got):
        assert nxt.a_m <= prev.b_m - OVERLAP_M + 1e-9  # each restarts on the last bead by the overlap
    assert got[-1].b_m >= got[0].a_m + 1.0 + OVERLAP_M - 1e-9  # and the last runs on over the first's start


def test_no_cover_without_the_overlap_or_beyond_the_arcs_allowed() -> None:
    touching = [_run(0.0, 0.5), _run(0.5, 1.0)]  # they meet, but no restart overlaps a bead
    assert cover(touching, 1.0, True, OVERLAP_M, 4) is None
    short = [_run(0.2 * k, 0.2 * k + 0.25) for k in range(5)]
    assert cover(short, 1.0, True, OVERLAP_M, 4) is None  # five arcs needed
    assert len(cover(short, 1.0, True, OVERLAP_M, 5) or []) == 5


def test_an_open_curve_is_covered_end_to_end() -> None:
    runs = [_run(0.0, 0.6), _run(0.55, 1.0, C1)]
    got = cover(runs, 1.0, False, 0.0, 4)
    assert got is not None and [r.cand for r in got] == [C0, C1]
    assert cover([_run(0.05, 1.0)], 1.0, False, 0.0, 4) is None  # its start is not held


def test_a_point_every_stretch_gives_out_near_is_passed_by_no_cover_however_many_arcs() -> None:
    # every point held, but both stretches through 1.0 (= 0) give out 2 mm from it: a restart there overlaps 4 mm
    runs = [_run(0.1, 1.002), _run(0.998, 1.15, C1), *(_run(0.1 * k, 0.1 * k + 0.3) for k in range(1, 7))]
    assert share(runs, 1.0, True) == 1.0
    at = pinch(runs, 1.0, OVERLAP_M)
    assert at is not None and min(at[0], 1.0 - at[0]) <= 0.0005 and at[1] == pytest.approx(0.002, abs=0.0006)
    assert cover(runs, 1.0, True, OVERLAP_M, 20) is None
    assert cover(runs, 1.0, True, 0.003, 4) is not None and pinch(runs, 1.0, 0.003) is None  # a 3 mm restart would
    short = [_run(0.2 * k, 0.2 * k + 0.25) for k in range(5)]  # five arcs needed, each junction 50 mm deep
    assert pinch(short, 1.0, OVERLAP_M) is None and pinch([_run(0.0, 0.5)], 1.0, OVERLAP_M) is None  # not a gap


def test_a_curve_held_all_round_but_pinched_is_refused_where_and_why_and_walked_finer_there() -> None:
    est = _foot()
    total = est.length_m
    runs = [_run(0.02, total + 0.001), _run(total - 0.001, total + 0.05, C1)]
    misses = [Miss(total - 0.002, PlanReason.COLLISION, "torch vs POST")] * 3 + [Miss(0.1, PlanReason.IK_FAILED)] * 5
    f = _gap(runs, misses, est, OVERLAP_M)
    assert f.code is PlanReason.COLLISION and "torch vs POST" in f.where and "gives out within 1.0 mm" in f.where
    assert np.linalg.norm(f.p_R - est.p_RS[0]) < 0.002
    [(lo, hi)] = _windows(runs, est, OVERLAP_M)  # walked again with finer settings: the overlap and 15 mm either side
    assert lo == pytest.approx(-0.025, abs=0.001) or lo == pytest.approx(total - 0.025, abs=0.001)
    assert hi - lo == pytest.approx(0.05, abs=0.001)


def test_share_counts_what_some_stretch_holds() -> None:
    assert share([_run(0.0, 0.3), _run(0.9, 1.2)], 1.0, True) == pytest.approx(0.4, abs=0.002)
    assert share([_run(0.0, 0.3), _run(0.2, 0.4)], 1.0, False) == pytest.approx(0.4, abs=0.002)


def _foot(n: int = 200) -> CurveEstimate:
    """A 40 mm tube's fillet on the table: a circle round CENTRE_R, the tube's and the table's normals."""
    a = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
    radial = np.column_stack([np.cos(a), np.sin(a), np.zeros(n)])
    up = np.tile([0.0, 0.0, 1.0], (n, 1))
    return CurveEstimate("TUBE>TABLE:circle", SeamStatus.FOUND, "", None, CENTRE_R + R_M * radial, radial, up, True,
                         np.full(n, 1e-4), (0.0, 0.0), 1.0)  # fmt: skip


def _search(*parts: Part, spec: sc.ProcessSpec | None = None) -> SeamSearch:
    robot = RobotModel.from_urdf(URDF)
    opt = PlanOptions()
    tube = Part("TUBE", Box(make_pose(p=CENTRE_R + np.array([0.0, 0.0, 0.1])), np.array([0.05, 0.05, 0.2])))
    checker = CollisionChecker(robot, (TABLE, tube, *parts), opt.collision)
    process = WeldProcess.from_spec(spec or sc.ProcessSpec())
    return SeamSearch(robot, process, checker, opt, np.random.default_rng(0), reach_model(robot))


def test_a_tube_foot_is_welded_whole_in_overlapping_arcs_each_pass_at_its_offset() -> None:
    est = _foot()
    cap = WeldPass(lateral_mm=1.5, lift_mm=2.0, travel_speed_mm_s=6.0)
    got = plan_arcs(_search(), est, HOME, WeldProcedure(name="two passes", passes=(WeldPass(), cap)))
    assert got.whole and got.share == 1.0 and 1 <= len(got.arcs) <= 4
    covered = np.zeros(180, dtype=bool)  # 2 deg bins
    for arc, (root, second) in got.arcs:
        tip = root.X_weld[:, :3, 3] - CENTRE_R
        assert np.allclose(np.linalg.norm(tip[:, :2], axis=1), R_M, atol=2e-4)  # the root pass on the circle
        assert np.allclose(tip[:, 2], 0.0, atol=2e-4)
        # the cap pass in the local cross-section: 1.5 mm across the 45 deg bisector towards the tube, 2 mm up it
        off = second.X_weld[:, :3, 3] - CENTRE_R
        radial = np.linalg.norm(off[:, :2], axis=1) - R_M
        assert np.allclose(radial, (2.0 - 1.5) * math.sqrt(0.5) * 1e-3, atol=2e-4)
        assert np.allclose(off[:, 2], (2.0 + 1.5) * math.sqrt(0.5) * 1e-3, atol=2e-4)
        ang = np.degrees(np.arctan2(arc.p_RS[:, 1] - CENTRE_R[1], arc.p_RS[:, 0] - CENTRE_R[0]))
        covered[np.mod(np.floor(ang / 2.0).astype(int), 180)] = True
    assert covered.all()
    assert sum(a.length_m for a, _ in got.arcs) >= est.length_m + OVERLAP_M - 1e-3


def test_a_pass_is_measured_against_the_true_curve_moved_by_its_offset() -> None:
    est = _foot()
    truth = np.asarray(est.p_RS)
    moved = pass_truth(truth, est.p_RS, est.n_abutting_R, est.n_receiving_R, 0.0015, 0.002)
    radial = np.linalg.norm((moved - CENTRE_R)[:, :2], axis=1) - R_M
    assert np.allclose(radial, 0.5e-3 * math.sqrt(0.5), atol=1e-5)
    assert np.allclose(moved[:, 2], 3.5e-3 * math.sqrt(0.5), atol=1e-5)
    assert pass_truth(truth, est.p_RS, est.n_abutting_R, est.n_receiving_R, 0.0, 0.0) is truth


GUSSET = Part("GUSSET", Box(make_pose(p=CENTRE_R + np.array([0.0, 0.09, 0.05])), np.array([0.008, 0.1, 0.1])))


def test_a_gusset_across_the_foot_is_refused_with_the_share_reached_when_the_process_refuses_a_remainder(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Refused with the share reached; planned again with the first plan's IK memo (the safety gate's next
    round), the same answer without one IK of the reach map asked again, and none kept for the base moved."""
    stiff = sc.ProcessSpec(travel_angle_tol_deg=0.0, work_angle_tol_deg=0.0, curve_remainder="refuse")  # quicker
    search = _search(GUSSET, spec=stiff)
    memo = IKMemo(search.robot, search.checker, search.opt)
    search = SeamSearch(search.robot, search.process, search.checker, search.opt, search.rng, search.reach, memo)
    got = plan_arcs(search, _foot(), HOME)
    assert not got.whole and not got.partial and got.failure is not None and got.arcs == ()
    assert 0.6 < got.share < 1.0
    kept, asked = len(memo._kept), []
    assert kept > 100 and memo.hits > 0  # the stages' walks ask some stations again within one plan too

    def counted(*args: object, **kw: object) -> object:
        asked.append(args)
        return solve_ik(*args, **kw)  # type: ignore[arg-type]

    monkeypatch.setattr(reach_module, "solve_ik", counted)
    again = plan_arcs(search, _foot(), HOME)
    assert asked == [] and len(memo._kept) == kept
    assert again.share == got.share and again.failure is not None and got.failure is not None
    assert (again.failure.code, again.failure.where) == (got.failure.code, got.failure.where)
    np.testing.assert_array_equal(again.failure.p_R, got.failure.p_R)
    search.checker.set_base(np.array([0.0, 0.0, 0.001]))  # another place of the arm: nothing kept answers it
    try:
        plan_arcs(search, _foot(), HOME)
    finally:
        search.checker.set_base(np.zeros(3))
    assert len(asked) > 100
    other = CollisionChecker(search.robot, (TABLE,), search.opt.collision)
    assert not memo.fits(search.robot, other, search.opt)
    assert SeamSearch(search.robot, search.process, other, search.opt, search.rng, None, memo).memo is None


def test_a_gusset_across_the_foot_is_welded_up_to_it_the_rest_left_for_a_manual_weld() -> None:
    from cell.process.curve_quality import unwelded_stretches

    stiff = sc.ProcessSpec(travel_angle_tol_deg=0.0, work_angle_tol_deg=0.0)  # the nominal angles only: quicker
    est = _foot()
    got = plan_arcs(_search(GUSSET, spec=stiff), est, HOME)
    assert got.partial and not got.whole and got.failure is not None and 2 <= len(got.arcs) <= 8
    assert 0.7 < got.share < 0.8  # measured 0.73: 3 arcs, 68 mm of 251 left (each 5 mm off a gap's edge)
    gusset = [r for r in got.remainder if "torch vs GUSSET" in r.why]
    assert len(gusset) == 1 and gusset[0].code is PlanReason.COLLISION
    # where the planned arcs' TCP never passes on the true curve is the remainder, within 2 mm at each end
    tcp = np.vstack([sols[0].X_weld[:, :3, 3] for _, sols in got.arcs])
    measured = unwelded_stretches(tcp, np.asarray(est.p_RS), True)
    assert len(measured) == len(got.remainder)
    for (lo, hi), r in zip(measured, got.remainder, strict=True):
        assert abs(lo - r.from_m) < 0.002 and abs(hi - r.to_m) < 0.002


def test_a_seam_is_welded_in_arcs_whole_or_not_at_all() -> None:
    from cell.planning.curves import whole_or_none
    from cell.types.plan import PlanReason, SeamOutcome

    seam = "TUBE>TABLE:circle"
    solved = {f"{seam}#arc1": 1, f"{seam}#arc3": 3, "OTHER": 0}
    parts = dict(solved)
    outcomes = {f"{seam}#arc2": SeamOutcome(f"{seam}#arc2", False, "timing: A1 too fast", np.zeros(3),
                                            code=PlanReason.TIMING)}  # fmt: skip
    whole_or_none(solved, outcomes, parts)
    assert solved == parts == {"OTHER": 0}  # the seam's other arcs dropped with the failed one
    assert list(outcomes) == [seam] and not outcomes[seam].feasible
    assert outcomes[seam].code is PlanReason.TIMING and outcomes[seam].reason.startswith("arc 2: timing")
