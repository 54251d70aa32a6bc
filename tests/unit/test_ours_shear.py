"""How face A's points are carried along the side lines to each end of a seam (cell.seams.ours._shear): one slope
for both ends when they share it (a box, a brace mitred alike at both ends), each end its own when they differ (a
gusset's 45 deg snipe at one end, its square toe at the other), and only where that end's side face ends A."""

from __future__ import annotations

import math

import numpy as np

from cell.seams.ours._planes import End
from cell.seams.ours._points import Points
from cell.seams.ours._shear import end_shear

T = np.array([1.0, 0.0, 0.0])  # the seam along x, face A (normal +y) standing on face B (normal +z)
N_A, N_B = np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])
P0 = np.zeros(3)
END_FACE = (np.array([0.0, 0.0, -1.0]), 0.0)  # A's edge face resting on B


def _points(P: np.ndarray) -> Points:
    return Points(P.T.copy(), np.zeros(len(P), np.intp), np.ones(len(P), bool), 0.002, 1.0, 1)


def test_ends_of_one_slope_share_it_and_a_snipe_and_a_square_toe_each_keep_their_own() -> None:
    snipe = np.array([-1.0, 0.0, -1.0]) / math.sqrt(2.0)  # the start: A's corner cut at 45 deg, 15 mm each way
    square = End(np.array([1.0, 0.0, 0.0]), 0.08, False, 0.08, span=(0.0, 0.015))
    start = End(snipe, float(snipe @ [0.015, 0.0, 0.0]), False, 0.015, span=(0.0, 0.015))
    # Alike at both ends (square): no shear, every point kept.
    alike = end_shear((End(-T, 0.0, False, 0.0), square), N_A, N_B, T, P0, END_FACE)
    assert alike.c == 0.0 and alike.ends is None
    shear = end_shear((start, square), N_A, N_B, T, P0, END_FACE)
    assert shear.ends is not None
    assert math.isclose(shear.ends[0], 1.0, abs_tol=1e-9) and shear.ends[1] == 0.0
    # Face A's first points at heights 5 and 10 mm over B, where the snipe stands: both carried to the start at
    # 15 mm; the toe's points (at 80 mm) stay where they are; the mean slope would move them by half their height.
    h = np.array([0.005, 0.010])
    pts = _points(np.column_stack([[0.015 - 0.005, 0.015 - 0.010], [0.0, 0.0], h]))
    np.testing.assert_allclose(shear.s(pts, P0, T, 0), [0.015, 0.015], atol=1e-12)
    np.testing.assert_allclose(shear.s(pts, P0, T, 1), [0.010, 0.005], atol=1e-12)
    np.testing.assert_allclose(shear.s(pts, P0, T), [0.0125, 0.010], atol=1e-12)
    # Above the snipe's 15 mm another face (the pipe it stops against) ends A: not the start's points.
    high = _points(np.array([[0.0, 0.0, 0.010], [0.0, 0.0, 0.030]]))
    assert shear.beside(high, P0, 0, 0.0).tolist() == [True, False]
    assert alike.beside(high, P0, 0, 0.0).tolist() == [True, True]
