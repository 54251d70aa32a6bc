"""An end read from where face A's points stop (cell/seams/ours/_ends.py): where the points thin out unevenly (a face
partly hidden), the extrapolated end lands away from them, and its sigma knows by how much."""

from __future__ import annotations

import numpy as np

from cell.seams.ours._ends import find_ends, within_receiving
from cell.seams.ours._planes import End, Face
from cell.seams.ours._points import Points
from cell.seams.ours.options import OursOptions

LENGTH_M = 0.2  # the seam along y from 0 to 0.2 m, face A the plane x = 0 (a wall facing -x), B the floor z = 0


def _ends_of(y: np.ndarray, rng: np.random.Generator) -> tuple[End, End]:
    """Both ends found (first pass: no dense cloud) from points of face A at the parameters ``y`` [m] along the seam,
    spread over its height 5-30 mm."""
    z = rng.uniform(0.005, 0.03, len(y))
    P = np.column_stack([np.zeros_like(y), y, z])
    pts = Points(P.T.copy(), np.zeros(len(y), np.intp), np.ones(len(y), bool), 0.001, 1.0, 1)
    face_a = Face(np.array([-1.0, 0.0, 0.0]), 0.0, 2e-4, "A", 1e-5)
    face_b = Face(np.array([0.0, 0.0, 1.0]), 0.0, 2e-4, "B", 1e-5)
    t = np.array([0.0, 1.0, 0.0])
    across = (End(-t, 0.0, False, 0.0), End(t, LENGTH_M, False, LENGTH_M))  # never fitted: no side faces seen
    o = OursOptions(tube_radius_m=0.06)
    end_face = (t, LENGTH_M)
    return find_ends(across, {}, pts, None, face_a, face_b, np.zeros(3), t, [0.0, LENGTH_M], 0.04, o, end_face)


def test_an_evenly_seen_face_ends_within_its_sigma() -> None:
    rng = np.random.default_rng(3)
    for found, true in zip(_ends_of(rng.uniform(0.0, LENGTH_M, 4000), rng), (0.0, LENGTH_M), strict=True):
        assert found.source == "extent"
        assert abs(found.s - true) <= 2.0 * np.hypot(found.spread, found.bias)
        assert abs(found.s - true) < 0.01


def test_a_face_thinning_out_towards_its_end_carries_the_extrapolations_miss_in_its_sigma() -> None:
    """Dense over its first half, a fifth as dense over the second (a neighbour hides most of it): the quantiles'
    line puts the far end 80 mm short of the last point. The end's bias covers its error at two sigmas."""
    rng = np.random.default_rng(4)
    y = np.concatenate([rng.uniform(0.0, 0.1, 4000), rng.uniform(0.1, LENGTH_M, 800)])
    start, end = _ends_of(y, rng)
    assert abs(end.s - LENGTH_M) > 0.05  # the extrapolation really misses (else this tests nothing)
    for found, true in ((start, 0.0), (end, LENGTH_M)):
        assert found.source == "extent"
        assert abs(found.s - true) <= 2.0 * np.hypot(found.spread, found.bias)


def test_an_end_past_where_the_other_face_stops_comes_back_to_its_edge() -> None:
    """A brace's cheek runs from its foot (5 mm below) up a plate standing 1.2 mm over the base: the fillet starts
    at the plate's lower edge, not at the foot; an end within the margin stays as found."""
    t = np.array([0.0, 0.0, 1.0])
    found = (End(-t, 0.005, False, -0.005, source="side face"), End(t, 0.005, False, 0.005, source="side face"))
    start, end = within_receiving(found, (-0.0038, 0.06), 3e-4)
    assert start.source == "map" and start.s == -0.0038
    assert end is found[1]
    assert within_receiving(found, (-0.0049, 0.0052), 3e-4) == found
    # A drawn face the line does not cross (its extent a point far off the seam) moves nothing.
    assert within_receiving(found, (-0.93, -0.93), 3e-4) == found
