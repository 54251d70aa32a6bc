"""Our locator on bodies that are not boxes: the joint geometry from vertices and face polygons
(cell.seams.ours._bodies), checked against the box's own answers and on fence1's real scene with every part a
polyhedron."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from cell import pipeline
from cell.geometry import make_pose
from cell.seams._lines import extent_behind
from cell.seams.ours import OursLocator
from cell.seams.ours._bodies import coplanar_boundary, over_polygon, over_region, side_planes
from cell.seams.ours._geometry import JointGeometry
from cell.seams.ours._points import Points
from cell.types import Box, Joint, Part, Polyhedron, SeamStatus


def _points(P: np.ndarray) -> Points:
    return Points(P.T.copy(), np.zeros(len(P), np.intp), np.ones(len(P), bool), 0.002, 1.0, 1)


def test_over_polygon_convex_and_not_with_an_inset() -> None:
    n = np.array([0.0, 0.0, 1.0])
    square = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]])
    P = np.array([[0.5, 0.5, 0.3], [0.05, 0.5, -0.2], [1.2, 0.5, 0.0], [0.5, 0.95, 0.0]])
    assert over_polygon(P, square, n, 0.0).tolist() == [True, True, False, True]
    assert over_polygon(P, square, n, 0.1).tolist() == [True, False, False, False]
    # An L: the notch (x > 0.5, y > 0.5) is outside though inside the bounding square.
    ell = np.array([[0, 0, 0], [1, 0, 0], [1, 0.5, 0], [0.5, 0.5, 0], [0.5, 1, 0], [0, 1, 0]], dtype=float)
    Q = np.array([[0.75, 0.75, 0.0], [0.25, 0.75, 0.0], [0.75, 0.25, 0.0], [0.55, 0.45, 0.0]])
    assert over_polygon(Q, ell, n, 0.0).tolist() == [False, True, True, True]
    assert over_polygon(Q, ell, n, 0.1).tolist() == [False, True, True, False]  # 0.05 from the notch's corner


def _plate_with_hole() -> Polyhedron:
    """A 0.3 x 0.2 x 0.01 m plate with a 0.06 m square hole, drawn as a mesh exporter does: its top and bottom
    each four quads around the hole."""
    outer = [(0.0, 0.0), (0.3, 0.0), (0.3, 0.2), (0.0, 0.2)]
    inner = [(0.12, 0.07), (0.18, 0.07), (0.18, 0.13), (0.12, 0.13)]
    v = np.array([(x, y, z) for z in (0.0, 0.01) for x, y in outer + inner])
    faces = []
    for i in range(4):
        j = (i + 1) % 4
        o0, o1, i0, i1 = i, j, 4 + i, 4 + j
        faces += [
            (o0 + 8, o1 + 8, i1 + 8, i0 + 8),
            (o0, i0, i1, o1),
            (o0, o1, o1 + 8, o0 + 8),
            (i0, i0 + 8, i1 + 8, i1),
        ]
    return Polyhedron(v, tuple(faces))


def test_a_face_split_in_quads_around_a_hole_is_one_region() -> None:
    plate = Part("BASE", _plate_with_hole())
    top = plate.face_names()[0]
    n, _ = plate.face_plane(top)
    edges = coplanar_boundary(plate, top)
    assert len(edges) == 8  # the outline and the hole; the four seams between the quads are inside
    P = np.array([[0.05, 0.1, 0.01], [0.15, 0.1, 0.01], [0.25, 0.18, 0.01], [0.15, 0.065, 0.01], [0.35, 0.1, 0.0]])
    assert over_region(P, edges, n, 0.0).tolist() == [True, False, True, True, False]
    assert over_region(P, edges, n, 0.01).tolist() == [True, False, True, False, False]  # 5 mm from the hole
    # One quad alone holds only the points over its own trapezoid.
    assert over_polygon(P, plate.face_polygon(top), n, 0.0).sum() < 3


def _wedge(angle_deg: float) -> Polyhedron:
    """A prism 0.2 m long along y whose end at y = 0 is cut at ``angle_deg`` to the x axis (a mitre)."""
    c = 0.05 / np.tan(np.radians(angle_deg))
    bottom = [[0, 0, 0], [0.05, c, 0], [0.05, 0.2, 0], [0, 0.2, 0]]
    top = [[x, y, 0.04] for x, y, _ in bottom]
    v = np.array(bottom + top, dtype=float)
    faces = ((0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7))
    return Polyhedron(v, faces, ("bottom", "top", "mitre", "right", "far", "left"))


def test_side_planes_and_extents_of_a_mitred_bar() -> None:
    bar = Part("BAR", _wedge(55.0))
    n_top, d_top = bar.face_plane("top")
    assert extent_behind(bar, n_top, d_top) == pytest.approx(0.04)
    n_m, d_m = bar.face_plane("mitre")
    # The bar reaches behind its mitre as far as its far corner (0, 0.2) lies from the mitre's plane.
    assert extent_behind(bar, n_m, d_m) == pytest.approx(float(d_m - n_m @ [0.0, 0.2, 0.0]))
    # The top seam along the mitre runs from the left face (x = 0) to the right one (x = 0.05).
    t = np.array([0.05, 0.05 / np.tan(np.radians(55.0)), 0.0])
    length = float(np.linalg.norm(t))
    t /= length
    p0 = np.array([0.0, 0.0, 0.04])
    sides = side_planes(bar, ("top", "mitre"), p0, t, (0.0, length), 0.02)
    assert sides is not None
    (n0, d0), (n1, d1) = sides
    assert np.allclose(n0, [-1.0, 0.0, 0.0]) and d0 == pytest.approx(0.0)
    assert np.allclose(n1, [1.0, 0.0, 0.0]) and d1 == pytest.approx(0.05)
    # Too far from where the map ends the seam: no side face ends it.
    assert side_planes(bar, ("top", "mitre"), p0, t, (0.0, length + 0.05), 0.02) is None


def _leaning_brace() -> Polyhedron:
    """A bar leaning from a base (z = 0) to a wall (x = 0), 30 mm wide along y, in (x, z) [mm]: foot flat on the base
    from x = 10 to 18, top against the wall from z = 12 to 20; its underside runs from (10, 0) up to (0, 12)."""
    outline = [(10.0, 0.0), (18.0, 0.0), (0.0, 20.0), (0.0, 12.0)]  # underside-foot, foot-overside, ...
    v = np.array([[x, y, z] for y in (-15.0, 15.0) for x, z in outline]) / 1000.0
    faces = ((0, 4, 5, 1), (1, 5, 6, 2), (2, 6, 7, 3), (3, 7, 4, 0), (0, 1, 2, 3), (4, 7, 6, 5))
    return Polyhedron(v, faces, ("foot", "over", "top", "under", "cheek-", "cheek+"))


def test_a_cheeks_end_is_the_face_that_holds_it_not_one_more_across_elsewhere() -> None:
    """The cheek's fillet on the wall runs up from the underside's top corner: the underside ends it there. The foot,
    flat on the base 10 mm away, is more across that line and its plane meets it 12 mm below the end: not it."""
    brace = Part("BRACE", _leaning_brace())
    p0, t = np.array([0.0, 0.015, 0.012]), np.array([0.0, 0.0, 1.0])
    sides = side_planes(brace, ("cheek+", "top"), p0, t, (0.0, 0.008), 0.02)
    assert sides is not None
    (n0, d0), (n1, d1) = sides
    n_under, d_under = brace.face_plane("under")
    n_over, d_over = brace.face_plane("over")
    assert np.allclose(n0, n_under) and d0 == pytest.approx(d_under)
    assert np.allclose(n1, n_over) and d1 == pytest.approx(d_over)


def test_a_box_as_a_polyhedron_gives_the_box_geometry() -> None:
    a = Box(make_pose(p=(0.0, 0.0, 0.3)), np.array([0.04, 0.04, 0.6]))
    b = Box(make_pose(p=(0.0, 0.0, -0.02)), np.array([0.8, 0.04, 0.04]))
    joint = Joint("S", "A", "B", "+x", "+z", "-z")
    p0, t = np.array([0.02, -0.02, 0.0]), np.array([0.0, 1.0, 0.0])
    s_map = (0.0, 0.04)
    boxes = JointGeometry.of(Part("A", a), Part("B", b), joint, p0, t, s_map, 0.002)
    polys = JointGeometry.of(Part("A", a.to_polyhedron()), Part("B", b.to_polyhedron()), joint, p0, t, s_map, 0.002)
    assert polys.depth_a == pytest.approx(boxes.depth_a) and polys.length_a == pytest.approx(boxes.length_a)
    assert polys.has_sides and boxes.has_sides
    for (n_p, d_p), (n_b, d_b) in zip(polys.planes, boxes.planes, strict=True):
        assert np.allclose(n_p, n_b) and d_p == pytest.approx(d_b)
    rng = np.random.default_rng(3)
    P = rng.uniform([-0.45, -0.05, -0.01], [0.45, 0.05, 0.01], size=(4000, 3))
    assert np.array_equal(polys.in_face_b(_points(P), 0.001), boxes.in_face_b(_points(P), 0.001))


@pytest.fixture(scope="module")
def polyhedral_fence1(fence1_detection: pipeline.Detection) -> tuple[pipeline.Detection, object]:
    """fence1's real scene with every part's box replaced by the same body as a polyhedron."""
    scene = fence1_detection.scene
    assert scene is not None
    ss = scene.seam_scene
    wm = ss.weldmap
    parts = tuple(Part(p.name, p.box.to_polyhedron(), "MESH") for p in wm.parts)
    poly = dataclasses.replace(ss, weldmap=dataclasses.replace(wm, parts=parts), cache={})
    return fence1_detection, poly


def test_ours_finds_fence1_as_well_with_polyhedral_parts(polyhedral_fence1: tuple[pipeline.Detection, object]) -> None:
    det, poly_scene = polyhedral_fence1
    assert det.scene is not None
    ss = det.scene.seam_scene
    seams = [s for s in ss.weldmap.seams if det.metrics.get(s.id) is not None]
    assert len(seams) >= 10
    boxes = OursLocator().locate_many(dataclasses.replace(ss, cache={}), seams, np.random.default_rng(0))
    polys = OursLocator().locate_many(poly_scene, seams, np.random.default_rng(0))  # type: ignore[arg-type]
    found = [(b, p) for b, p in zip(boxes, polys, strict=True) if b.status is SeamStatus.FOUND]
    assert len(found) == len(seams)
    for b, p in found:
        assert p.status is SeamStatus.FOUND, p.reason
        assert b.p_start is not None and b.p_end is not None and p.p_start is not None and p.p_end is not None
        # The same geometry, asked through vertices and polygons: the same seam within a few micrometres.
        assert np.linalg.norm(p.p_start - b.p_start) < 1e-5 and np.linalg.norm(p.p_end - b.p_end) < 1e-5
