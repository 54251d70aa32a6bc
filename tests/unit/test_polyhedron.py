"""The general part body (Polyhedron) and the Box as its special case: one set of methods for both."""

from __future__ import annotations

import numpy as np
import pytest

from cell.geometry import make_pose, rpy_to_matrix, transform_points
from cell.types import BOX_FACES, Box, Part, Polyhedron


def prism(outline_xy: list[tuple[float, float]], height: float) -> Polyhedron:
    """A straight prism over a simple counter-clockwise outline (convex or not), from z = 0 to ``height``."""
    m = len(outline_xy)
    xy = np.array(outline_xy, dtype=float)
    v = np.vstack([np.c_[xy, np.zeros(m)], np.c_[xy, np.full(m, height)]])
    faces = [tuple(range(m - 1, -1, -1)), tuple(range(m, 2 * m))]
    faces += [(i, (i + 1) % m, m + (i + 1) % m, m + i) for i in range(m)]
    return Polyhedron(v, tuple(faces), tuple(f"f{i}" for i in range(len(faces))))


# An L: 0.3 x 0.3 with the square (0.1..0.3, 0.1..0.3) cut away, 0.05 high.
L_SHAPE = prism([(0, 0), (0.3, 0), (0.3, 0.1), (0.1, 0.1), (0.1, 0.3), (0, 0.3)], 0.05)


def plate_with_hole(outer: float = 0.2, hole: float = 0.05, t: float = 0.01) -> Polyhedron:
    """A square plate (outer x outer x t) with a square through-hole in its middle; convex faces only."""
    o, h = outer / 2.0, hole / 2.0
    ring_o = [(-o, -o), (o, -o), (o, o), (-o, o)]
    ring_h = [(-h, -h), (h, -h), (h, h), (-h, h)]
    v = [(x, y, z) for z in (0.0, t) for ring in (ring_o, ring_h) for x, y in ring]  # 0-3 oz0, 4-7 hz0, 8-11, 12-15
    faces: list[tuple[int, ...]] = []
    for i in range(4):
        j = (i + 1) % 4
        faces.append((8 + i, 8 + j, 12 + j, 12 + i))  # top trapezoid, +z
        faces.append((i, 4 + i, 4 + j, j))  # bottom trapezoid, -z
        faces.append((i, j, 8 + j, 8 + i))  # outer side
        faces.append((4 + j, 4 + i, 12 + i, 12 + j))  # hole side, facing the hole's axis
    return Polyhedron(np.array(v), tuple(faces), tuple(f"f{i}" for i in range(len(faces))))


def test_contains_a_non_convex_l() -> None:
    inside = np.array([[0.05, 0.05, 0.02], [0.25, 0.05, 0.02], [0.05, 0.25, 0.02]])
    outside = np.array([[0.2, 0.2, 0.02], [0.15, 0.15, 0.025], [0.05, 0.05, 0.06], [-0.01, 0.1, 0.02]])
    assert L_SHAPE.contains(inside).all()
    assert not L_SHAPE.contains(outside).any()
    assert L_SHAPE.contains(np.array([0.2, 0.2, 0.02]), margin=0.0) == np.False_
    # a point in the notch 12 mm from both of its walls: inside when grown by 13 mm, not by 11 mm
    near = np.array([[0.112, 0.112, 0.02]])
    assert L_SHAPE.contains(near, margin=0.013).all() and not L_SHAPE.contains(near, margin=0.011).any()
    assert not L_SHAPE.contains(inside[:1], margin=-0.03).any()  # shrunk by 30 mm the 50 mm high body is empty
    assert L_SHAPE.volume == pytest.approx(0.3 * 0.3 * 0.05 - 0.2 * 0.2 * 0.05)


def test_contains_a_plate_with_a_hole() -> None:
    plate = plate_with_hole()
    assert not plate.contains(np.array([[0.0, 0.0, 0.005], [0.01, -0.02, 0.005]])).any()  # in the hole
    assert plate.contains(np.array([[0.05, 0.0, 0.005], [-0.09, 0.09, 0.005]])).all()  # in the material
    assert not plate.contains(np.array([[0.05, 0.0, 0.012]])).any()
    assert plate.contains(np.array([[0.05, 0.0, 0.012]]), margin=0.003).all()
    assert plate.volume == pytest.approx((0.2**2 - 0.05**2) * 0.01)
    assert np.allclose(plate.center, [0.0, 0.0, 0.005])


def test_face_plane_and_polygon() -> None:
    n, d = L_SHAPE.face_plane("f1")  # the top
    assert np.allclose(n, [0, 0, 1]) and d == pytest.approx(0.05)
    n, d = L_SHAPE.face_plane("f5")  # the notch's wall x = 0.1 facing +x (outline edge (0.1, 0.1) -> (0.1, 0.3))
    assert np.allclose(n, [1, 0, 0]) and d == pytest.approx(0.1)
    assert L_SHAPE.face_polygon("f1").shape == (6, 3)
    for name in L_SHAPE.face_names():
        n, d = L_SHAPE.face_plane(name)
        assert np.allclose(L_SHAPE.face_polygon(name) @ n, d)
    with pytest.raises(ValueError, match="unknown face 'top'"):
        L_SHAPE.face_plane("top")
    assert len(L_SHAPE.edges()) == 18


def test_triangles_wind_outward_on_non_convex_faces() -> None:
    tri = L_SHAPE.vertices[L_SHAPE.triangles()]
    assert len(tri) == 2 * 4 + 2 * 6  # the two L caps (6 corners: 4 triangles each) and six side quads
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    top = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])[:, 2] > 0
    assert area[top].sum() == pytest.approx(0.3 * 0.3 - 0.2 * 0.2)  # no triangle spills into the notch


def test_a_dart_quad_face_is_cut_at_its_reflex_corner_not_fanned() -> None:
    """A prism over an arrowhead (four corners, the fourth reflex): each cap is two triangles that lie inside it
    (a fan from its first corner would cover 6 cm2 of a 3 cm2 face, part of it twice); the side quads, convex,
    are the fan of their first corner."""
    dart = prism([(0.0, 0.0), (0.03, 0.015), (0.0, 0.03), (0.01, 0.015)], 0.01)
    tri = dart.vertices[dart.triangles()]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    top, bottom = n[:, 2] > 1e-12, n[:, 2] < -1e-12
    assert np.count_nonzero(top) == np.count_nonzero(bottom) == 2
    assert 0.5 * n[top, 2].sum() == pytest.approx(3e-4) and -0.5 * n[bottom, 2].sum() == pytest.approx(3e-4)
    assert dart.volume == pytest.approx(3e-6)
    assert [tuple(t) for t in dart.triangles()[4:6]] == [(0, 1, 5), (0, 5, 4)]  # the first side quad's fan


def test_transformed_moves_planes_points_and_centre() -> None:
    X = make_pose(rpy_to_matrix([0.3, -0.2, 1.1]), [0.5, -0.4, 0.2])
    moved = L_SHAPE.transformed(X)
    rng = np.random.default_rng(3)
    p = rng.uniform(-0.05, 0.35, size=(400, 3))
    assert np.array_equal(L_SHAPE.contains(p), moved.contains(transform_points(X, p)))
    n0, d0 = L_SHAPE.face_plane("f5")
    n1, d1 = moved.face_plane("f5")
    assert np.allclose(n1, X[:3, :3] @ n0)
    assert d1 == pytest.approx(d0 + float(n1 @ X[:3, 3]))
    assert np.allclose(moved.center, transform_points(X, L_SHAPE.center))
    assert moved.radius == pytest.approx(L_SHAPE.radius)


def test_a_rigid_move_keeps_what_a_rebuilt_body_computes() -> None:
    X = make_pose(rpy_to_matrix([0.3, -0.2, 1.1]), [0.5, -0.4, 0.2])
    moved = plate_with_hole().moved(X)
    rebuilt = Polyhedron(transform_points(X, plate_with_hole().vertices), moved.faces, moved.names)
    assert np.allclose(moved.face_planes(), rebuilt.face_planes(), atol=1e-12)
    assert np.array_equal(moved.triangles(), rebuilt.triangles())
    assert moved.volume == pytest.approx(rebuilt.volume) and np.allclose(moved.center, rebuilt.center)
    q = transform_points(X, np.random.default_rng(3).uniform(-0.12, 0.12, (400, 3)) * [1.0, 1.0, 0.2])
    for margin in (-0.002, 0.0, 0.002):  # its answers too (its bounds moved with it)
        assert np.array_equal(moved.contains(q, margin), rebuilt.contains(q, margin))


def test_box_and_its_polyhedron_agree() -> None:
    box = Box(make_pose(rpy_to_matrix([0.2, 0.5, -0.7]), [0.1, 0.2, 0.3]), np.array([0.4, 0.1, 0.06]))
    poly = box.to_polyhedron()
    assert poly.face_names() == BOX_FACES == box.face_names()
    for face in BOX_FACES:
        nb, db = box.face_plane(face)
        npoly, dpoly = poly.face_plane(face)
        assert np.allclose(nb, npoly) and db == pytest.approx(dpoly)
        assert np.allclose(box.face_polygon(face), poly.face_polygon(face))
    rng = np.random.default_rng(7)
    p = box.center + rng.uniform(-0.25, 0.25, size=(2000, 3))
    assert np.array_equal(box.contains(p), poly.contains(p))
    assert np.allclose(box.center, poly.center) and box.radius == pytest.approx(poly.radius)
    assert poly.volume == pytest.approx(0.4 * 0.1 * 0.06)
    assert len(poly.edges()) == len(box.edges()) == 12
    assert np.array_equal(box.triangles(), poly.triangles())


def test_part_takes_either_body() -> None:
    box = Box(make_pose(p=[0, 0, 0.05]), np.array([0.2, 0.1, 0.1]))
    part = Part("RAIL", box)
    assert part.is_box and part.box is box and part.body is box and part.kind == "box"
    assert part.face_names() == BOX_FACES and part.radius == pytest.approx(box.radius)
    v, t = part.triangles()
    assert v.shape == (8, 3) and t.shape == (12, 3)
    brace = Part("BRACE", L_SHAPE, "MESH")
    assert not brace.is_box and brace.kind == "mesh" and brace.face_names() == L_SHAPE.names
    with pytest.raises(TypeError, match="part BRACE is not a box"):
        _ = brace.box
    X = make_pose(p=[1.0, 0.0, 0.0])
    assert np.allclose(brace.transformed(X).center, L_SHAPE.center + np.array([1.0, 0, 0]))
    assert brace.transformed(X).drawn_as == "MESH"
    assert np.allclose(brace.vertices(), L_SHAPE.vertices) and brace.edges().shape == (18, 2, 3)
    assert brace.volume == pytest.approx(L_SHAPE.volume)


def test_bad_bodies_are_refused() -> None:
    with pytest.raises(ValueError, match="zero area"):
        Polyhedron(np.zeros((4, 3)), ((0, 1, 2), (0, 2, 3), (0, 3, 1), (1, 3, 2)))
    with pytest.raises(ValueError, match="vertex indices"):
        Polyhedron(np.eye(3), ((0, 1, 5), (0, 1, 2), (0, 2, 1), (1, 2, 0)))


def test_segments_hit_convex_and_non_convex_bodies() -> None:
    box = Box(make_pose(p=[0.0, 0.0, 0.0]), np.array([0.2, 0.2, 0.2]))
    poly = box.to_polyhedron()
    assert poly.is_convex and not L_SHAPE.is_convex
    eye = np.array([0.0, 0.0, 1.0])
    ends = np.array([[0.0, 0.0, -1.0], [0.5, 0.0, -1.0], [0.0, 0.0, 0.2]])  # through, past the side, short
    assert poly.segments_hit(eye, ends).tolist() == [True, False, False]
    grazing = np.array([[0.105, 0.0, -1.0]])  # straight down 5 mm beside the box
    assert not poly.segments_hit([0.105, 0.0, 1.0], grazing).any()
    assert poly.segments_hit([0.105, 0.0, 1.0], grazing, margin=0.01).all()
    # through the L's notch: clear; through an arm: met
    top = np.array([0.2, 0.2, 0.5])
    assert L_SHAPE.segments_hit(top, np.array([[0.2, 0.2, -0.1], [0.05, 0.2, -0.1]])).tolist() == [False, True]
