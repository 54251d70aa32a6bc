"""Splitting a curved seam the arm cannot weld in one go into reachable arcs (cell/planning/curves/split.py): the
arcs cover the loop with the restart overlap, at most four, each one the planner accepted; a part no arc reaches
is reported with the share the arcs cover."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cell.planning.curves.split import MAX_ARCS, seam_of, split_curve, sub_arc
from cell.planning.failures import SeamFailure
from cell.planning.seam_search import SeamSolution
from cell.process.torch_orientations import Candidate
from cell.types import SeamStatus
from cell.types.curve_estimate import CurveEstimate
from cell.types.plan import PlanReason, SeamTask

R_M = 0.05
OVERLAP_M = 0.01


def _circle(n: int = 300) -> CurveEstimate:
    a = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
    p = np.column_stack([R_M * np.cos(a), R_M * np.sin(a), np.zeros(n)])
    n_tube = p / R_M
    n_plate = np.tile([0.0, 0.0, 1.0], (n, 1))
    return CurveEstimate("TUBE>PLATE:circle", SeamStatus.FOUND, "", None, p, n_tube, n_plate, True,
                         np.full(n, 1e-4), (0.0, 0.0), 1.0)  # fmt: skip


def _angles(arc: CurveEstimate) -> np.ndarray:
    return np.mod(np.arctan2(arc.p_RS[:, 1], arc.p_RS[:, 0]), 2.0 * math.pi)


def _planner(max_len_m: float, blocked: tuple[float, float] | None = None):  # type: ignore[no-untyped-def]
    """A torch search that accepts an arc no longer than max_len_m and clear of the blocked angles [rad]."""
    calls: list[CurveEstimate] = []

    def plan(arc: CurveEstimate) -> SeamSolution | SeamFailure:
        calls.append(arc)
        ang = _angles(arc)
        hit = blocked is not None and bool(np.any((ang > blocked[0]) & (ang < blocked[1])))
        if arc.length_m > max_len_m or hit:
            return SeamFailure(PlanReason.IK_FAILED, "IK did not converge", arc.p_RS[-1], arc.length_m)
        task = SeamTask(arc.id, arc.p_RS[0], arc.p_RS[-1], arc.n_abutting_R[0], arc.n_receiving_R[0])
        eye = np.eye(4)
        return SeamSolution(task, Candidate(False, 0.0, 0.0, 0.0), eye[None], eye[:1, :6], eye[:1, :6],
                            eye[:1, :6], eye, eye)  # fmt: skip

    plan.calls = calls  # type: ignore[attr-defined]
    return plan


def _covered(arcs: list[CurveEstimate]) -> np.ndarray:
    """Which of 180 two-degree bins round the loop the arcs cover."""
    bins = np.zeros(180, dtype=bool)
    for arc in arcs:
        bins[(_angles(arc) / (2.0 * math.pi) * 180).astype(int) % 180] = True
    return bins


def test_sub_arc_is_an_open_piece_of_the_loop_round_its_start() -> None:
    est = _circle()
    total = est.length_m
    arc = sub_arc(est, 0.9 * total, 1.2 * total, 2)
    assert not arc.closed and arc.id == "TUBE>PLATE:circle#arc2" and seam_of(arc.id) == est.id
    assert arc.length_m == pytest.approx(0.3 * total, rel=0.01)
    assert np.allclose(np.linalg.norm(arc.p_RS[:, :2], axis=1), R_M, atol=2e-5)  # on the circle
    assert np.allclose(np.linalg.norm(arc.n_abutting_R, axis=1), 1.0)


def test_a_loop_too_long_for_one_go_is_covered_by_overlapping_arcs() -> None:
    est = _circle()
    plan = _planner(0.55 * est.length_m)
    got = split_curve(est, plan, OVERLAP_M, np.array([0.0, -1.0, 0.0]))
    arcs = [a for a, _ in got.arcs]
    assert got.whole and got.share == 1.0 and got.failure is None
    assert 2 <= len(arcs) <= MAX_ARCS
    assert all(a.length_m <= 0.55 * est.length_m for a in arcs)
    assert _covered(arcs).all()
    # each arc restarts on the bead before it by the overlap; the last runs the overlap over the first's start
    total = sum(a.length_m for a in arcs)
    assert total == pytest.approx(est.length_m + len(arcs) * OVERLAP_M, abs=2e-3)
    first = _angles(arcs[0])[0]
    assert abs(math.remainder(first - 1.5 * math.pi, 2.0 * math.pi)) < 2.0 * math.pi / 8 + 1e-6  # nearest the base


def test_a_part_no_arc_reaches_is_reported_with_the_share_covered() -> None:
    est = _circle()
    plan = _planner(0.6 * est.length_m, blocked=(0.4 * math.pi, 0.6 * math.pi))  # a gusset at 90 deg
    got = split_curve(est, plan, OVERLAP_M, np.array([0.0, -1.0, 0.0]))
    assert not got.whole
    assert got.failure is not None and got.failure.code is PlanReason.IK_FAILED
    assert 0.75 < got.share < 1.0  # the blocked tenth and the arcs' ends round it are not welded
    assert len(got.arcs) <= MAX_ARCS
    assert not _covered([a for a, _ in got.arcs])[45]  # 90 deg: never covered
