"""Parts that are not boxes, from the drawing to the joints: the brace map (maps/brace.dxf, a mitred flat-bar brace
drawn as a MESH in a rotated block), closed-body checks on drawn meshes, joints at any dihedral, the table test
and the per-seam refusal of the box-only locators."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from dxf_factory import REPO_ROOT, design, make_brace, make_maps

from cell.errors import MapError
from cell.geometry import make_pose
from cell.process.procedures import joint_type
from cell.seams._support import mesh_part, not_supported
from cell.seams.joint import dihedral, find_joints, joint_kind, joint_notes, weld_geometry
from cell.seams.visibility import UNDERSIDE_REASON, visibility
from cell.types import Joint, Reason, SeamScene, SeamStatus, WeldMap
from cell.weldmap import describe, read_map
from cell.weldmap.polyfit import fit_polyhedron

MAPS = REPO_ROOT / "maps"
BRACE_SEAMS = ("BRACE>POST_L:lower", "BRACE>POST_L:upper", "BRACE>POST_R:lower", "BRACE>POST_R:upper")


@pytest.fixture(scope="module")
def brace() -> WeldMap:
    return read_map(MAPS / "brace.dxf")


def test_the_brace_reads_as_a_polyhedral_part(brace: WeldMap, tmp_path: Path) -> None:
    assert make_brace.write_brace_map(tmp_path / "b.dxf").read_bytes() == (MAPS / "brace.dxf").read_bytes()
    assert brace.warnings == () and len(brace.seams) == 20
    part = brace.part("BRACE")
    assert part.drawn_as == "MESH" and not part.is_box and len(part.face_names()) == 6
    assert [p.is_box for p in brace.parts] == [True] * 4 + [False]
    # the block's rotation undone: the drawn outline, 19 mm thick, a parallelogram 40 mm across its axis
    (x0, _), (x1, _), _, _ = make_brace.brace_outline()
    v = part.vertices()
    assert v[:, 0].min() == pytest.approx(x0 * 1e-3) and v[:, 0].max() == pytest.approx(x1 * 1e-3)
    assert np.ptp(v[:, 2]) == pytest.approx(0.019)
    assert part.volume == pytest.approx((x1 - x0) * 40.0 / math.cos(math.radians(35.0)) * 19.0 * 1e-9, rel=1e-9)
    end = [f for f in part.face_names() if np.allclose(part.face_plane(f)[0], [-1, 0, 0])]
    assert len(end) == 1 and part.face_polygon(end[0])[:, 0] == pytest.approx(x0 * 1e-3)  # cut square: flat on POST_L


def test_brace_joints_at_55_and_125_degrees(brace: WeldMap) -> None:
    joints = find_joints(brace)
    deg = {s: round(math.degrees(dihedral(brace, joints[s]))) for s in BRACE_SEAMS}
    assert deg == {BRACE_SEAMS[0]: 125, BRACE_SEAMS[1]: 55, BRACE_SEAMS[2]: 55, BRACE_SEAMS[3]: 125}
    for s in BRACE_SEAMS:
        j = joints[s]
        assert (j.abutting, j.receiving) == ("BRACE", s.split(">")[1].split(":")[0])
        assert j.face_receiving == ("+x" if "POST_L" in s else "-x") and j.face_abutting.startswith("f")
        g = weld_geometry(brace, j)
        assert g.bisector @ (g.n_a + g.n_b) > 0 and g.dihedral == pytest.approx(dihedral(brace, j))
        assert joint_kind(brace, j) == "T"
    box_joints = {s.id: joints[s.id] for s in brace.seams if s.id not in BRACE_SEAMS}
    assert all(math.degrees(dihedral(brace, j)) == pytest.approx(90.0) for j in box_joints.values())
    # for boxes the general joint type is the motion stage's
    assert all(joint_kind(brace, j) == joint_type(brace, j) for j in box_joints.values())
    text = describe(brace, joint_notes(brace))
    assert "BRACE        mesh (MESH) 6 faces" in text
    assert "BRACE>POST_L:upper" in text and "T 55 deg  BRACE > POST_L" in text and "T 125 deg" in text


def test_a_seam_no_faces_hold_names_the_nearest(brace: WeldMap) -> None:
    s = brace.seam(BRACE_SEAMS[0])
    dy = np.array([0.0, 0.01, 0.0])  # 10 mm off the brace's side, still on the post
    off = replace(s, p_start=s.p_start + dy, p_end=s.p_end + dy)
    with pytest.raises(MapError) as exc:
        find_joints(replace(brace, seams=(off,)))
    msg = str(exc.value)
    assert (
        "\n" not in msg
        and "BRACE>POST_L:lower" in msg
        and "nearest faces: POST_L:+x (0.0 mm), BRACE:f5 (1.0 mm)" in msg
    )


def _box_faces(lo: tuple[float, ...], hi: tuple[float, ...], base: int = 0) -> tuple[list, list]:
    v = [(x, y, z) for z in (lo[2], hi[2]) for y in (lo[1], hi[1]) for x in (lo[0], hi[0])]
    f = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    return v, [tuple(i + base for i in q) for q in f]


def test_drawn_meshes_must_be_closed_bodies() -> None:
    v, f = _box_faces((0, 0, 0), (0.1, 0.2, 0.3))
    flipped = [f[0][::-1], *f[1:]]  # one face drawn the wrong way round: fixed by the orientation walk
    body = fit_polyhedron(np.array(v), flipped, "P", 1e-4)
    assert body.volume == pytest.approx(0.006) and len(body.face_names()) == 6
    with pytest.raises(MapError, match="part P is not closed: 4 edges on one face only"):
        fit_polyhedron(np.array(v), f[1:], "P", 1e-4)
    v2, f2 = _box_faces((0.05, 0.05, 0.05), (0.2, 0.3, 0.4), base=8)  # a second box through the first
    with pytest.raises(MapError, match="part P is self-intersecting"):
        fit_polyhedron(np.array(v + v2), f + f2, "P", 1e-4)
    flat = np.array(v, dtype=float)
    flat[:, 2] = 0.0
    with pytest.raises(MapError, match=r"part P is not a closed body|encloses no volume"):
        fit_polyhedron(flat, f, "P", 1e-4)


def test_coplanar_triangles_merge_into_one_face() -> None:
    # an L prism drawn as triangles (its caps as fans): the caps come back as one six-cornered face each
    xy = [(0, 0), (0.3, 0), (0.3, 0.1), (0.1, 0.1), (0.1, 0.3), (0, 0.3)]
    v = [(x, y, z) for z in (0.0, 0.05) for x, y in xy]
    tris = [(0, 3 - k, 2 - k) for k in range(0, 1)] + [(0, 5, 4), (0, 4, 3), (0, 3, 2), (0, 2, 1)]
    tris = tris[1:] + [(6, 6 + k, 6 + k + 1) for k in range(1, 5)]
    tris += [t for i in range(6) for t in ((i, (i + 1) % 6, 6 + (i + 1) % 6), (i, 6 + (i + 1) % 6, 6 + i))]
    body = fit_polyhedron(np.array(v, dtype=float), tris, "L", 1e-4)
    assert len(body.face_names()) == 8
    assert sorted(len(body.faces[i]) for i in range(8)) == [4] * 6 + [6, 6]
    assert body.volume == pytest.approx(0.05 * (0.09 - 0.04))
    assert not body.contains(np.array([[0.2, 0.2, 0.02]])).any()


def test_the_table_test_reads_face_polygons(brace: WeldMap) -> None:
    joints = find_joints(brace)
    lifted = brace.transformed(make_pose(p=[0.0, 0.0, -0.061]), "R")  # the brace's underside now on z = 0
    under = Joint("X", "BRACE", "POST_L", _down_face(brace), "+x", joints[BRACE_SEAMS[0]].end_face)
    assert visibility(lifted, under, table_z=0.0) == (False, UNDERSIDE_REASON)
    assert visibility(lifted, joints[BRACE_SEAMS[0]], table_z=0.0) == (True, "")
    assert visibility(brace, under, table_z=0.0) == (True, "")  # 61 mm over the table: not against it


def _down_face(m: WeldMap) -> str:
    part = m.part("BRACE")
    return next(f for f in part.face_names() if part.face_plane(f)[0][2] < -0.99)


def test_box_only_locators_refuse_a_mesh_seam(brace: WeldMap) -> None:
    joints = find_joints(brace)
    scene = SeamScene(voxel=None, dense=None, weldmap=brace, joints=joints, table_z=0.0)  # type: ignore[arg-type]
    assert mesh_part(scene, brace.seam(BRACE_SEAMS[1])) == "BRACE"
    assert mesh_part(scene, brace.seam("POST_L>TOP_RAIL:+z")) is None
    est = not_supported(brace.seam(BRACE_SEAMS[1]), "paper", "BRACE", "the method needs boxes")
    assert est.status is SeamStatus.NOT_FOUND and est.code is Reason.NOT_SUPPORTED
    assert est.reason == "paper: part BRACE is a mesh; the method needs boxes"


def test_fence1_joints_unchanged() -> None:
    parts, seams = design("fence1")
    m = read_map(MAPS / "fence1.dxf")
    joints = find_joints(m)
    for sid, _, _ in seams:  # the id names abutting>receiving:face, as the finder says from geometry alone
        a, rest = sid.split(">")
        r, face = rest.split(":")
        assert (joints[sid].abutting, joints[sid].receiving, joints[sid].face_abutting) == (a, r, face)
    assert set(parts) == {p.name for p in m.parts}


@pytest.mark.parametrize("form", ["3DFACE", "POLYFACE", "3DSOLID"])
def test_the_brace_drawn_as_3dfaces_a_polyface_or_a_solid(tmp_path: Path, form: str) -> None:
    parts, seams = design("fence1")
    doc = make_maps.build_map(parts, seams + make_brace.brace_seams(), solid="mesh")
    mesh = make_brace.brace_mesh()
    if form == "POLYFACE":
        mesh.render_polyface(doc.modelspace(), dxfattribs={"layer": "BRACE"})
    elif form == "3DSOLID":  # ACIS, as AutoCAD writes solids
        make_maps._add_body(doc.modelspace(), mesh, "BRACE", "3dsolid")
    else:  # each quad as two triangles, as mesh exporters write them
        for f in mesh.faces:
            a, b, c, d = (mesh.vertices[i] for i in f)
            doc.modelspace().add_3dface([a, b, c], dxfattribs={"layer": "BRACE"})
            doc.modelspace().add_3dface([a, c, d], dxfattribs={"layer": "BRACE"})
    doc.saveas(tmp_path / "b.dxf")
    m = read_map(tmp_path / "b.dxf")
    part = m.part("BRACE")
    assert part.drawn_as == form and not part.is_box and m.warnings == ()
    assert sorted(len(part.face_polygon(f)) for f in part.face_names()) == [4] * 6  # triangles merged into quads
    joints = find_joints(m)
    assert sorted(round(math.degrees(dihedral(m, joints[s]))) for s in BRACE_SEAMS) == [55, 55, 125, 125]


def test_broken_meshes_are_one_line_errors() -> None:
    v, f = _box_faces((0, 0, 0), (0.1, 0.2, 0.3))
    with pytest.raises(MapError, match="part P has a face naming a vertex it does not have"):
        fit_polyhedron(np.array(v), [*f[:-1], (1, 3, 7, 9)], "P", 1e-4)
    bad = np.array(v, dtype=float)
    bad[2, 1] = np.nan
    with pytest.raises(MapError, match="not finite"):
        fit_polyhedron(bad, f, "P", 1e-4)
