"""Round bodies: tessellated tubes and bars (MESH, 3DFACE; 16 to 64 facets, any pose) recognised as cylinders;
the joint of a curved seam from the surfaces it lies on; the true curve of a curved seam on the as-built parts."""

from __future__ import annotations

import math
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from dxf_factory import make_maps
from round_meshes import add_spline_seam, add_tube_on_plane_seam, plane_cut, pose, rot_y, saddle_points, tube_mesh

from cell.geometry import make_pose, rpy_to_matrix
from cell.seams.curve_truth import true_curve_W
from cell.types import Part, Polyhedron, Surface
from cell.weldmap import read_map
from cell.weldmap.cylinders import recognise_cylinder

AXIS_RAD = 1e-9  # the recognised axis is within this of the drawn one (the corners lie exactly on the round)
RADIUS_M = 1e-9  # and the radius within this


def _flat(z0: float, z1: float):  # type: ignore[no-untyped-def]
    return (lambda x, y: z0), (lambda x, y: z1)


def _save(doc: ezdxf.document.Drawing, tmp_path: Path, name: str = "round.dxf") -> Path:
    path = tmp_path / name
    doc.saveas(path)
    return path


def _plate_and_tube(doc: ezdxf.document.Drawing, X_MT: np.ndarray, facets: int, as_faces: bool) -> None:
    msp = doc.modelspace()
    make_maps.box_mesh((-200, -200, 0), (200, 200, 20)).render_mesh(msp, dxfattribs={"layer": "PLATE"})
    mesh = tube_mesh(30.0, 25.0, facets, plane_cut(X_MT, (0, 0, 1), 20.0), lambda x, y: 300.0, X_MT)
    if as_faces:  # every face as 3DFACEs (a quad each, or triangles), as some exporters write bodies
        for f in mesh.faces:
            v = [mesh.vertices[i] for i in f]
            for k in range(1, len(v) - 1, 2):
                corners = [v[0], v[k], v[k + 1], v[k + 2] if k + 2 < len(v) else v[k + 1]]
                msp.add_3dface(corners, dxfattribs={"layer": "TUBE"})
    else:
        mesh.render_mesh(msp, dxfattribs={"layer": "TUBE"})


@pytest.mark.parametrize(("facets", "as_faces"), [(16, False), (32, True), (48, False), (64, True)])
def test_a_tessellated_tube_is_a_cylinder_in_any_pose(tmp_path: Path, facets: int, as_faces: bool) -> None:
    rng = np.random.default_rng(facets)
    X = make_pose(rpy_to_matrix(rng.uniform(-0.4, 0.4, 3)), [rng.uniform(-50, 50), rng.uniform(-50, 50), 40.0])
    doc = ezdxf.new("R2018", units=4)
    _plate_and_tube(doc, X, facets, as_faces)
    doc.layers.add("WELD_SEAMS", color=1)
    axis = X[:3, 2]
    foot = X[:3, 3] + (20.0 - X[2, 3]) / axis[2] * axis  # the axis meets the plate's top here
    add_tube_on_plane_seam(doc.modelspace(), "TUBE>PLATE", foot, axis, 30.0, (0, 0, 1), "WELD_SEAMS")
    m = read_map(_save(doc, tmp_path))
    part = m.part("TUBE")
    c = part.cylinder
    assert c is not None and part.drawn_as == ("3DFACE" if as_faces else "MESH") and c.facets == facets
    assert math.acos(min(1.0, abs(float(c.axis @ axis)))) < AXIS_RAD
    assert abs(c.radius - 0.03) < RADIUS_M and abs(c.inner_radius - 0.025) < RADIUS_M
    assert float(np.abs(c.distance_to_axis(X[:3, 3][None] * 1e-3))[0]) < 1e-9  # the axis goes through the drawn one
    assert m.part("PLATE").cylinder is None  # a box is no round body
    [seam] = m.curved
    assert seam.joint is not None and seam.joint.surfaces == "cylinder_on_plane" and seam.joint.abutting == "TUBE"


def test_prisms_and_boxes_are_not_round() -> None:
    hexagon = tube_mesh(30.0, 0.0, 6, *_flat(0.0, 100.0), np.eye(4))
    body = Polyhedron(np.array(hexagon.vertices) * 1e-3, tuple(tuple(f) for f in hexagon.faces))
    assert recognise_cylinder(body) is None
    bar = tube_mesh(30.0, 0.0, 24, *_flat(0.0, 100.0), np.eye(4))  # a solid round bar: no bore
    c = recognise_cylinder(Polyhedron(np.array(bar.vertices) * 1e-3, tuple(tuple(f) for f in bar.faces)))
    assert c is not None and c.inner_radius == 0.0 and math.isclose(c.length, 0.1)


def _joint_map(tmp_path: Path, lean_deg: float) -> object:
    """A plate, a tube leaning ``lean_deg`` standing on it, a ring flange slid over the tube higher up, a branch
    coped onto a run pipe lying on the plate; their curved seams."""
    doc = ezdxf.new("R2018", units=4)
    msp = doc.modelspace()
    doc.layers.add("WELD_SEAMS", color=1)
    make_maps.box_mesh((-300, -300, 0), (300, 300, 20)).render_mesh(msp, dxfattribs={"layer": "PLATE"})
    X = pose(rot_y(lean_deg), (-150.0, 0.0, 20.0))
    tube_mesh(30.0, 25.0, 48, plane_cut(X, (0, 0, 1), 20.0), lambda x, y: 250.0, X).render_mesh(
        msp, dxfattribs={"layer": "TUBE"}
    )
    add_tube_on_plane_seam(msp, "TUBE>PLATE", (-150.0, 0.0, 20.0), X[:3, 2], 30.0, (0, 0, 1), "WELD_SEAMS")
    # A ring flange (a short wide tube whose bore is the tube's round) on the tube, 150 mm along its axis.
    q = X[:3, 3] + 150.0 * X[:3, 2]
    tube_mesh(60.0, 30.0, 48, *_flat(150.0, 162.0), X).render_mesh(msp, dxfattribs={"layer": "RING"})
    add_tube_on_plane_seam(msp, "RING>TUBE", q + 12.0 * X[:3, 2], X[:3, 2], 30.0, X[:3, 2], "WELD_SEAMS")
    X_run = pose(rot_y(90.0), (150.0, 0.0, 80.0))
    tube_mesh(57.15, 51.15, 64, *_flat(-120.0, 120.0), X_run).render_mesh(msp, dxfattribs={"layer": "RUN"})

    def cope(x: float, y: float) -> float:
        return 80.0 + math.sqrt(57.15**2 - y**2)

    tube_mesh(30.15, 26.15, 48, cope, lambda x, y: 300.0, pose(np.eye(3), (150.0, 0.0, 0.0))).render_mesh(
        msp, dxfattribs={"layer": "BRANCH"}
    )
    add_spline_seam(msp, "BRANCH>RUN", saddle_points(150.0, 30.15, 80.0, 57.15), "WELD_SEAMS")
    return read_map(_save(doc, tmp_path))


def test_a_curved_seams_joint_comes_from_the_surfaces_it_lies_on(tmp_path: Path) -> None:
    m = _joint_map(tmp_path, 20.0)
    joints = {c.id: c.joint for c in m.curved}
    foot, ring, saddle = joints["TUBE>PLATE"], joints["RING>TUBE"], joints["BRANCH>RUN"]
    assert foot is not None and (foot.abutting, foot.receiving, foot.surfaces) == ("TUBE", "PLATE", "cylinder_on_plane")
    assert foot.kind == "T"  # a tube standing on a plate is a T fillet, 90 -+ its lean around
    np.testing.assert_allclose([foot.dihedral_min_rad, foot.dihedral_max_rad], np.radians([70.0, 110.0]), atol=1e-3)
    assert ring is not None and (ring.abutting, ring.receiving) == ("RING", "TUBE")  # the tube goes on through it
    assert (ring.abutting_surface, ring.receiving_surface) == (Surface.PLANE, Surface.CYLINDER)
    np.testing.assert_allclose([ring.dihedral_min_rad, ring.dihedral_max_rad], [math.pi / 2] * 2, atol=1e-3)
    assert saddle is not None and (saddle.abutting, saddle.receiving, saddle.surfaces) == (
        "BRANCH",
        "RUN",
        "cylinder_on_cylinder",
    )


def test_the_truth_of_a_leaning_tube_is_its_ellipse(tmp_path: Path) -> None:
    lean = 25.0
    m = _joint_map(tmp_path, lean)
    seam = next(c for c in m.curved if c.id == "TUBE>PLATE")
    # As built the tube stands 1.5 mm and 0.2 degrees off: the true curve is the moved cylinder on the plate.
    tube = m.part("TUBE")
    X_off = make_pose(rpy_to_matrix([0.0, 0.0, math.radians(0.2)]), [0.0015, -0.0008, 0.0])
    built = [Part(p.name, p.body.transformed(X_off), p.drawn_as) if p.name == "TUBE" else p for p in m.parts]
    P = true_curve_W(m, seam, built, np.eye(4))
    assert np.all(np.linalg.norm(np.diff(P, axis=0), axis=1) <= 0.0005 + 1e-12)  # sampled at most 0.5 mm apart
    c = tube.cylinder
    assert c is not None
    axis = X_off[:3, :3] @ c.axis
    foot = X_off[:3, :3] @ np.array([-0.15, 0.0, 0.02]) + X_off[:3, 3]  # the moved axis meets the plate's top here
    u = np.array([axis[0], axis[1], 0.0]) / np.linalg.norm(axis[:2])  # the lean's direction in the plate
    v = np.cross([0.0, 0.0, 1.0], u)
    a, b = 0.03 / math.cos(math.radians(lean)), 0.03  # closed form: semi-axes r / cos(lean) and r
    d = P - foot
    assert np.allclose(P[:, 2], 0.02, atol=1e-12)
    residual = np.sqrt((d @ u / a) ** 2 + (d @ v / b) ** 2) - 1.0
    assert float(np.abs(residual).max()) < 1e-9
    assert float(np.ptp(d @ u)) == pytest.approx(2 * a, abs=1e-6)


def test_the_truth_of_a_saddle_lies_on_both_pipes(tmp_path: Path) -> None:
    m = _joint_map(tmp_path, 0.0)
    seam = next(c for c in m.curved if c.id == "BRANCH>RUN")
    P = true_curve_W(m, seam, m.parts, np.eye(4))
    run, branch = m.part("RUN").cylinder, m.part("BRANCH").cylinder
    assert run is not None and branch is not None
    assert float(np.abs(run.distance_to_axis(P) - run.radius).max()) < 1e-9
    assert float(np.abs(branch.distance_to_axis(P) - branch.radius).max()) < 1e-9
    assert float(np.ptp(P[:, 2])) == pytest.approx(0.05715 - math.sqrt(0.05715**2 - 0.03015**2), abs=1e-6)


def test_make_round_writes_the_shipped_maps_byte_for_byte(tmp_path: Path) -> None:
    import make_round

    assert make_round.main(["--out", str(tmp_path)]) == 0
    for name in make_round.MAPS:
        assert (tmp_path / f"{name}.dxf").read_bytes() == (make_maps.REPO_ROOT / "maps" / f"{name}.dxf").read_bytes()


@pytest.mark.parametrize(
    ("scenario", "surfaces"),
    [
        ("pipe-flange", {"cylinder_on_plane": 1}),
        ("railing", {"cylinder_on_plane": 4}),
        ("round-brace", {"cylinder_on_plane": 2}),
        ("tube-tee", {"cylinder_on_plane": 2, "cylinder_on_cylinder": 1}),
    ],
)
def test_the_round_scenarios_curved_seams_have_their_joints_and_truths(scenario: str, surfaces: dict[str, int]) -> None:
    from collections import Counter

    from cell.pipeline.detect import read_weldmap
    from cell.scenario import load
    from cell.seams.curve_truth import true_curves
    from cell.sim.asbuilt.parts import as_built_parts

    sc = load(scenario)
    m = read_weldmap(sc)
    assert Counter(c.joint.surfaces for c in m.curved if c.joint is not None) == surfaces and not m.warnings
    assert all(c.joint is not None and c.joint.kind == "T" for c in m.curved)
    truth = true_curves(m, as_built_parts(m, sc), sc.X_WM, sc.X_WR)  # on the deviated parts, in R
    for c in m.curved:
        drawn_R = c.transformed(np.linalg.inv(sc.X_WR) @ sc.X_WM).sample(0.0005)
        gap = np.linalg.norm(truth[c.id][:, None] - drawn_R[None], axis=2).min(axis=1)
        assert 0.0 < float(gap.max()) < 0.006  # the deviations move each curve, by millimetres at most


def test_a_round_tube_is_rendered_from_its_facets(tmp_path: Path) -> None:
    from pinhole import deproject

    from cell import scenario as scn
    from cell.sim import SimCell

    (tmp_path / "dummy.dxf").write_text("not read by this test\n")
    sc = scn.from_yaml(
        """
name: tiny-tube
seed: 3
simulation: {noise: none}
map: {file: dummy.dxf, X_WM: {xyz_m: [0.0, 0.0, 0.9]}}
table: {center_m: [0.0, 0.0, 0.85], size_m: [1.2, 0.8, 0.1]}
cameras:
  above: {eye_m: [0.35, 0.05, 1.4], target_m: [0.0, 0.0, 0.95], resolution: [160, 120], hfov_deg: 30}
perception:
  workspace: {min_m: [-1.0, -1.0, 0.9], max_m: [1.0, 1.0, 1.5]}
""",
        base_dir=tmp_path,
    )
    mesh = tube_mesh(30.0, 25.0, 48, *_flat(900.0, 1000.0), np.eye(4))  # standing on the table top (z 0.9 m)
    body = Polyhedron(np.array(mesh.vertices) * 1e-3, tuple(tuple(f) for f in mesh.faces))
    c = recognise_cylinder(body)
    assert c is not None
    with SimCell(sc, [Part("TUBE", body, "MESH", c)]) as sim:
        image = sim.capture("above")
    p_W = deproject(image)[image.depth > 0]
    side = p_W[(p_W[:, 2] > 0.902) & (p_W[:, 2] < 0.998)]
    r = c.distance_to_axis(side)
    outer, bore = side[r > 0.0275], r[r <= 0.0275]  # its near side outside, its far side inside the bore
    r_out = c.distance_to_axis(outer)
    assert len(outer) > 200 and len(bore) > 50  # every point on a facet of the round, within the facets' sagitta
    assert float(r_out.max()) < c.radius + 2e-4 and float(r_out.min()) > c.radius - c.sagitta_m - 2e-4
    sag_in = c.inner_radius * (1.0 - math.cos(math.pi / c.facets))
    assert float(bore.max()) < c.inner_radius + 2e-4 and float(bore.min()) > c.inner_radius - sag_in - 2e-4
    assert float(np.ptp(np.arctan2(outer[:, 1], outer[:, 0]))) > math.radians(120)  # across the round
