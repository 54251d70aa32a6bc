"""The realism options of ``simulation:`` (docs/bodies.md section 7): varying gaps, tack welds, a bow, specular
dropout. Small and direct: the as-built geometry of fence1's map, one synthetic depth image."""

from __future__ import annotations

import importlib
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from dxf_factory import REPO_ROOT  # puts tools/ on the path

from cell.errors import ScenarioError
from cell.scenario import Scenario, SpecularDropoutSpec, from_dict, load
from cell.seams.joint import find_joints
from cell.seams.truth import true_seams
from cell.sim.asbuilt.parts import as_built_fixtures, as_built_parts
from cell.sim.asbuilt.shapes import bowed, cut_end, principal_frame
from cell.sim.camera import intrinsics_for
from cell.sim.noise import specular_dropout
from cell.types import Box, Part, Polyhedron, WeldMap
from cell.weldmap import read_map


@pytest.fixture(scope="module")
def fence1() -> tuple[Scenario, WeldMap]:
    scenario = load("fence1")
    return scenario, read_map(scenario.map_path)


def _with(scenario: Scenario, **simulation: Any) -> Scenario:
    data = scenario.model_dump()
    data["simulation"].update(simulation)
    return from_dict(data, base_dir=Path(scenario.base_dir))


def _part(parts: tuple[Part, ...], name: str) -> Part:
    return next(p for p in parts if p.name == name)


def test_every_option_is_off_by_default(fence1: tuple[Scenario, WeldMap]) -> None:
    scenario, weldmap = fence1
    sim = scenario.simulation
    assert sim.gaps is None and sim.tacks_present is None and sim.bow == () and sim.specular_dropout is None
    assert all(p.is_box for p in as_built_parts(weldmap, scenario))
    assert as_built_fixtures(weldmap, scenario) == ()


def test_gap_opens_from_zero_to_max_along_the_seam(fence1: tuple[Scenario, WeldMap]) -> None:
    scenario, weldmap = fence1
    plain = as_built_parts(weldmap, scenario)
    gapped = as_built_parts(weldmap, _with(scenario, gaps={"max_mm": 2.0}))
    a0, a1 = _part(plain, "BOTTOM_RAIL"), _part(gapped, "BOTTOM_RAIL")
    assert not a1.is_box and _part(gapped, "TOP_RAIL").is_box  # only abutting parts are cut
    post = _part(plain, "POST_L").box
    n, d = post.face_plane("+x")
    on_end = a1.vertices() @ n < d + 0.01  # the rail's end at POST_L
    gap0 = np.abs(a0.box.corners() @ n - d)[on_end]
    gap1 = np.abs(a1.vertices() @ n - d)[on_end]
    opened = (gap1 - gap0) * 1000.0
    assert opened.min() == pytest.approx(0.0, abs=1e-6)
    assert opened.max() == pytest.approx(2.0, abs=1e-6)
    # Along the junction's horizontal seam (+z: along y) the opening grows linearly from one end to the other.
    ys = a1.vertices()[on_end, 1]
    order = np.argsort(ys)
    assert abs(opened[order][0] - opened[order][-1]) == pytest.approx(2.0, abs=1e-6)


def test_tacks_lie_in_the_corner_at_both_ends_of_every_seam(fence1: tuple[Scenario, WeldMap]) -> None:
    scenario, weldmap = fence1
    tacked = _with(scenario, tacks_present={"length_mm": 10.0, "leg_mm": 4.0})
    tacks = as_built_fixtures(weldmap, tacked)
    assert len(tacks) == 2 * len(weldmap.seams)
    truth = true_seams(weldmap, find_joints(weldmap), as_built_parts(weldmap, tacked), np.eye(4))
    seam_id = "POST_L>TOP_RAIL:+z"
    start = next(t for t in tacks if t.name == f"tack:{seam_id}:start")
    end = next(t for t in tacks if t.name == f"tack:{seam_id}:end")
    assert start.volume == pytest.approx(0.5 * 0.004**2 * 0.010, rel=1e-6)
    p0, p1 = truth[seam_id]
    assert np.linalg.norm(start.vertices()[0] - p0) < 1e-9 and np.linalg.norm(end.vertices()[3] - p1) < 1e-9
    # In the corner: above the rail's top... the bead's legs run along the rail's -y face and up the post's top.
    legs = start.vertices()[1:3] - p0
    assert sorted(np.round(np.abs(legs).max(axis=1) * 1000.0, 3)) == [4.0, 4.0]


def test_bow_has_its_sagitta_and_moves_the_seams_on_the_bowed_face(fence1: tuple[Scenario, WeldMap]) -> None:
    scenario, weldmap = fence1
    box = Box(np.eye(4), np.array([1.4, 0.1, 0.1])).to_polyhedron()
    X_AP, _, _ = principal_frame(box)
    bent = bowed(box, X_AP, 0.0015, 1, 16)
    assert len([n for n in bent.names if n.startswith("+y@")]) == 16
    mid = np.abs(bent.vertices[:, 0]) < 1e-9
    assert float(bent.vertices[mid, 1].max()) - 0.05 == pytest.approx(0.0015, abs=1e-9)
    assert float(np.abs(bent.vertices[:8, 1]).max()) == pytest.approx(0.05, abs=1e-6)  # the ends stay put
    bow = _with(scenario, bow={"part": "TOP_RAIL", "mm": 1.5})
    joints = find_joints(weldmap)
    t0 = true_seams(weldmap, joints, as_built_parts(weldmap, scenario), np.eye(4))
    t1 = true_seams(weldmap, joints, as_built_parts(weldmap, bow), np.eye(4))
    shift = t1["POST_L>TOP_RAIL:+x"][0] - t0["POST_L>TOP_RAIL:+x"][0]
    # The rail (1420 mm as built) bulges away from the posts; the post's +x side is 420 mm from its middle:
    # 1.5 mm x (1 - (2 x 420 / 1420)^2) = 0.975 mm, less the tilt of the rail's as-built turn.
    assert shift[1] * 1000.0 == pytest.approx(0.95, abs=0.05)
    assert np.linalg.norm(t1["BOTTOM_RAIL>POST_L:+z"][0] - t0["BOTTOM_RAIL>POST_L:+z"][0]) < 1e-9
    dev = scenario.model_dump()["simulation"]["deviations"]
    dev["TOP_RAIL"]["bow_mm"] = 1.5  # the same bow, given with the part's deviations
    t2 = true_seams(weldmap, joints, as_built_parts(weldmap, _with(scenario, deviations=dev)), np.eye(4))
    assert np.array_equal(t2["POST_L>TOP_RAIL:+x"][0], t1["POST_L>TOP_RAIL:+x"][0])
    with pytest.raises(ScenarioError, match="bowed twice"):
        as_built_parts(weldmap, _with(scenario, deviations=dev, bow={"part": "TOP_RAIL", "mm": 1.0}))
    with pytest.raises(ScenarioError, match="names no one part"):
        as_built_parts(weldmap, _with(scenario, bow={"part": "NOPE", "mm": 1.0}))


def test_specular_dropout_takes_the_fraction_of_pixels_facing_the_camera() -> None:
    intr = intrinsics_for(64, 48, np.radians(10.0))  # every ray within 6 degrees of the axis
    facing = np.full((48, 64), 1.0)
    spec = SpecularDropoutSpec(within_deg=8.0, fraction=0.7)
    out = specular_dropout(facing, facing, intr, spec, np.random.default_rng(3))
    assert (out == 0).mean() == pytest.approx(0.7, abs=0.03)
    v = np.arange(48)[:, None].repeat(64, axis=1)
    tilted = 1.0 / (1.0 - (v - intr.cy) / intr.fy)  # the plane z = 1 + y: 45 degrees to the axis
    kept = specular_dropout(tilted, tilted, intr, spec, np.random.default_rng(3))
    assert (kept == 0).mean() == 0.0


def test_tacks_are_rendered_and_turn_with_the_part(fence1: tuple[Scenario, WeldMap]) -> None:
    from cell.geometry import make_pose
    from cell.sim import SimCell

    scenario, weldmap = fence1
    tacked = _with(scenario, tacks_present={"length_mm": 10.0, "leg_mm": 4.0}, noise="none")
    tacks = as_built_fixtures(weldmap, tacked)
    with SimCell(tacked, as_built_parts(weldmap, tacked), fixtures_W=tacks) as sim:
        name = "tack:POST_L>TOP_RAIL:+z:start"
        assert name in sim.bodies and not any(n.startswith("fixture:") for n in sim.bodies)
        before = sim.client.getBasePositionAndOrientation(sim.body_id(name))[0]
        sim.move_part(make_pose(p=(0.0, 0.0, 0.1)))
        after = sim.client.getBasePositionAndOrientation(sim.body_id(name))[0]
        assert after[2] - before[2] == pytest.approx(0.1, abs=1e-9)


def test_the_rhs_map_reads_as_hollow_tubes_and_every_seam_has_a_truth() -> None:
    scenario = load("rhs")
    weldmap = read_map(scenario.map_path)
    assert [p.kind for p in weldmap.parts] == ["mesh"] * 4 and len(weldmap.seams) == 12
    top = weldmap.part("TOP_RAIL")
    assert len(top.face_names()) == 80
    # Open ends: the volume is the wall's (4 mm, corner radii 8 and 4 mm, 4 facets a quarter) times 1.4 m, not a box's.
    assert 1.4 * 0.1 * 0.1 * 0.1 < top.volume < 1.4 * 0.1 * 0.1 * 0.2
    joints = find_joints(weldmap)
    parts = as_built_parts(weldmap, scenario, joints)
    truth = true_seams(weldmap, joints, parts, scenario.X_WR)
    assert len(truth) == 12
    lengths = [float(np.linalg.norm(b - a)) * 1000.0 for a, b in truth.values()]
    assert min(lengths) > 40.0 and max(lengths) < 70.0
    assert len(as_built_fixtures(weldmap, scenario, joints)) == 24  # two tacks a seam


def test_make_rhs_writes_the_shipped_map_byte_for_byte(tmp_path: Path) -> None:
    make_rhs = importlib.import_module("make_rhs")  # tools/make_rhs.py (tools/ is on the path: dxf_factory)
    assert make_rhs.write_rhs_map(tmp_path / "rhs.dxf").read_bytes() == (REPO_ROOT / "maps" / "rhs.dxf").read_bytes()


def test_an_end_cut_out_of_square_keeps_a_mitred_bodys_faces_plane() -> None:
    """A brace leaning at 35 deg, its end mitred to lie flat: the end cut out of square slides each end vertex along
    the brace's edge, so its broad faces stay planes (moved along the end's normal, they were warped by the gap's
    share and the true seam along them was lost) and the gap still opens from 0 to its maximum."""
    a, length, w, t = np.radians(35.0), 0.1, 0.04, 0.006
    base = np.array([[0.0, 0.0, 0.0], [w, 0.0, 0.0], [w, t, 0.0], [0.0, t, 0.0]])
    axis = np.array([0.0, np.cos(a), np.sin(a)])
    v = np.vstack([base, base + length * axis])
    faces = ((0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7))
    body = Polyhedron(v, faces)
    end = body.names[0]  # the bottom, flat on what it meets
    cut = cut_end(body, end, np.array([1.0, 0.0, 0.0]), 0.002)
    for name, face in zip(cut.names, cut.faces, strict=True):
        n, d = cut.face_plane(name)
        assert np.max(np.abs(cut.vertices[list(face)] @ n - d)) < 1e-12, name
    rise = cut.vertices[:4, 2]  # how far each end vertex moved back off the plane it lay on
    np.testing.assert_allclose(rise, [0.0, 0.002, 0.002, 0.0], atol=1e-12)
    np.testing.assert_allclose(cut.vertices[4:], v[4:])  # the other end untouched
