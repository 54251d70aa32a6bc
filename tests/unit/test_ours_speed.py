"""The shortcuts that keep our locator fast on mesh parts give the answers of the straightforward computations:
``Polyhedron.contains`` with a margin (distances only for the point-triangle pairs that can be within it), every
face's plane at once, the region test kept per point over a seam's passes, the vectorised face searches."""

from __future__ import annotations

import numpy as np
import pytest
from bodies_fixtures import l_prism
from test_ours_bodies import _plate_with_hole, _wedge

from cell.geometry import pose_from_xyz_rpy
from cell.seams.ours._bodies import Region, coplanar_boundary, face_planes, over_region, side_planes, touch_gap
from cell.types import Box, Part, Polyhedron


def _near_the_body(body: Polyhedron, n: int, seed: int) -> np.ndarray:
    """(n, 3) points in the body's bounds grown by 3 cm, half of them on or just off its faces."""
    rng = np.random.default_rng(seed)
    lo, hi = body.vertices.min(axis=0) - 0.03, body.vertices.max(axis=0) + 0.03
    free = rng.uniform(lo, hi, (n // 2, 3))
    tri = body.vertices[body.triangles()[rng.integers(0, len(body.triangles()), n - n // 2)]]
    w = rng.dirichlet(np.ones(3), len(tri))
    on = np.einsum("nk,nkj->nj", w, tri) + rng.normal(0.0, 0.004, (len(tri), 3))
    return np.vstack([free, on])


@pytest.mark.parametrize("margin", [0.002, 0.006, 0.02, -0.004])
def test_contains_with_a_margin_is_inside_or_within_the_margin_of_a_face(margin: float) -> None:
    body = l_prism()  # not convex: the winding number and the distances both matter
    P = _near_the_body(body, 1500, 7)
    d = np.min([body.face_distance(f, P) for f in body.names], axis=0)
    inside = body.contains(P)
    expected = (inside | (d <= margin)) if margin > 0 else (inside & (d >= -margin))
    got = body.contains(P, margin=margin)
    assert np.array_equal(got, expected)
    assert 0 < got.sum() < len(P)  # both answers occur


def test_face_planes_are_every_face_plane_in_order() -> None:
    box = Box(pose_from_xyz_rpy((0.1, 0.2, 0.3), (0.1, 0.2, 0.3)), np.array([0.1, 0.2, 0.3]))
    for part in (Part("L", l_prism()), Part("B", box)):
        N, D = face_planes(part)
        rows = [part.face_plane(f) for f in part.face_names()]
        assert np.array_equal(N, np.array([n for n, _ in rows]))
        assert np.array_equal(D, np.array([d for _, d in rows]))


def test_the_kept_region_test_is_over_region_for_every_inset_and_subset() -> None:
    plate = Part("BASE", _plate_with_hole())
    top = plate.face_names()[0]
    n, _ = plate.face_plane(top)
    edges = coplanar_boundary(plate, top)
    rng = np.random.default_rng(3)
    P = np.column_stack([rng.uniform(-0.02, 0.32, 3000), rng.uniform(-0.02, 0.22, 3000), np.full(3000, 0.01)])
    region = Region(P, edges, n)
    for inset, share in ((0.011, 0.3), (0.005, 0.6), (0.0, 0.5), (0.011, 1.0), (0.02, 0.8)):
        where = rng.random(len(P)) < share
        expected = np.zeros(len(P), bool)
        expected[where] = over_region(P[where], edges, n, inset)
        assert np.array_equal(region.over(inset, where), expected)
        assert np.array_equal(region.over(inset), over_region(P, edges, n, inset))
    assert 0 < region.over(0.005).sum() < len(P)


def test_vectorised_face_searches_are_the_loops_over_faces() -> None:
    bar = Part("BAR", _wedge(40.0))
    p0, t = np.array([0.0, 0.0, 0.04]), np.array([0.0, 1.0, 0.0])
    # side_planes: of the faces crossing the line within reach of each map end, the one most across it, the nearest
    # of those as much across it (the faces in order).
    best = []
    for end, s_end in enumerate((0.0, 0.2)):
        kept: tuple[float, float, str] | None = None
        for f in bar.face_names():
            nf, df = bar.face_plane(f)
            c = float(nf @ t)
            if f in ("top", "left") or abs(c) < np.cos(np.radians(60.0)) or (c > 0.0) != (end == 1):
                continue
            off = abs((df - float(nf @ p0)) / c - s_end)
            if off <= 0.05 and (kept is None or abs(c) > kept[0] + 1e-3 or (abs(c) > kept[0] - 1e-3 and off < kept[1])):
                kept = (abs(c), off, f)
        assert kept is not None
        best.append(bar.face_plane(kept[2]))
    sides = side_planes(bar, ("top", "left"), p0, t, (0.0, 0.2), 0.05)
    assert sides is not None
    for (n_got, d_got), (n_want, d_want) in zip(sides, best, strict=True):
        assert np.array_equal(n_got, n_want) and d_got == d_want
    # touch_gap: the face of the bar lying on a plane 0.5 mm off its bottom, seen from below.
    n_b, d_b = bar.face_plane("bottom")
    assert touch_gap(bar, -n_b, -d_b - 0.0005, np.array([0.03, 0.1, 0.0])) == pytest.approx(0.0005, abs=1e-12)
    assert touch_gap(bar, n_b, d_b, np.array([0.03, 0.1, 0.0])) is None  # same normal: not lying on it
