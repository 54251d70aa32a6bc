"""A curved seam's arcs (cell/planning/curves/split.py): an arc is an open piece of the loop, taken round its
start, on the curve, with its seam's id."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cell.planning.curves.arc_solve import TRIM_M, trimmed
from cell.planning.curves.reach import Run
from cell.planning.curves.split import seam_of, sub_arc
from cell.planning.failures import SeamFailure
from cell.process.torch_orientations import Candidate
from cell.types import SeamStatus
from cell.types.curve_estimate import CurveEstimate
from cell.types.plan import PlanReason

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


def test_sub_arc_is_an_open_piece_of_the_loop_round_its_start() -> None:
    est = _circle()
    total = est.length_m
    arc = sub_arc(est, 0.9 * total, 1.2 * total, 2)
    assert not arc.closed and arc.id == "TUBE>PLATE:circle#arc2" and seam_of(arc.id) == est.id
    assert arc.length_m == pytest.approx(0.3 * total, rel=0.01)
    assert np.allclose(np.linalg.norm(arc.p_RS[:, :2], axis=1), R_M, atol=2e-5)  # on the circle
    assert np.allclose(np.linalg.norm(arc.n_abutting_R, axis=1), 1.0)


@pytest.mark.parametrize("reverse", [False, True])
def test_an_arc_failing_on_its_approach_is_trimmed_at_its_start_not_dropped(reverse: bool) -> None:
    est = _circle()
    arc = sub_arc(est, 0.0, 0.1, 1)
    run = Run(Candidate(reverse, 0.0, 0.0, 0.0), 0.0, 0.1, np.zeros(6))
    far = np.array([0.0, 0.0, 0.05])  # 50 mm out along the torch: the approach's end
    on_approach = SeamFailure(PlanReason.HOSE_WINDOW, "A6 out of the window on the approach", far, -0.05)
    (left,) = trimmed(run, on_approach, arc)
    assert (left.a_m, left.b_m) == pytest.approx((0.0, 0.1 - TRIM_M) if reverse else (TRIM_M, 0.1))
    on_weld = SeamFailure(PlanReason.FLIP, "A3 jumps", far, 0.05)  # 50 mm along the weld
    (left,) = trimmed(run, on_weld, arc)
    kept = 0.05 - TRIM_M
    assert (left.a_m, left.b_m) == pytest.approx((0.1 - kept, 0.1) if reverse else (0.0, kept), abs=1e-5)
