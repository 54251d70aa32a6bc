"""CAD in (cell/cad, ``cell map from-cad``): the benchmark part's situation made here (tests/cad_parts.py: a plate,
a web forming a T, a tube standing on the plate, a bolt with washer and nut through a hole), as a STEP assembly
written with OpenCascade and as one STL of several bodies; every fillet proposed within 0.1 mm of its true place,
none at the bolt, and the map written loads in the welding-map reader with the proposals as its seams."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from cad_parts import TRUE_CIRCLES, TRUE_LINES, TUBE, WEB, write_step, write_stl
from typer.testing import CliRunner

from cell.cad import (
    GAP_M,
    MIN_LENGTH_M,
    CurveKind,
    Proposal,
    Proposals,
    Rejection,
    Role,
    propose,
    read_cad,
)
from cell.cli import app
from cell.cli.cad import GAP_MM, MIN_LENGTH_MM
from cell.errors import MapError, MapUnitsError
from cell.weldmap import read_map

TOL_MM = 0.1


@pytest.fixture(scope="module")
def step_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_step(tmp_path_factory.mktemp("cad") / "bench.step")


@pytest.fixture(scope="module")
def stl_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_stl(tmp_path_factory.mktemp("cad") / "bench.stl")


@pytest.fixture(scope="module")
def from_step(step_file: Path) -> Proposals:
    return propose(read_cad(step_file))


def _line_error_mm(s: Proposal, a: tuple[float, ...], b: tuple[float, ...]) -> float:
    """The larger distance between the seam's ends and the true ends, either way round [mm]."""
    P = s.curve.points * 1000.0
    A = np.array([a, b])
    return float(min(np.abs(P - A).max(), np.abs(P[::-1] - A).max()))


def _circle_error_mm(s: Proposal, centre: tuple[float, ...], radius: float) -> float:
    c = s.curve
    return max(float(np.linalg.norm(c.centre * 1000.0 - centre)), abs(c.radius * 1000.0 - radius))


def _check_every_fillet(found: Proposals, names: dict[str, str]) -> None:
    """Each true fillet proposed once within TOL_MM (``names``: the test part's names -> the file's)."""
    proposed = found.proposed
    web, plate, tube = names["WEB"], names["PLATE"], names["TUBE"]
    for true_id, (a, b) in TRUE_LINES.items():
        where = true_id.split(":")[1]
        (s,) = [s for s in proposed if s.id == f"{web}>{plate}:{where}"]
        assert s.curve.kind == CurveKind.LINE and _line_error_mm(s, a, b) <= TOL_MM, (s.id, s.curve.points)
        assert s.joint.value == "T" and math.degrees(s.dihedral) == pytest.approx(90.0, abs=0.5)
    (centre, radius) = TRUE_CIRCLES["TUBE>PLATE"]
    circles = [s for s in proposed if s.abutting == tube and s.receiving == plate]
    assert len(circles) == 1 and circles[0].curve.closed and circles[0].curved
    assert _circle_error_mm(circles[0], centre, radius) <= TOL_MM
    assert np.abs(circles[0].curve.axis) @ np.array([0.0, 0.0, 1.0]) == pytest.approx(1.0, abs=1e-6)
    # Nothing else is proposed: the web's 12 mm ends and the tube's bore are listed, rejected with their reason.
    assert len(proposed) == 3, [s.id for s in proposed]
    why = {s.id: s.rejected for s in found.seams if s.abutting in (web, tube) and s.rejected is not None}
    assert sorted(why.values()) == sorted([Rejection.SHORT, Rejection.SHORT, Rejection.BORE]), why


def test_step_proposes_every_fillet_within_a_tenth_of_a_millimetre(from_step: Proposals) -> None:
    assert from_step.model.units == "mm"
    names = {b.name for b in from_step.model.bodies}
    assert names == {"PLATE", "WEB", "TUBE", "BOLT_M12X40", "WASHER", "HEX_NUT"}  # the assembly's names kept
    _check_every_fillet(from_step, {"WEB": "WEB", "PLATE": "PLATE", "TUBE": "TUBE"})


def test_step_keeps_exact_planes_and_cylinders(from_step: Proposals) -> None:
    tube = next(b for b in from_step.model.bodies if b.name == "TUBE")
    radii = sorted(round(f.radius * 1000.0, 6) for f in tube.faces if f.kind.value == "cylinder")
    assert radii == [TUBE[2], TUBE[1]]  # the bore and the outer wall, exactly
    bore = next(f for f in tube.faces if f.kind.value == "cylinder" and f.radius < 0.026)
    assert bore.sign == -1.0  # its outward normal points at the axis
    web = next(b for b in from_step.model.bodies if b.name == "WEB")
    assert len(web.faces) == 6 and {f.kind.value for f in web.faces} == {"plane"}


def test_no_seam_is_proposed_at_the_bolt(from_step: Proposals) -> None:
    roles = dict(zip([b.name for b in from_step.model.bodies], from_step.roles, strict=True))
    assert [n for n, r in roles.items() if r == Role.FASTENER] == ["BOLT_M12X40", "WASHER", "HEX_NUT"]
    fasteners = {"BOLT_M12X40", "WASHER", "HEX_NUT"}
    on_them = [s for s in from_step.seams if {s.abutting, s.receiving} & fasteners]
    assert on_them and all(s.rejected == Rejection.FASTENER for s in on_them)


def test_a_bolt_is_told_by_its_place_when_nothing_is_named(tmp_path: Path) -> None:
    found = propose(read_cad(write_step(tmp_path / "unnamed.step", names=False)))
    roles = [r.value for r in found.roles]
    assert roles == ["part", "part", "part", "fastener", "fastener", "fastener"]  # through the hole, and on it
    _check_every_fillet(found, {"PLATE": "SOLID1", "WEB": "SOLID2", "TUBE": "SOLID3"})


def test_stl_of_several_bodies_with_a_solid_header(stl_file: Path) -> None:
    assert stl_file.read_bytes()[:5] == b"solid"  # binary all the same
    model = read_cad(stl_file, units="mm")
    assert len(model.bodies) == 3
    by_size = sorted(model.bodies, key=lambda b: -b.volume)  # plate, web, tube (of 64 sections)
    names = {"PLATE": by_size[0].name, "WEB": by_size[1].name, "TUBE": by_size[2].name}
    _check_every_fillet(propose(model), names)


def test_mesh_units_asked_when_the_size_does_not_tell(stl_file: Path) -> None:
    with pytest.raises(MapError, match="no such file"):
        read_cad(stl_file.with_name("missing.stl"), units="mm")
    with pytest.raises(MapUnitsError) as e:  # 400 units: 0.4 m in mm, 10 m in inches: both could be
        read_cad(stl_file)
    assert "--units" in e.value.message and e.value.exit_code == 12
    assert read_cad(stl_file, units="in").units == "in"


def test_a_third_body_covering_the_seam_cuts_it(tmp_path: Path) -> None:
    # A gusset standing against the web's -x face, on the plate: the web's -x fillet stops on either side of it.
    from cad_parts import write_step_with_gusset

    found = propose(read_cad(write_step_with_gusset(tmp_path / "g.step")))
    minus_x = sorted(
        (s for s in found.proposed if s.abutting == "WEB" and s.id.split(":")[1].startswith("-x")),
        key=lambda s: float(s.curve.points[:, 1].min()),
    )
    spans = [sorted(s.curve.points[:, 1] * 1000.0) for s in minus_x]
    assert len(spans) == 2, [s.id for s in found.proposed]
    (a0, a1), (b0, b1) = spans
    assert a0 == pytest.approx(WEB[0][1], abs=TOL_MM) and b1 == pytest.approx(WEB[1][1], abs=TOL_MM)
    assert a1 == pytest.approx(140.0, abs=TOL_MM) and b0 == pytest.approx(152.0, abs=TOL_MM)  # the gusset's faces


@pytest.mark.parametrize(
    ("name", "content", "needle"),
    [
        ("bad.step", b"not a step file", "not a readable STEP file"),
        ("bad.stl", b"\x00\x01 not a mesh", "mesh"),
        ("part.iges", b"IGES", "valid: .step, .stp, .stl, .obj, .ply"),
    ],
)
def test_bad_files_are_refused_in_one_line(tmp_path: Path, name: str, content: bytes, needle: str) -> None:
    bad = tmp_path / name
    bad.write_bytes(content)
    with pytest.raises(MapError) as e:
        read_cad(bad, units="mm")
    assert needle in e.value.message and "\n" not in e.value.message and e.value.exit_code == 11


def test_from_cad_writes_a_map_the_reader_welds(step_file: Path, tmp_path: Path) -> None:
    assert (GAP_MM, MIN_LENGTH_MM) == (GAP_M * 1000.0, MIN_LENGTH_M * 1000.0)
    out = tmp_path / "bench.dxf"
    result = CliRunner().invoke(app, ["map", "from-cad", str(step_file), "--out", str(out)])
    assert result.exit_code == 0, result.stderr
    assert "WEB>PLATE:-x" in result.stdout and "rejected: fastener" in result.stdout
    assert (tmp_path / "bench.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    weldmap = read_map(out)
    assert sorted(s.id for s in weldmap.seams) == ["WEB>PLATE:+x", "WEB>PLATE:-x"]  # red: welded
    [circle] = weldmap.curved  # the curve: read as a curved seam
    assert circle.id == "TUBE>PLATE:circle.1" and circle.kind == "circle" and not weldmap.unsupported
    tube = weldmap.part("TUBE").cylinder  # the STEP's tube, tessellated into the MESH: recognised as round again
    assert tube is not None and abs(tube.radius - 0.03) < 1e-4 and abs(tube.inner_radius - 0.025) < 1e-4
    assert circle.joint is not None and (circle.joint.abutting, circle.joint.receiving) == ("TUBE", "PLATE")
    assert circle.joint.surfaces == "cylinder_on_plane" and circle.joint.kind == "T"
    assert sorted(p.name for p in weldmap.parts) == ["PLATE", "TUBE", "WEB"]
    assert sorted(f.name for f in weldmap.fixtures) == ["BOLT_M12X40", "HEX_NUT", "WASHER"]
    for s in weldmap.seams:
        (a, b) = TRUE_LINES[s.id]
        ends = np.array([s.p_start, s.p_end]) * 1000.0
        assert min(np.abs(ends - [a, b]).max(), np.abs(ends[::-1] - [a, b]).max()) <= TOL_MM
    again = tmp_path / "again.dxf"
    CliRunner().invoke(app, ["map", "from-cad", str(step_file), "--out", str(again)])
    assert again.read_bytes() == out.read_bytes()  # byte-stable
    info = CliRunner().invoke(app, ["map", "info", str(out)])
    assert info.exit_code == 0 and "T 90 deg  WEB > PLATE" in info.stdout


def test_units_come_from_the_step_header(tmp_path: Path) -> None:
    inch = write_step(tmp_path / "inch.step", inches=True)
    assert "CONVERSION_BASED_UNIT('INCH'" in inch.read_text()
    model = read_cad(inch)
    assert model.units == "in" and model.warnings == ()
    _check_every_fillet(propose(model), {"WEB": "WEB", "PLATE": "PLATE", "TUBE": "TUBE"})
    told = read_cad(inch, units="mm")  # the user's units win (a header written wrong), with a warning
    assert told.units == "mm" and "declares in" in told.warnings[0]
    web = next(b for b in told.bodies if b.name == "WEB")
    assert float(web.extent[1]) == pytest.approx(0.200 / 25.4, rel=1e-9)


def test_an_obj_keeps_its_objects_names(tmp_path: Path) -> None:
    import trimesh  # the test writes the file; cell.cad reads it through its adapter

    plate = trimesh.creation.box(extents=(400.0, 300.0, 12.0))
    plate.apply_translation((200.0, 150.0, 6.0))
    web = trimesh.creation.box(extents=(12.0, 200.0, 100.0))
    web.apply_translation((150.0, 150.0, 62.0))
    scene = trimesh.Scene()
    scene.add_geometry(plate, geom_name="Base plate")
    scene.add_geometry(web, geom_name="WEB")
    path = tmp_path / "part.obj"
    scene.export(path)
    found = propose(read_cad(path, units="mm"))
    assert sorted(b.name for b in found.model.bodies) == ["BASE_PLATE", "WEB"]  # a space is no layer character
    assert sorted(s.id for s in found.proposed) == ["WEB>BASE_PLATE:+x", "WEB>BASE_PLATE:-x"]


def test_init_from_a_mesh_asks_for_its_units_and_writes_the_map_beside_the_scenario(
    stl_file: Path, tmp_path: Path
) -> None:
    runner = CliRunner()
    scenario = tmp_path / "cell" / "part.yaml"
    scenario.parent.mkdir()
    result = runner.invoke(app, ["init", str(stl_file), "--out", str(scenario)])
    assert result.exit_code == 12 and "--units" in result.stderr and not scenario.exists()
    result = runner.invoke(app, ["init", str(stl_file), "--out", str(scenario), "--units", "mm"])
    assert result.exit_code == 0, result.stderr
    assert (tmp_path / "cell" / "part.dxf").is_file() and (tmp_path / "cell" / "part.png").is_file()
    assert "file: part.dxf" in scenario.read_text()
    again = runner.invoke(app, ["init", str(stl_file), "--out", str(scenario), "--units", "mm"])
    assert again.exit_code == 2 and "exists" in again.stderr  # neither the scenario nor its map overwritten


def _boxes_stl(path: Path, boxes: list[tuple[tuple[float, float, float], tuple[float, float, float]]]) -> Path:
    import trimesh

    meshes = []
    for lo, hi in boxes:
        m = trimesh.creation.box(extents=np.subtract(hi, lo))
        m.apply_translation(np.add(lo, hi) / 2.0)
        meshes.append(m)
    trimesh.util.concatenate(meshes).export(path)
    return path


def test_a_lap_plate_and_an_l_corner(tmp_path: Path) -> None:
    base = ((0.0, 0.0, 0.0), (400.0, 250.0, 12.0))
    lap = ((50.0, 40.0, 12.0), (150.0, 210.0, 20.0))  # 8 mm plate lying on the base: four lap fillets
    wall = ((388.0, 0.0, 12.0), (400.0, 250.0, 150.0))  # standing flush on the base's +x edge: an L
    found = propose(read_cad(_boxes_stl(tmp_path / "l.stl", [base, lap, wall]), units="mm"))
    names = {round(float(b.extent[2]) * 1000.0): b.name for b in found.model.bodies}  # 12, 8, 138 mm tall
    laps = [s for s in found.proposed if s.abutting == names[8]]
    assert len(laps) == 4 and {s.joint.value for s in laps} == {"lap"}
    assert sorted(round(s.curve.length * 1000.0, 6) for s in laps) == [100.0, 100.0, 170.0, 170.0]
    (inside,) = [s for s in found.proposed if s.abutting == names[138]]  # the outside of the L is flush: none
    assert inside.joint.value == "corner" and inside.id.endswith(":-x")
    assert np.allclose(inside.curve.points[:, 0] * 1000.0, 388.0) and inside.curve.length == pytest.approx(0.25)


def test_a_body_on_a_fixture_layer_of_the_step_is_a_fixture(tmp_path: Path) -> None:
    from cad_parts import write_step as write

    found = propose(read_cad(write(tmp_path / "clamped.step", clamp=True)))
    block = next(b for b in found.model.bodies if b.name == "BLOCK")
    assert block.layers == ("FIXTURE_CLAMPS",)
    assert found.roles[found.model.bodies.index(block)] == Role.FIXTURE
    on_it = [s for s in found.seams if "BLOCK" in (s.abutting, s.receiving)]
    assert on_it and all(s.rejected == Rejection.FIXTURE for s in on_it)  # its fillets on the plate: not welded
