"""Welding maps as CAD users draw them: the reds AutoCAD draws, polylines, arcs, 3DFACE models, polyfaces in
blocks, fixtures and layer roles, and the messages for files that are no welding map. Every file is written here
with ezdxf (tmp_path), from the fence1 design; meshes rather than ACIS solids, to stay fast."""

from __future__ import annotations

import logging
import struct
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from dxf_factory import design, make_maps

from cell.errors import MapError
from cell.geometry import make_pose
from cell.scenario.layer_specs import LayerSpec
from cell.types import Box, Unsupported
from cell.weldmap import DEFAULT_FIXTURE_LAYERS, RED_ACI, LayerRoles, read_map

TOL = 1e-6  # [m]
PARTS, SEAMS = design("fence1")


def _doc(**options: object) -> ezdxf.document.Drawing:
    return make_maps.build_map(PARTS, SEAMS, solid="mesh", **options)


def _save(doc: ezdxf.document.Drawing, tmp_path: Path, name: str = "v.dxf") -> Path:
    doc.saveas(tmp_path / name)
    return tmp_path / name


def _one_line(exc: pytest.ExceptionInfo[MapError], *needles: str) -> None:
    msg = str(exc.value)
    assert "\n" not in msg and exc.value.__cause__ is None
    for n in needles:
        assert n in msg, msg


# --- seams in every form ---------------------------------------------------------------------------------------


def test_the_reds_autocad_draws_are_seams(tmp_path: Path) -> None:
    assert sorted(RED_ACI) == [1, 10]  # both draw #FF0000 in the ACI table
    doc = _doc()
    lines = list(doc.modelspace().query("LINE"))
    for i, line in enumerate(lines):
        line.dxf.color = (10, 1, 256)[i % 3] if i % 4 else 3  # every 4th green ...
        if not i % 4:
            line.rgb = (255, 0, 0)  # ... but with a true colour red, which wins
    doc.layers.get("WELD_SEAMS").color = 10
    m = read_map(_save(doc, tmp_path))
    assert [s.id for s in m.seams] == [i for i, _, _ in SEAMS]


def test_byblock_through_nested_blocks(tmp_path: Path) -> None:
    doc = make_maps.build_map(PARTS, [], solid="mesh")
    inner = doc.blocks.new("INNER")
    inner.add_line((0, 0, 0), (0, 0, 80), dxfattribs={"color": 0})  # BYBLOCK
    outer = doc.blocks.new("OUTER")
    outer.add_blockref("INNER", (0, 0, 0), dxfattribs={"color": 0})  # BYBLOCK again
    doc.modelspace().add_blockref("OUTER", (200, 700, 0), dxfattribs={"color": 10})  # red: both lines are seams
    doc.modelspace().add_blockref("OUTER", (280, 700, 0), dxfattribs={"color": 5})  # blue: no seam
    m = read_map(_save(doc, tmp_path))
    [s] = m.seams
    np.testing.assert_allclose([s.p_start, s.p_end], [[0.2, 0.7, 0.0], [0.2, 0.7, 0.08]], atol=TOL)
    assert s.id.startswith("seam-") and s.id.count(".") == 2  # OUTER's and INNER's handles, then the line's


def test_polylines_are_chains_of_straight_seams_and_curves_are_unsupported(tmp_path: Path) -> None:
    doc = make_maps.build_map(PARTS, [], solid="mesh")
    msp = doc.modelspace()
    # the top seam of POST_L > TOP_RAIL as a 2D polyline at elevation 80, with an arc segment after it
    lw = msp.add_lwpolyline([(200, 700, 0), (280, 700, -0.4), (280, 650, 0)], format="xyb")
    lw.dxf.elevation, lw.dxf.color = 80.0, 1
    p3 = msp.add_polyline3d([(280, 700, 0), (280, 700, 80), (200, 700, 80)], dxfattribs={"color": 1})
    p3.set_xdata("WELDCELL", [(1000, "POST_L>TOP_RAIL:corner")])
    msp.add_arc((240, 700, 0), 40, 0, 180, dxfattribs={"color": 1, "layer": "WELD_SEAMS"})
    spline = msp.add_spline([(0, 0, 0), (100, 50, 0), (200, 0, 10)], dxfattribs={"color": 1})
    # drawn from below (extrusion -z, as mirrored views export it): its own x and elevation are mirrored
    flip = msp.add_lwpolyline([(-1120, 700), (-1200, 700)], dxfattribs={"color": 1})
    flip.dxf.extrusion, flip.dxf.elevation = (0.0, 0.0, -1.0), -80.0
    m = read_map(_save(doc, tmp_path))
    ids = [s.id for s in m.seams]
    assert ids[:3] == [f"seam-{lw.dxf.handle}.1", "POST_L>TOP_RAIL:corner.1", "POST_L>TOP_RAIL:corner.2"]
    assert ids[3:] == [f"seam-{flip.dxf.handle}.1"]
    np.testing.assert_allclose([m.seams[3].p_start, m.seams[3].p_end], [[1.12, 0.7, 0.08], [1.2, 0.7, 0.08]], atol=TOL)
    np.testing.assert_allclose([m.seams[0].p_start, m.seams[0].p_end], [[0.2, 0.7, 0.08], [0.28, 0.7, 0.08]])
    np.testing.assert_allclose(m.seams[2].p_end, [0.2, 0.7, 0.08])
    # The bulged segment, the arc and the spline are curved seams (typed curves), not dropped and not refused.
    curved = {c.id: c for c in m.curved}
    assert list(curved) == [f"seam-{lw.dxf.handle}.2", m.curved[1].id, f"seam-{spline.dxf.handle}"]
    assert not m.unsupported and {u.code for u in m.not_straight} == {Unsupported.CURVED_NOT_LOCATED}
    bulged = curved[f"seam-{lw.dxf.handle}.2"]
    assert bulged.kind == "arc" and "LWPOLYLINE" in bulged.drawn and "segment 2" in bulged.drawn
    np.testing.assert_allclose(bulged.curve.sample(0.001)[[0, -1]], [[0.28, 0.7, 0.08], [0.28, 0.65, 0.08]], atol=TOL)
    assert m.curved[1].drawn.startswith("ARC ") and "on layer WELD_SEAMS" in m.curved[1].drawn
    assert m.curved[2].kind == "curve" and m.curved[2].curve.chord_error_m < 1e-4
    assert m.not_straight[0].reason.endswith("not located") and "a curved seam (arc" in m.not_straight[0].reason


def test_lines_on_a_seam_layer_are_seams_whatever_their_colour(tmp_path: Path) -> None:
    doc = _doc(seam_color="bylayer")
    doc.layers.get("WELD_SEAMS").color = 3  # green
    path = _save(doc, tmp_path)
    with pytest.raises(MapError, match="no red weld seams"):
        read_map(path)
    m = read_map(path, layers=LayerSpec(seams=("weld*",)))
    assert len(m.seams) == 16


# --- bodies: 3DFACE models, polyfaces in blocks, fixtures, roles -------------------------------------------------


def test_a_3dface_model_reads_as_boxes(tmp_path: Path) -> None:
    doc = make_maps.build_map({}, SEAMS)
    for name, (lo, hi) in PARTS.items():
        mesh = make_maps.box_mesh(lo, hi)
        for f in mesh.faces:  # each quad as two triangles, as mesh exporters write them
            a, b, c, d = (mesh.vertices[i] for i in f)
            doc.modelspace().add_3dface([a, b, c], dxfattribs={"layer": name})
            doc.modelspace().add_3dface([a, c, d], dxfattribs={"layer": name})
    m = read_map(_save(doc, tmp_path))
    assert [(p.name, p.drawn_as) for p in m.parts] == [(n, "3DFACE") for n in PARTS]
    lo, hi = PARTS["TOP_RAIL"]
    np.testing.assert_allclose(m.part("TOP_RAIL").box.size, (np.array(hi) - lo) * 1e-3, atol=TOL)
    lids = [e for e in doc.modelspace().query("3DFACE") if e.dxf.layer == "POST_L"][-2:]
    for e in lids:  # POST_L loses a face: an open body, named by its first face's handle
        doc.modelspace().delete_entity(e)
    with pytest.raises(MapError) as exc:
        read_map(_save(doc, tmp_path))
    first = next(e for e in doc.modelspace().query("3DFACE") if e.dxf.layer == "POST_L").dxf.handle
    _one_line(exc, f"3DFACE {first} (and 9 more) on layer POST_L", "is not closed", "holds seam POST_L>")


def test_a_polyface_in_a_rotated_block(tmp_path: Path) -> None:
    doc = make_maps.build_map({k: v for k, v in PARTS.items() if k != "POST_R"}, SEAMS, solid="mesh")
    block = doc.blocks.new("Post")  # the post drawn lying along x about its centre, turned 90 deg by its INSERT
    make_maps.box_mesh((-349.5, -40, -40), (349.5, 40, 40)).render_polyface(block, dxfattribs={"layer": "0"})
    doc.modelspace().add_blockref("Post", (1160, 349.5, 40), dxfattribs={"rotation": 90.0})
    m = read_map(_save(doc, tmp_path))
    post = m.part("Post")  # a body on layer 0 takes its block's name, in the block's case
    assert post.drawn_as == "POLYFACE" and m.warnings == ()
    np.testing.assert_allclose(post.box.center, [1.16, 0.3495, 0.04], atol=TOL)
    np.testing.assert_allclose(post.box.size, [0.08, 0.699, 0.08], atol=TOL)  # axes ordered like M's


def test_fixtures_are_obstacles_and_seams_on_them_unsupported(tmp_path: Path) -> None:
    doc = _doc()
    msp = doc.modelspace()
    make_maps.box_mesh((500, 560, 0), (560, 620, 120)).render_mesh(msp, dxfattribs={"layer": "Clamp_A"})
    msp.add_line((500, 560, 120), (560, 560, 120), dxfattribs={"color": 1})  # a seam drawn on the clamp
    path = _save(doc, tmp_path)
    m = read_map(path)
    assert [f.name for f in m.fixtures] == ["Clamp_A"] and "Clamp_A" not in [p.name for p in m.parts]
    [u] = m.unsupported
    assert u.code is Unsupported.ON_FIXTURE
    assert "on fixture Clamp_A: a fixture is never welded" in u.reason and u.reason.startswith("LINE ")
    # the scenario's map.layers override the defaults: the clamp's layer is a part's now, the others ignored
    spec = LayerSpec(parts=("POST_*", "TOP_RAIL", "clamp_*"), fixtures=())
    m2 = read_map(path, layers=spec)
    assert [p.name for p in m2.parts] == ["TOP_RAIL", "POST_L", "POST_R", "Clamp_A"] and m2.fixtures == ()
    assert any("on layer BOTTOM_RAIL ignored: neither a parts nor a fixtures layer" in w for w in m2.warnings)
    assert LayerSpec().fixtures == DEFAULT_FIXTURE_LAYERS == LayerRoles().fixtures  # one default, two places


def test_a_fixture_that_is_no_box_is_its_bounding_box(tmp_path: Path) -> None:
    doc = _doc()
    mesh = make_maps.box_mesh((500, 560, 0), (560, 620, 120))
    mesh.vertices[7] = mesh.vertices[7] + (0, 0, 30)  # a wedge
    mesh.render_mesh(doc.modelspace(), dxfattribs={"layer": "JIG"})
    m = read_map(_save(doc, tmp_path))
    np.testing.assert_allclose(m.fixtures[0].box.size, [0.06, 0.06, 0.15], atol=TOL)
    assert "fixture MESH" in m.warnings[0] and "its bounding box is the obstacle" in m.warnings[0]


def test_an_open_body_holding_a_seam_is_refused_naming_it(tmp_path: Path) -> None:
    doc = make_maps.build_map({k: v for k, v in PARTS.items() if k != "POST_L"}, SEAMS, solid="mesh")
    mesh = make_maps.box_mesh(*PARTS["POST_L"])
    mesh.faces = mesh.faces[:5]  # the lid is missing
    mesh.render_mesh(doc.modelspace(), dxfattribs={"layer": "POST_L"})
    with pytest.raises(MapError) as exc:
        read_map(_save(doc, tmp_path))
    _one_line(exc, "MESH", "on layer POST_L", "not closed: 4 edges on one face only", "holds seam POST_L>")


# --- not a welding map, units, broken numbers, ezdxf's failures ---------------------------------------------------


def test_a_2d_drawing_is_told_it_is_no_welding_map_before_units(tmp_path: Path) -> None:
    doc = ezdxf.new("R2010", units=0)  # no units declared: still not asked for them
    for i in range(1200):
        doc.modelspace().add_line((i, 0), (i, 10))
    doc.modelspace().add_circle((0, 0), 5)
    with pytest.raises(MapError) as exc:
        read_map(_save(doc, tmp_path))
    _one_line(exc, "not a welding map: 1,200 LINEs, none red, also 1 CIRCLE; no 3D bodies")


def test_missing_units_name_the_command_line_fix(tmp_path: Path) -> None:
    path = make_maps.write_map(tmp_path / "v.dxf", PARTS, SEAMS, units=None, solid="mesh")
    with pytest.raises(MapError) as exc:
        read_map(path)
    _one_line(exc, f"`cell map info {path} --units mm`", "map.units")


@pytest.mark.parametrize(("value", "needle"), [("nan", "NaN or infinite"), ("1e20", "beyond 10 km")])
def test_broken_numbers_are_refused_naming_the_entity(tmp_path: Path, value: str, needle: str) -> None:
    doc = _doc()
    line = doc.modelspace().query("LINE")[2]
    path = _save(doc, tmp_path)
    text = path.read_text()
    # the line's x start (group 10) in the file: replace its value by a broken number
    at = text.index(f"\n  5\n{line.dxf.handle}\n")
    at = text.index("\n 10\n", at) + len("\n 10\n")
    path.write_text(text[:at] + value + text[text.index("\n", at) :])
    with pytest.raises(MapError) as exc:
        read_map(path)
    _one_line(exc, f"LINE {line.dxf.handle} on layer WELD_SEAMS", needle)


def test_ezdxf_failures_become_map_errors(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from cell.weldmap import _load, _meshes

    path = make_maps.write_map(tmp_path / "v.dxf", PARTS, SEAMS)  # ACIS solids, R2018 (binary SAB)

    def bad_sab(entity: object) -> list[object]:
        raise struct.error("unpack requires a buffer of 4 bytes")

    monkeypatch.setattr(_meshes.acis, "load_dxf", bad_sab)
    with pytest.raises(MapError) as exc:
        read_map(path)
    _one_line(
        exc, "3DSOLID", "on layer TOP_RAIL", "struct", "save the drawing as DXF R2000-R2010 or export bodies as MESH"
    )

    def bad_tag(*args: object, **kwargs: object) -> object:
        raise AssertionError("invalid id tag")

    monkeypatch.setattr(_load.ezdxf, "readfile", bad_tag)
    with pytest.raises(MapError) as exc:
        read_map(path)
    _one_line(exc, str(path), "AssertionError: invalid id tag")


def test_ezdxf_log_goes_to_ours_not_stderr(
    tmp_path: Path, capfd: pytest.CaptureFixture[str], caplog: pytest.LogCaptureFixture
) -> None:
    path = _save(_doc(in_blocks=True), tmp_path)
    text = path.read_text()
    at = text.index("\n  0\nENDBLK\n")  # a block without its ENDBLK: ezdxf warns, and reads on
    path.write_text(text[:at] + text[text.index("\n  0\n", at + 5) :])
    with caplog.at_level(logging.DEBUG, logger="cell.weldmap"):
        read_map(path)
    assert capfd.readouterr().err == ""  # the old reader let ezdxf print "Missing required ENDBLK ..." here
    assert any(
        r.name == "cell.weldmap" and "ezdxf warning: Missing required ENDBLK" in r.getMessage() for r in caplog.records
    )
    assert logging.getLogger("ezdxf").propagate  # restored after reading


# --- part names keep their case: the scenario's deviations still find their parts ------------------------------


def test_deviation_keys_match_part_names_ignoring_case_unless_ambiguous() -> None:
    from dataclasses import replace

    from cell import scenario as sc
    from cell.errors import ScenarioError
    from cell.sim.asbuilt.parts import as_built_parts
    from cell.types import Part, WeldMap

    base = sc.load("fence1-exact")
    parts = tuple(Part(n.title(), make_maps_box(lo, hi)) for n, (lo, hi) in PARTS.items())  # Top_Rail, Post_L...
    weldmap = WeldMap(parts, (), "mm", "test")
    grown = base.with_simulation(deviations={"TOP_RAIL": sc.Deviation(size_mm=(10.0, 0.0, 0.0))})
    built = {p.name: p for p in as_built_parts(weldmap, grown)}
    np.testing.assert_allclose(built["Top_Rail"].box.size[0], 1.41, atol=TOL)
    exact = replace(weldmap, parts=(*parts, Part("TOP_RAIL", parts[0].box)))  # an exact match wins
    assert {p.name: p for p in as_built_parts(exact, grown)}["Top_Rail"].box.size[0] == pytest.approx(1.4)
    with pytest.raises(ScenarioError, match=r"deviations\.TOP_RAIL matches parts Top_Rail, top_rail ignoring case"):
        as_built_parts(replace(weldmap, parts=(*parts, Part("top_rail", parts[0].box))), grown)


def make_maps_box(lo: tuple[float, float, float], hi: tuple[float, float, float]) -> Box:
    lo_m, hi_m = np.array(lo) * 1e-3, np.array(hi) * 1e-3
    return Box(make_pose(p=(lo_m + hi_m) / 2.0), hi_m - lo_m)


def test_degenerate_and_self_intersecting_faces(tmp_path: Path) -> None:
    doc = make_maps.build_map({k: v for k, v in PARTS.items() if k != "POST_L"}, SEAMS, solid="mesh")
    mesh = make_maps.box_mesh(*PARTS["POST_L"])
    mesh.faces = [*mesh.faces, (0, 1, 1)]  # a sliver: zero area
    mesh.render_mesh(doc.modelspace(), dxfattribs={"layer": "POST_L"})
    m = read_map(_save(doc, tmp_path))
    [w] = m.warnings
    assert "MESH" in w and "on layer POST_L has 1 zero-area face (ignored)" in w
    post = doc.modelspace().query("MESH")[-1]
    doc.modelspace().delete_entity(post)
    mesh.faces = [(0, 2, 3, 1), (4, 5, 6, 7), *mesh.faces[2:6]]  # the lid's corners out of order: a bow tie
    mesh.render_mesh(doc.modelspace(), dxfattribs={"layer": "POST_L"})
    with pytest.raises(MapError) as exc:
        read_map(_save(doc, tmp_path))
    _one_line(exc, "MESH", "on layer POST_L: part POST_L is not closed", "holds seam POST_L>")


def test_a_map_of_curves_only_is_read_with_its_curved_seams(tmp_path: Path) -> None:
    doc = make_maps.build_map(PARTS, [], solid="mesh")
    doc.modelspace().add_circle((240, 700, 80), 30, dxfattribs={"color": 1})
    m = read_map(_save(doc, tmp_path))
    assert not m.seams and [c.kind for c in m.curved] == ["circle"]
    assert m.not_welded[0].code == Unsupported.CURVED_NOT_LOCATED


def test_fixtures_are_obstacles_of_the_motion_scene() -> None:
    from types import SimpleNamespace

    from cell import scenario as sc
    from cell.motion.robot import RobotModel
    from cell.pipeline.geometry import motion_scene
    from cell.station.arm import robot_urdf
    from cell.types import Part, WeldMap

    scn = sc.load("fence1-exact")
    model = RobotModel.from_urdf(robot_urdf(scn))
    q = np.radians(np.asarray(scn.robot.home_deg, dtype=float))
    p_R = model.fk(q, "tool0")[:3, 3]  # a clamp drawn right where the flange is at home
    clamp = Part("CLAMP_1", Box(make_pose(p=p_R), np.array([0.2, 0.2, 0.2])))
    weldmap_R = WeldMap((), (), "mm", "test", "R", fixtures=(clamp,))
    scene = motion_scene(SimpleNamespace(model=model), SimpleNamespace(scenario=scn, weldmap_R=weldmap_R))  # type: ignore[arg-type]
    assert "CLAMP_1" in scene.checker.obstacle_names
    contact = scene.checker.check(q)
    assert contact is not None and "CLAMP_1" in (contact.a, contact.b)
