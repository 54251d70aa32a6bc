"""An end read from where face A's points stop (cell/seams/ours/_ends.py): where the points thin out unevenly (a face
partly hidden), the extrapolated end lands away from them, and its sigma knows by how much."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from cell.seams._extent import EdgeFit, edge_fit
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


def test_an_edge_with_no_density_inside_it_places_nothing() -> None:
    """An edge fitted below all its points (none inside it: no pitch, strays not a ratio) is no edge: a face placed
    from it had an infinite standard error and NaN ends (random cells, detect)."""
    from cell.seams._edge import edge_fault
    from cell.seams._extent import EdgeFit

    o = OursOptions()
    empty = EdgeFit(b=-0.004, se=1e-4, blur=2e-4, n_edge=40, strays=float("nan"), pitch=float("inf"), at_limit=False)
    assert edge_fault(empty, "f1", 0.006, False, o) != ""
    good = EdgeFit(b=-0.004, se=1e-4, blur=2e-4, n_edge=40, strays=0.0, pitch=5e-4, at_limit=False)
    assert edge_fault(good, "f1", 0.006, False, o) == ""


def _refined_ends(y: np.ndarray, length: float) -> tuple[End, End]:
    """Both ends found with a dense cloud to refine them in (the last pass), from points of face A at the parameters
    ``y`` [m] along a seam of ``length`` [m], spread over its height 5-30 mm."""
    face_a = Face(np.array([-1.0, 0.0, 0.0]), 0.0, 2e-4, "A", 1e-5)
    face_b = Face(np.array([0.0, 0.0, 1.0]), 0.0, 2e-4, "B", 1e-5)
    t = np.array([0.0, 1.0, 0.0])
    across = (End(-t, 0.0, False, 0.0), End(t, length, False, length))
    noise = np.random.default_rng(1)

    def points(y: np.ndarray) -> Points:
        P = np.column_stack([np.zeros_like(y), y, noise.uniform(0.005, 0.03, len(y))])
        return Points(P.T.copy(), np.zeros(len(y), np.intp), np.ones(len(y), bool), 5e-4, 1.0, 1)

    def dense(a: np.ndarray, b: np.ndarray) -> Points:
        lo, hi = sorted((float(a[1]), float(b[1])))
        return points(y[(y >= lo) & (y <= hi)])

    o = OursOptions(tube_radius_m=0.06)
    return find_ends(across, {}, points(y), dense, face_a, face_b, np.zeros(3), t, [0.0, length], 0.04, o, (t, length))


def test_an_edge_found_at_the_limit_of_its_search_is_no_edge(monkeypatch: pytest.MonkeyPatch) -> None:
    """Face A's points thin out over the last 15 mm to its end (seen more and more edge-on, partly hidden): the
    edge likelihood's best edge, with a finite standard error, lies at the end of the range it searches about the
    extrapolated guess, which is no edge found. The end keeps the extrapolation with its miss as its bias, and
    its sigma covers the error at two sigmas (taken as an edge, it was 5.4 mm short at a sigma of 2.5 mm)."""
    import cell.seams.ours._ends as ends_module

    fits: list[EdgeFit] = []

    def spy(*args: Any) -> EdgeFit:
        fits.append(edge_fit(*args))
        return fits[-1]

    monkeypatch.setattr(ends_module, "edge_fit", spy)
    length, ramp = 0.08, 0.015
    rng = np.random.default_rng(0)
    y = rng.uniform(0.0, length, 20000)
    y = y[(y > ramp) | (rng.uniform(0.0, 1.0, len(y)) < y / ramp)]
    start, _ = _refined_ends(y, length)
    assert any(f.at_limit and np.isfinite(f.se) for f in fits)  # the case this is about
    assert start.source == "extent"
    assert abs(start.s) <= 2.0 * np.hypot(start.spread, start.bias)


def test_a_sharp_edge_far_from_the_extrapolation_is_found_at_the_faces_last_point() -> None:
    """Face A seen a third as densely over the last 30 mm at each end (a neighbour hides part of it): the
    quantiles' line puts both ends 17-19 mm inside, where the edge likelihood finds no edge within its search.
    Searched again about the face's last point, the sharp edge there is found, within its sigma."""
    length, band = 0.2, 0.03
    rng = np.random.default_rng(0)
    y = rng.uniform(0.0, length, 20000)
    y = y[((y > band) & (y < length - band)) | (rng.uniform(0.0, 1.0, len(y)) < 0.3)]
    for found, true in zip(_refined_ends(y, length), (0.0, length), strict=True):
        assert found.source == "extent"
        sigma = np.hypot(found.spread, found.bias)
        assert abs(found.s - true) <= 2.0 * sigma  # measured 0.06-0.11 mm at 0.26 mm
        assert sigma < 5e-4
