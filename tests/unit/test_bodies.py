"""General bodies in the simulated world (docs/bodies.md): polyhedral parts rendered from their mesh, fixtures as
grey obstacles, the turn with a mesh part, collisions against meshes, ground truth of any two faces, as-built
deviations of a mesh and recorded truth files with meshes. Tiny cells, pybullet DIRECT, tiny images."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from bodies_fixtures import BRACE_DEG, brace, l_prism, tetrahedron, wedge
from pinhole import deproject
from tiny_cell import HOME, URDF

from cell import scenario as scn
from cell.errors import CaptureError, ScenarioError
from cell.geometry import make_pose, rot_x, transform_points
from cell.motion.collision import CollisionChecker
from cell.motion.collision.grow import grown_convex, grown_mesh, is_convex
from cell.motion.robot import RobotModel
from cell.recorded._fields import truth_json, truth_parts
from cell.scenario.turnover_specs import TurnoverPlacementSpec
from cell.seams.truth import true_seams
from cell.sim import SimCell
from cell.sim.asbuilt.parts import as_built_fixtures, as_built_parts, principal_frame
from cell.sim.cell import FIXTURE_PREFIX
from cell.sim.turnover import body_volume, turned_pose
from cell.types import Box, Joint, MapSeam, Part, Polyhedron, WeldMap

TABLE_TOP = 0.9  # [m]
TINY = """
name: tiny-bodies
seed: 3
simulation: {noise: none}
map: {file: dummy.dxf, X_WM: {xyz_m: [0.0, 0.0, 0.9], rpy_deg: [0.0, 0.0, 30.0]}}
table: {center_m: [0.0, 0.0, 0.85], size_m: [1.2, 0.8, 0.1]}
cameras:
  above:
    eye_m: [0.25, 0.05, 1.5]
    target_m: [0.0, 0.0, 0.9]
    resolution: [64, 48]
    hfov_deg: 40
perception:
  workspace: {min_m: [-1.0, -1.0, 0.9], max_m: [1.0, 1.0, 1.5]}
"""


def _scenario(tmp_path: Path) -> scn.Scenario:
    (tmp_path / "dummy.dxf").write_text("not read by these tests\n")
    return scn.from_yaml(TINY, base_dir=tmp_path)


def _on_table(body: Polyhedron, dx: float = 0.0) -> Polyhedron:
    return body.transformed(make_pose(p=[dx, 0.0, TABLE_TOP]))


# -- the simulator ---------------------------------------------------------------------------------------------


def test_a_mesh_part_and_a_fixture_are_rendered_where_they_are(tmp_path: Path) -> None:
    w = _on_table(wedge(), dx=-0.05)  # 0.2 long (y), 0.1 deep (x), 0.05 high, its slope facing the camera at +x
    clamp = Part("CLAMP", Box(make_pose(p=[0.2, -0.15, TABLE_TOP + 0.02]), np.array([0.04, 0.04, 0.04])))
    with SimCell(_scenario(tmp_path), [Part("WEDGE", w)], fixtures_W=[clamp]) as sim:
        assert {"WEDGE", FIXTURE_PREFIX + "CLAMP"} <= set(sim.bodies)
        image = sim.capture("above")
        p_W = deproject(image)[image.depth > 0]
        up = p_W[p_W[:, 2] > TABLE_TOP + 0.002]
        on_wedge, on_clamp = w.contains(up, margin=0.002), clamp.contains(up, margin=0.002)
        assert np.all(on_wedge | on_clamp)  # everything above the table is the wedge or the clamp
        assert on_wedge.sum() > 300 and on_clamp.sum() > 20
        n, d = w.face_plane("f3")  # the slope, seen from above: points on it at the right depth
        assert np.sum(np.abs(up @ n - d) < 1e-4) > 300
        # the part turned over moves; the fixture stays where it is
        X = make_pose(p=[0.08, 0.0, 0.0])
        before = sim.client.getBasePositionAndOrientation(sim.body_id(FIXTURE_PREFIX + "CLAMP"))
        (moved,) = sim.move_part(X)
        assert sim.client.getBasePositionAndOrientation(sim.body_id(FIXTURE_PREFIX + "CLAMP")) == before
        again = sim.capture("above")
        q_W = deproject(again)[again.depth > 0]
        q_up = q_W[q_W[:, 2] > TABLE_TOP + 0.002]
        assert np.all(moved.contains(q_up, margin=0.002) | clamp.contains(q_up, margin=0.002))
        np.testing.assert_allclose(moved.vertices(), transform_points(X, w.vertices), atol=1e-12)


def test_the_turn_of_a_mesh_part_rests_it_on_a_face_by_its_mesh_volume() -> None:
    w = _on_table(wedge(length=0.2, base=0.1, height=0.05))
    part = Part("WEDGE", w)
    assert body_volume(part) == pytest.approx(0.5 * 0.1 * 0.05 * 0.2, rel=1e-12)
    np.testing.assert_allclose(part.center, [0.1 / 3.0, 0.0, TABLE_TOP + 0.05 / 3.0], atol=1e-12)
    box = Part("BOX", Box(make_pose(p=[0.0, 0.0, 1.0]), np.array([0.1, 0.2, 0.3])))
    assert body_volume(box) == 0.1 * 0.2 * 0.3  # a box exactly as before
    X_turn = make_pose(rot_x(math.pi), [0.0, 0.0, 2.0 * TABLE_TOP])  # upside down about x
    X = turned_pose(
        [part], np.zeros((0, 2, 3)), 0.0, X_turn, TABLE_TOP, TurnoverPlacementSpec(), np.random.default_rng(0)
    )
    v = transform_points(X, w.vertices)
    assert v[:, 2].min() == pytest.approx(TABLE_TOP, abs=1e-9)
    assert np.sum(np.abs(v[:, 2] - TABLE_TOP) < 1e-9) >= 3  # lies on a face, not on an edge


# -- collisions ------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


def test_a_convex_mesh_grows_like_a_box_and_a_concave_one_along_its_normals() -> None:
    box = Box(make_pose(p=[0.1, 0.2, 0.3]), np.array([0.1, 0.2, 0.3]))
    grown = grown_convex(box.to_polyhedron(), 0.01)
    expected = Box(box.X_AB, box.size + 0.02).corners()
    assert len(grown) == 8 and np.allclose(np.sort(grown, axis=0), np.sort(expected, axis=0), atol=1e-12)
    assert is_convex(wedge()) and is_convex(tetrahedron()) and not is_convex(l_prism())
    body = l_prism()
    v, _ = grown_mesh(body, 0.005)
    planes = [body.face_plane(f) for f in body.face_names()]
    for face, (n, d) in zip(body.faces, planes, strict=True):  # every face moved out by at least the margin
        assert np.all(v[list(face)] @ n - d >= 0.005 - 1e-12)


def test_the_checker_finds_the_arm_inside_a_mesh_part_and_clears_it_outside(robot: RobotModel) -> None:
    p = robot.fk(HOME, "tool0")[:3, 3]
    tet = tetrahedron(0.3)
    inside = tet.transformed(make_pose(p=p - tet.center))  # the flange deep inside a convex mesh
    cc = CollisionChecker(robot, (Part("TET", inside),))
    hit = cc.check(HOME)
    assert hit is not None and hit.b == "TET" and hit.depth < 0.0
    far = CollisionChecker(robot, (Part("TET", inside.transformed(make_pose(p=[0.0, 0.0, 1.5]))),))
    assert far.check(HOME) is None
    assert far.torch_clear(robot.fk(HOME), HOME) is None
    assert cc.torch_clear(robot.fk(HOME), HOME) is not None
    # a convex prism (more than four vertices: qhull keeps its triangulated facets) near the torch, then clear of it
    bar = brace().transformed(make_pose(p=p - brace().center))
    assert CollisionChecker(robot, (Part("BAR", bar),)).check(HOME) is not None
    assert CollisionChecker(robot, (Part("BAR", bar.transformed(make_pose(p=[0, 0, 1.5]))),)).check(HOME) is None


def test_the_arm_wholly_inside_a_concave_mesh_is_a_contact(robot: RobotModel) -> None:
    # a thick angle (L profile, walls 0.5 m) whose corner block holds the whole wrist and torch
    p = robot.fk(HOME, "tool0")[:3, 3]
    angle = l_prism(size=1.0, wall=0.5, length=0.6).transformed(make_pose(p=p - [0.25, 0.0, 0.25]))
    assert not is_convex(angle) and bool(angle.contains(p[None])[0])
    cc = CollisionChecker(robot, (Part("ANGLE", angle),))
    hit = cc.check(HOME)  # the deepest: a link wholly inside (its distance to the surface, as a penetration)
    assert hit is not None and hit.b == "ANGLE" and hit.depth < -0.15
    assert cc.clearance(HOME)[0] == pytest.approx(hit.depth)
    deep = cc.torch_clear(robot.fk(HOME), HOME)
    assert deep is not None and deep.depth < -0.15
    cc._solids = {}  # the surface alone: only the links that cross it, far less deep
    surface = cc.check(HOME)
    assert surface is not None and surface.depth > hit.depth + 0.05


def test_a_sweep_through_a_concave_mesh_is_found(robot: RobotModel) -> None:
    q_a = HOME + np.radians([-20.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    q_b = HOME + np.radians([20.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    p_mid = robot.fk(HOME)[:3, 3]
    # an angle (L profile, walls 10 mm) standing so that one wall crosses the torch's sweep at the middle
    angle = l_prism(size=0.3, wall=0.01, length=0.3).transformed(make_pose(p=p_mid - [0.005, 0.0, 0.15]))
    cc = CollisionChecker(robot, (Part("ANGLE", angle),))
    assert cc.check(q_a) is None and cc.check(q_b) is None
    hit = cc.check_path(np.array([q_a, q_b]), np.array([0.0, 1.0]))
    assert hit is not None and hit.b == "ANGLE" and 0.0 < hit.t < 1.0


# -- ground truth ----------------------------------------------------------------------------------------------

RAIL = Part("RAIL", Box(make_pose(p=[0.15, 0.0, -0.03]), np.array([0.6, 0.1, 0.06])))  # top face on z = 0
DEPTH = 0.04
FOOT = 0.04 / math.sin(math.radians(BRACE_DEG))  # the mitre's length along x


def _brace_map(brace_part: Part) -> tuple[WeldMap, dict[str, Joint]]:
    seams = (
        MapSeam("acute", np.array([FOOT, -DEPTH / 2, 0.0]), np.array([FOOT, DEPTH / 2, 0.0])),
        MapSeam("side", np.array([FOOT, DEPTH / 2, 0.0]), np.array([0.0, DEPTH / 2, 0.0])),  # drawn towards -x
    )
    joints = {
        "acute": Joint("acute", "BRACE", "RAIL", "f3", "+z", "f2"),
        "side": Joint("side", "BRACE", "RAIL", "f1", "+z", "f2"),
    }
    return WeldMap((brace_part, RAIL), seams, "m", "test"), joints


def test_truth_of_a_35_degree_brace_is_the_line_where_its_faces_meet() -> None:
    design, joints = _brace_map(Part("BRACE", brace(depth=DEPTH)))
    n, _ = design.part("BRACE").face_plane("f3")
    assert 180.0 - math.degrees(math.acos(float(n @ [0.0, 0.0, 1.0]))) == pytest.approx(BRACE_DEG)  # the dihedral
    truth = true_seams(design, joints, design.parts, np.eye(4))
    np.testing.assert_allclose(truth["acute"], [[FOOT, -DEPTH / 2, 0.0], [FOOT, DEPTH / 2, 0.0]], atol=1e-12)
    np.testing.assert_allclose(truth["side"], [[FOOT, DEPTH / 2, 0.0], [0.0, DEPTH / 2, 0.0]], atol=1e-12)
    # built 1 mm above the rail: the acute fillet's corner moves in along the rail by 1 mm / tan(35 deg)
    lifted = Part("BRACE", brace(depth=DEPTH).transformed(make_pose(p=[0.0, 0.0, 0.001])))
    truth = true_seams(design, joints, (lifted, RAIL), np.eye(4))
    x = FOOT - 0.001 / math.tan(math.radians(BRACE_DEG))
    np.testing.assert_allclose(truth["acute"], [[x, -DEPTH / 2, 0.0], [x, DEPTH / 2, 0.0]], atol=1e-12)
    np.testing.assert_allclose(truth["side"], [[FOOT, DEPTH / 2, 0.0], [0.0, DEPTH / 2, 0.0]], atol=1e-12)


def test_truth_keeps_the_whole_edge_of_a_face_warped_as_built() -> None:
    # A gap opened unevenly under the brace's foot (one corner of its cut end 0.8 mm up) twists the faces beside it:
    # no corner lies on both fitted planes any more, and the true seam is still the whole edge, not a sliver of it.
    body = brace(depth=DEPTH)
    v = np.array(body.vertices, dtype=float)
    corner = int(np.argmin(np.linalg.norm(v - [FOOT, DEPTH / 2, 0.0], axis=1)))
    v[corner, 2] += 0.0008
    warped = Part("BRACE", Polyhedron(v, body.faces))
    design, joints = _brace_map(Part("BRACE", body))
    start, end = true_seams(design, joints, (warped, RAIL), np.eye(4))["acute"]
    assert float(np.linalg.norm(end - start)) == pytest.approx(DEPTH, abs=1e-3)


def test_truth_keeps_the_whole_edge_of_an_end_face_drawn_in_two() -> None:
    # a block standing on the rail whose end face (z = 0) is drawn as two quads split at x = 0.05
    d, h = 0.02, 0.05
    bottom = [[0, -d, 0], [0.05, -d, 0], [0.1, -d, 0], [0.1, d, 0], [0.05, d, 0], [0, d, 0]]
    v = np.array([*bottom, [0, -d, h], [0.1, -d, h], [0.1, d, h], [0, d, h]], dtype=float)
    faces = (
        (0, 5, 4, 1),  # f0: the end, first half (normal -z)
        (1, 4, 3, 2),  # f1: the end, second half
        (0, 1, 2, 7, 6),  # f2: -y (a pentagon: the split's vertex on its lower edge)
        (3, 4, 5, 9, 8),  # f3: +y
        (0, 6, 9, 5),  # f4: -x
        (2, 3, 8, 7),  # f5: +x
        (6, 7, 8, 9),  # f6: top
    )
    block = Polyhedron(v, faces)
    assert block.volume == pytest.approx(0.1 * 2 * d * h) and block.face_plane("f0")[0][2] == pytest.approx(-1.0)
    seam = MapSeam("front", np.array([0.0, -d, 0.0]), np.array([0.1, -d, 0.0]))
    design = WeldMap((Part("BLOCK", block), RAIL), (seam,), "m", "test")
    truth = true_seams(design, {"front": Joint("front", "BLOCK", "RAIL", "f2", "+z", "f0")}, design.parts, np.eye(4))
    np.testing.assert_allclose(truth["front"], [[0.0, -d, 0.0], [0.1, -d, 0.0]], atol=1e-12)  # not only f0's half


def test_general_truth_of_boxes_equals_the_box_truth_on_fence1() -> None:
    from cell.seams.joint import find_joints
    from cell.weldmap import read_map

    s = scn.load("fence1")
    wm = read_map(s.map_path, units=s.map.units)
    joints = find_joints(wm)
    built = as_built_parts(wm, s)
    design_W = wm.transformed(s.X_WM, "W")
    boxes = true_seams(design_W, joints, built, s.X_WR)

    def meshes(parts: tuple[Part, ...]) -> tuple[Part, ...]:
        return tuple(Part(p.name, p.box.to_polyhedron()) for p in parts)

    general = true_seams(WeldMap(meshes(design_W.parts), design_W.seams, "m", "W"), joints, meshes(built), s.X_WR)
    assert boxes.keys() == general.keys() and len(boxes) == len(wm.seams)
    worst = max(float(np.abs(np.subtract(boxes[k], general[k])).max()) for k in boxes)
    assert worst < 5e-6  # [m] (1.8 um measured): the carried edge and the faces' line differ by gap x tilt


# -- as built --------------------------------------------------------------------------------------------------


def test_a_mesh_part_takes_offset_rotation_and_size_along_its_principal_axes(tmp_path: Path) -> None:
    base = _scenario(tmp_path)
    w = Part("WEDGE", wedge(length=0.2, base=0.1, height=0.05), "MESH")
    wm = WeldMap((w,), (), "m", "test")
    X_AP, extent, _ = principal_frame(w.body)  # type: ignore[arg-type]
    assert abs(float(X_AP[1, 0])) == pytest.approx(1.0)  # the longest spread: along the wedge (y)
    (plain,) = as_built_parts(wm, base)
    assert plain.drawn_as == "MESH" and isinstance(plain.body, Polyhedron)
    assert plain.vertices()[:, 2].min() == pytest.approx(base.table.top_z, abs=1e-12)
    dev = {"wedge": scn.Deviation(offset_mm=(5.0, 0.0, 0.0), size_mm=(10.0, 0.0, 0.0))}  # any case, as a map's
    (moved,) = as_built_parts(wm, base.with_simulation(deviations=dev))
    axis_W = (base.X_WM @ X_AP)[:3, 0]
    shift = moved.center - plain.center
    np.testing.assert_allclose(shift, 0.005 * axis_W, atol=1e-9)
    spread = np.ptp(moved.vertices() @ axis_W)
    assert spread == pytest.approx(extent[0] + 0.010, abs=1e-12)
    # a part drawn above the table (a brace on top of a rail) keeps its height; one drawn on it rests on it
    up = WeldMap((Part("UP", w.body.transformed(make_pose(p=[0.0, 0.0, 0.05]))),), (), "m", "test")
    (held,) = as_built_parts(up, base)
    assert held.vertices()[:, 2].min() == pytest.approx(base.table.top_z + 0.05, abs=1e-12)
    # fixtures lie where the map really lies: no deviation, no drop
    clamp = Part("CLAMP", Box(make_pose(p=[0.3, 0.0, 0.1]), np.array([0.04, 0.04, 0.04])))
    (placed,) = as_built_fixtures(WeldMap((w,), (), "m", "test", fixtures=(clamp,)), base)
    np.testing.assert_allclose(placed.box.X_AB, base.X_WM @ base.simulation.placement_error.X @ clamp.box.X_AB)
    cube = Part("CUBE", Box(make_pose(), np.array([0.1, 0.1, 0.1])).to_polyhedron())
    bad = {"CUBE": scn.Deviation(size_mm=(1.0, 0.0, 0.0))}
    with pytest.raises(ScenarioError, match=r"deviations\.CUBE\.size_mm: part CUBE .*valid for it: offset_mm"):
        as_built_parts(WeldMap((cube,), (), "m", "test"), base.with_simulation(deviations=bad))


# -- recorded truth --------------------------------------------------------------------------------------------


def test_truth_files_hold_mesh_parts_beside_boxes(tmp_path: Path) -> None:
    import json

    parts = (Part("WEDGE", _on_table(wedge()), "MESH"), RAIL)
    path = tmp_path / "truth.json"
    path.write_text(json.dumps(truth_json(parts)))
    back = truth_parts(path)
    assert [p.name for p in back] == ["WEDGE", "RAIL"] and back[1].is_box and not back[0].is_box
    assert back[0].drawn_as == "MESH" and back[0].body.faces == parts[0].body.faces  # type: ignore[union-attr]
    np.testing.assert_array_equal(back[0].vertices(), parts[0].vertices())
    np.testing.assert_array_equal(back[1].box.X_AB, RAIL.box.X_AB)
    data = truth_json(parts)
    data["parts"][0]["faces"][0] = [0, 1, 99]
    path.write_text(json.dumps(data))
    with pytest.raises(CaptureError, match=r"parts\[0\] is not a closed body"):
        truth_parts(path)


# -- pictures --------------------------------------------------------------------------------------------------


def test_part_mesh_draws_any_body_in_millimetres() -> None:
    from cell.preview.solids import box_mesh, part_mesh

    w = Part("WEDGE", wedge())
    mesh = part_mesh(w)
    np.testing.assert_allclose(mesh.vertices, np.asarray(w.vertices()) * 1000.0)
    assert mesh.triangles.shape == (8, 3)  # the two triangular ends, three rectangles of two triangles each
    area = 0.0
    for a, b, c in mesh.vertices[mesh.triangles]:
        area += 0.5 * float(np.linalg.norm(np.cross(b - a, c - a)))
    hyp = math.hypot(100.0, 50.0)
    assert area == pytest.approx(2 * 0.5 * 100.0 * 50.0 + 200.0 * (100.0 + 50.0 + hyp), rel=1e-9)  # [mm^2]
    box = RAIL.box
    assert sorted(map(tuple, part_mesh(RAIL).vertices.round(9))) == sorted(map(tuple, box_mesh(box).vertices.round(9)))
