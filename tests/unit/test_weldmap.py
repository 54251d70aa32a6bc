"""Welding maps: generated DXF files read as designed, drawing variants read the same, bad files refused."""

from __future__ import annotations

from pathlib import Path

import ezdxf
import numpy as np
import pytest
from dxf_factory import REPO_ROOT, design, make_maps, scaled
from ezdxf.render import MeshTransformer

from cell.errors import MapError, MapUnitsError
from cell.geometry import make_pose, rpy_to_matrix, transform_points
from cell.types import WeldMap
from cell.weldmap import describe, fit_box, read_map

MAPS = REPO_ROOT / "maps"
TOL = 1e-6  # [m]
MM = 1e-3


def check_design(m: WeldMap, parts: dict[str, make_maps.BoxSpec], seams: list[make_maps.SeamSpec]) -> None:
    """``m`` holds exactly the designed parts (named in the layers' case) and seams (given in mm), in metres, axes
    along M's."""
    assert [p.name for p in m.parts] == list(parts)
    for name, (lo, hi) in parts.items():
        box = m.part(name).box
        np.testing.assert_allclose(box.size, (np.array(hi) - lo) * MM, atol=TOL)
        np.testing.assert_allclose(box.center, (np.array(hi) + lo) / 2 * MM, atol=TOL)
        np.testing.assert_allclose(box.X_AB[:3, :3], np.eye(3), atol=1e-9)
    assert [s.id for s in m.seams] == [i for i, _, _ in seams]
    for seam_id, a, b in seams:
        s = m.seam(seam_id)
        np.testing.assert_allclose(s.p_start, np.array(a) * MM, atol=TOL)
        np.testing.assert_allclose(s.p_end, np.array(b) * MM, atol=TOL)


# --- The shipped maps --------------------------------------------------------------------------------


@pytest.mark.parametrize(("name", "n_parts", "n_seams"), [("fence1", 4, 16), ("fence2", 4, 16), ("ladder", 28, 208)])
def test_shipped_map_reads_as_designed(name: str, n_parts: int, n_seams: int) -> None:
    m = read_map(MAPS / f"{name}.dxf")
    assert (len(m.parts), len(m.seams), m.units, m.frame) == (n_parts, n_seams, "mm", "M")
    check_design(m, *design(name))


@pytest.mark.parametrize("name", ["fence1", "fence2", "ladder"])
def test_seam_end_points_lie_on_the_faces_named_by_their_id(name: str) -> None:
    m = read_map(MAPS / f"{name}.dxf")
    for s in m.seams:
        joint, face = s.id.split(":")
        abutting, receiving = (m.part(n).box for n in joint.split(">"))
        n_a, d_a = abutting.face_plane(face)
        # the receiving face: the abutting part lies wholly outside it, within the 1 mm gap
        faces = [receiving.face_plane(f) for f in ("+x", "-x", "+y", "-y", "+z", "-z")]
        [(n_r, d_r)] = [(n, d) for n, d in faces if np.all(abutting.corners() @ n - d > -TOL)]
        for p in (s.p_start, s.p_end):
            assert abs(n_a @ p - d_a) < TOL, f"{s.id}: not on {face} of the abutting part"
            assert abs(n_r @ p - d_r) < TOL, f"{s.id}: not on the receiving face"
        assert abs(s.direction @ n_a) < 1e-9 and abs(s.direction @ n_r) < 1e-9
        assert np.all(s.p_end - s.p_start >= -1e-12)  # lower coordinate first


def test_fence1_example_seams_from_the_brief() -> None:
    m = read_map(MAPS / "fence1.dxf")
    top = m.seam("POST_L>TOP_RAIL:+z")
    np.testing.assert_allclose([top.p_start, top.p_end], [[0.2, 0.7, 0.08], [0.28, 0.7, 0.08]], atol=TOL)
    side = m.seam("POST_L>TOP_RAIL:-x")
    np.testing.assert_allclose([side.p_start, side.p_end], [[0.2, 0.7, 0.0], [0.2, 0.7, 0.08]], atol=TOL)
    bottom = m.seam("POST_L>TOP_RAIL:-z")
    assert bottom.p_start[2] == bottom.p_end[2] == 0.0  # against the table
    # the bottom rail's seams lie on the post's inner face, 1 mm from the rail's end
    assert m.seam("BOTTOM_RAIL>POST_L:+z").p_start[0] == pytest.approx(0.280)
    assert m.part("BOTTOM_RAIL").box.corners()[:, 0].min() == pytest.approx(0.281)


def test_generator_reproduces_the_shipped_maps(tmp_path: Path) -> None:
    assert make_maps.main(["--out", str(tmp_path)]) == 0
    for name in ("fence1", "fence2", "ladder"):
        assert (tmp_path / f"{name}.dxf").read_bytes() == (MAPS / f"{name}.dxf").read_bytes(), name


def test_describe_lists_parts_and_seams() -> None:
    text = describe(read_map(MAPS / "fence1.dxf"))
    assert "units: mm" in text and "fence1.dxf" in text
    assert "1400.0 x 100.0 x 100.0 mm" in text
    assert text.count("\n") >= 1 + 4 + 16
    assert "POST_L>TOP_RAIL:+z" in text


def test_junction_seams_refuse_overlapping_boxes() -> None:
    parts = {"A": ((0.0, 0.0, 0.0), (10.0, 10.0, 10.0)), "B": ((5.0, 5.0, 0.0), (20.0, 20.0, 10.0))}
    with pytest.raises(ValueError, match="exactly one axis"):
        make_maps.junction_seams(parts, "A", "B")


# --- Drawing variants that must read the same ------------------------------------------------------------


@pytest.mark.parametrize(
    "options",
    [
        {"seam_color": "bylayer"},
        {"seam_color": "truecolor"},
        {"solid": "mesh"},
        {"solid": "polyface"},
        {"dxfversion": "R2010"},  # ACIS as SAT text
        {"in_blocks": True},
        {"in_blocks": True, "block_rotation_deg": 30.0, "seam_color": "bylayer", "solid": "mesh"},
        {"in_blocks": True, "block_rotation_deg": -90.0},
    ],
    ids=lambda o: ",".join(f"{k}={v}" for k, v in o.items()),
)
def test_variants_read_as_designed(tmp_path: Path, options: dict) -> None:
    parts, seams = design("fence1")
    path = make_maps.write_map(tmp_path / "v.dxf", parts, seams, **options)
    check_design(read_map(path), parts, seams)


def test_layer_names_in_any_case(tmp_path: Path) -> None:
    parts, seams = design("fence2")
    lower = {n.lower(): box for n, box in parts.items()}
    doc = make_maps.build_map(lower, seams, seam_layer="weld_seams", seam_color="bylayer")
    for line in doc.modelspace().query("LINE"):
        line.dxf.layer = "Weld_Seams"  # the layer table says "weld_seams": DXF layer names ignore case
    doc.saveas(tmp_path / "v.dxf")
    check_design(read_map(tmp_path / "v.dxf"), lower, seams)


@pytest.mark.parametrize(("units", "code", "factor"), [("m", 6, 1e-3), ("cm", 5, 0.1), ("in", 1, 1 / 25.4)])
def test_units_scale_the_geometry(tmp_path: Path, units: str, code: int, factor: float) -> None:
    parts, seams = design("fence1")
    path = make_maps.write_map(tmp_path / "v.dxf", *scaled(parts, seams, factor), units=code)
    m = read_map(path)
    assert m.units == units and m.warnings == ()
    check_design(m, parts, seams)
    assert read_map(path, units=units).warnings == ()  # an override that agrees says nothing


def test_the_callers_units_win_over_declared_ones_with_a_warning(tmp_path: Path) -> None:
    # Drawn in metres, declared in inches: the parts came out 36 mm long, silently.
    parts, seams = design("fence1")
    path = make_maps.write_map(tmp_path / "v.dxf", *scaled(parts, seams, 1e-3), units=1)
    doubted = read_map(path)
    assert doubted.units == "in"
    [doubt] = doubted.warnings
    assert "read in inches, the map is only 35.6 mm across" in doubt and "--units m" in doubt
    m = read_map(path, units="m")
    assert m.units == "m"
    check_design(m, parts, seams)
    assert len(m.warnings) == 1 and "$INSUNITS=1 (in); read in m as asked" in m.warnings[0]


@pytest.mark.parametrize("code", [None, 0])
def test_no_units_needs_the_override(tmp_path: Path, code: int | None) -> None:
    parts, seams = design("fence1")
    path = make_maps.write_map(tmp_path / "v.dxf", *scaled(parts, seams, 0.1), units=code)
    m = read_map(path, units="cm")
    assert m.units == "cm"
    check_design(m, parts, seams)
    with pytest.raises(MapUnitsError, match=r"map\.units.*mm, cm, m, in"):
        read_map(path)


def test_unknown_units_override_is_refused() -> None:
    with pytest.raises(MapUnitsError, match=r"'ft'.*valid: mm, cm, m, in"):
        read_map(MAPS / "fence1.dxf", units="ft")


def test_unsupported_declared_units_are_refused(tmp_path: Path) -> None:
    parts, seams = design("fence1")
    path = make_maps.write_map(tmp_path / "v.dxf", parts, seams, units=2)  # feet
    with pytest.raises(MapUnitsError, match=r"\$INSUNITS=2.*cell map info .* --units mm"):
        read_map(path)
    m = read_map(path, units="mm")  # the caller's units make it usable
    assert m.units == "mm" and "$INSUNITS=2" in m.warnings[0]


def test_seam_ids_fall_back_to_handles(tmp_path: Path) -> None:
    parts, seams = design("fence1")
    doc = make_maps.build_map(parts, seams, in_blocks=True)
    for block in doc.blocks:
        for e in block:
            e.discard_xdata("WELDCELL")
    doc.saveas(tmp_path / "v.dxf")
    a, b = read_map(tmp_path / "v.dxf"), read_map(tmp_path / "v.dxf")
    ids = [s.id for s in a.seams]
    assert ids == [s.id for s in b.seams]  # stable
    assert len(set(ids)) == 16
    assert all(i.startswith("seam-") and i.count(".") == 2 for i in ids)  # two INSERTs deep
    np.testing.assert_allclose(a.seams[0].p_start, np.array(seams[0][1]) * MM, atol=TOL)


def test_bodies_on_one_layer_get_a_suffix_and_minsert_expands(tmp_path: Path) -> None:
    parts, seams = design("fence1")
    doc = make_maps.build_map(parts, seams)
    msp = doc.modelspace()
    make_maps.box_mesh((0, 900, 0), (50, 950, 50)).render_mesh(msp, dxfattribs={"layer": "POST_L"})
    block = doc.blocks.new("CLAMP")
    make_maps.box_mesh((0, 0, 0), (10, 20, 30)).render_polyface(block, dxfattribs={"layer": "0"})
    ref = msp.add_blockref("CLAMP", (0, -100, 0))
    ref.grid(size=(1, 3), spacing=(1, 40))  # MINSERT, 3 columns 40 mm apart
    doc.saveas(tmp_path / "v.dxf")
    m = read_map(tmp_path / "v.dxf")
    names = [p.name for p in m.parts]
    assert names == ["TOP_RAIL", "POST_L_1", "POST_R", "BOTTOM_RAIL", "POST_L_2"]
    np.testing.assert_allclose(m.part("POST_L_2").box.center, [0.025, 0.925, 0.025], atol=TOL)
    # a block named CLAMP* is a fixture (an obstacle), never a part
    assert [f.name for f in m.fixtures] == ["CLAMP_1", "CLAMP_2", "CLAMP_3"]
    np.testing.assert_allclose(m.fixtures[2].box.center, [0.085, -0.090, 0.015], atol=TOL)


def test_byblock_seams_take_the_colour_of_their_insert(tmp_path: Path) -> None:
    parts, _ = design("fence1")
    doc = make_maps.build_map(parts, [])
    block = doc.blocks.new("WELD")
    block.add_line((0, 0, 0), (0, 0, 80), dxfattribs={"color": 0})
    block.add_line((0, 0, 0), (80, 0, 0), dxfattribs={"color": 3})  # green: not a seam
    doc.modelspace().add_blockref("WELD", (200, 700, 0), dxfattribs={"color": 1})
    doc.modelspace().add_blockref("WELD", (280, 700, 0), dxfattribs={"color": 5})  # blue: not seams
    doc.saveas(tmp_path / "v.dxf")
    m = read_map(tmp_path / "v.dxf")
    assert len(m.seams) == 1
    np.testing.assert_allclose(m.seams[0].p_end, [0.2, 0.7, 0.08], atol=TOL)


# --- Box fitting --------------------------------------------------------------------------------


def _mesh_arrays(lo: tuple, hi: tuple, X: np.ndarray) -> tuple[np.ndarray, list[tuple[int, ...]]]:
    mesh = make_maps.box_mesh(lo, hi)
    return transform_points(X, np.array(mesh.vertices)), [tuple(f) for f in mesh.faces]


def test_fit_box_recovers_a_known_pose() -> None:
    rng = np.random.default_rng(7)
    for _ in range(20):
        R = rpy_to_matrix(rng.uniform(-0.6, 0.6, 3).tolist())  # within 35 deg: the axes keep their M axis
        X = make_pose(R, rng.uniform(-2, 2, 3))
        size = rng.uniform(0.01, 2.0, 3)
        v, f = _mesh_arrays(tuple(-size / 2), tuple(size / 2), X)
        box = fit_box(v, f, "P")
        np.testing.assert_allclose(box.X_AB, X, atol=1e-9)
        np.testing.assert_allclose(box.size, size, atol=1e-9)


def test_fit_box_orders_axes_like_m_and_right_handed() -> None:
    R = rpy_to_matrix([0.0, 0.0, np.radians(100.0)])  # box x now points along M's y
    v, f = _mesh_arrays((-0.5, -0.1, -0.05), (0.5, 0.1, 0.05), make_pose(R))
    box = fit_box(v, f, "P")
    np.testing.assert_allclose(box.size, [0.2, 1.0, 0.1], atol=1e-12)
    Rb = box.X_AB[:3, :3]
    assert np.linalg.det(Rb) == pytest.approx(1.0)
    assert np.all(np.diag(Rb) > 0.9)


def test_fit_box_refuses_an_l_shape() -> None:
    L = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
    v = np.array([(x, y, z) for z in (0.0, 0.5) for x, y in L], dtype=float)
    faces = [(5, 4, 3, 2, 1, 0), (6, 7, 8, 9, 10, 11)] + [(i, (i + 1) % 6, (i + 1) % 6 + 6, i + 6) for i in range(6)]
    with pytest.raises(MapError, match="part ELL is not a box"):
        fit_box(v, faces, "ELL")


def test_fit_box_refuses_a_skewed_body() -> None:
    v, f = _mesh_arrays((0, 0, 0), (1, 1, 1), np.eye(4))
    v[7] += [0.0, 0.0, 0.005]  # one corner 5 mm up
    with pytest.raises(MapError, match="not a box"):
        fit_box(v, f, "P")
    v[7] -= [0.0, 0.0, 0.00495]  # 0.05 mm off: a box within 0.1 mm
    assert fit_box(v, f, "P").size[2] == pytest.approx(1.0, abs=1e-4)


# --- Bad files --------------------------------------------------------------------------------


def _refused(path: Path, cls: type[MapError], *needles: str) -> str:
    with pytest.raises(cls) as info:
        read_map(path)
    msg = str(info.value)
    assert "\n" not in msg
    exc = info.value  # raised "from None": no chained ezdxf traceback
    assert exc.__cause__ is None and (exc.__context__ is None or exc.__suppress_context__)
    for n in needles:
        assert n in msg, msg
    return msg


def test_not_dxf(tmp_path: Path) -> None:
    junk = tmp_path / "junk.dxf"
    junk.write_bytes(np.random.default_rng(1).integers(0, 256, 4000, dtype=np.uint8).tobytes())
    _refused(junk, MapError, str(junk), "DXF")
    text = tmp_path / "notes.dxf"
    text.write_text("these are my welding notes\nseam 1: 80 mm\n")
    _refused(text, MapError, str(text), "DXF")
    empty = tmp_path / "empty.dxf"
    empty.write_bytes(b"")
    _refused(empty, MapError, str(empty))
    _refused(tmp_path / "missing.dxf", MapError, "not found")
    _refused(tmp_path, MapError, "not found")


@pytest.mark.parametrize("fraction", [0.05, 0.5, 0.97, 0.9999])
def test_truncated_dxf(tmp_path: Path, fraction: float) -> None:
    data = (MAPS / "fence1.dxf").read_bytes()
    path = tmp_path / "cut.dxf"
    path.write_bytes(data[: int(len(data) * fraction)])
    _refused(path, MapError, str(path))


def test_no_red_seams(tmp_path: Path) -> None:
    parts, seams = design("fence1")
    doc = make_maps.build_map(parts, seams, seam_color="bylayer")
    doc.layers.get("WELD_SEAMS").color = 3  # green layer: the seams are not red any more
    doc.saveas(tmp_path / "v.dxf")
    _refused(tmp_path / "v.dxf", MapError, "no red weld seams")


def test_no_parts(tmp_path: Path) -> None:
    _, seams = design("fence1")
    _refused(make_maps.write_map(tmp_path / "v.dxf", {}, seams), MapError, "no parts")


def test_empty_drawing(tmp_path: Path) -> None:
    _refused(make_maps.write_map(tmp_path / "v.dxf", {}, []), MapError, "empty")


def test_flat_drawing(tmp_path: Path) -> None:
    doc = ezdxf.new("R2018", units=4)
    msp = doc.modelspace()
    msp.add_lwpolyline([(200, 0), (280, 0), (280, 699), (200, 699)], close=True, dxfattribs={"layer": "POST_L"})
    msp.add_line((200, 700), (280, 700), dxfattribs={"color": 1})
    msp.add_line((200, 700), (200, 800), dxfattribs={"color": 1})
    doc.saveas(tmp_path / "flat.dxf")
    _refused(tmp_path / "flat.dxf", MapError, "flat")


def test_zero_length_seam(tmp_path: Path) -> None:
    parts, seams = design("fence1")
    seams[3] = ("DOT", (10.0, 10.0, 10.0), (10.0, 10.0, 10.0))
    _refused(make_maps.write_map(tmp_path / "v.dxf", parts, seams), MapError, "seam DOT has zero length")


def test_duplicate_seam_ids(tmp_path: Path) -> None:
    parts, seams = design("fence1")
    seams[1] = (seams[0][0], *seams[1][1:])
    _refused(make_maps.write_map(tmp_path / "v.dxf", parts, seams), MapError, seams[0][0], "unique")


def test_a_solid_without_flat_faces(monkeypatch: pytest.MonkeyPatch) -> None:
    # ezdxf meshes only the flat faces of an ACIS body: a cylinder or sphere comes back empty
    from cell.weldmap import _meshes

    monkeypatch.setattr(_meshes.acis, "mesh_from_body", lambda body: [MeshTransformer()])
    _refused(MAPS / "fence1.dxf", MapError, "3DSOLID", "TOP_RAIL", "no flat faces")


def test_a_part_that_is_not_a_box(tmp_path: Path) -> None:
    parts, seams = design("fence1")
    doc = make_maps.build_map(parts, seams)
    mesh = make_maps.box_mesh((0, 900, 0), (50, 950, 50))
    mesh.vertices[7] = mesh.vertices[7] + (0, 0, 20)  # a wedge, not a box
    mesh.render_mesh(doc.modelspace(), dxfattribs={"layer": "Wedge"})
    doc.saveas(tmp_path / "v.dxf")
    m = read_map(tmp_path / "v.dxf")  # a closed body that is not a box: a polyhedral part
    assert [p.name for p in m.parts] == [*parts, "Wedge"] and not m.part("Wedge").is_box and not m.warnings
    doc = make_maps.build_map(parts, seams)
    mesh.faces = mesh.faces[1:]  # an open body: it holds no seam, so it is skipped with a warning naming it
    mesh.render_mesh(doc.modelspace(), dxfattribs={"layer": "Wedge"})
    doc.saveas(tmp_path / "v.dxf")
    m = read_map(tmp_path / "v.dxf")
    assert [p.name for p in m.parts] == list(parts)
    [w] = m.warnings
    assert "MESH" in w and "on layer Wedge: part Wedge is not closed" in w and "skipped" in w
    doc.modelspace().add_line((0, 900, 50), (50, 900, 50), dxfattribs={"color": 1})  # now it holds a seam
    doc.saveas(tmp_path / "v.dxf")
    _refused(tmp_path / "v.dxf", MapError, "MESH", "on layer Wedge: part Wedge is not closed", "v.dxf", "holds seam")
