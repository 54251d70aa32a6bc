"""The random-cell generator (tools/random_cells.py): reproducible from its seed alone, every cell readable and laid
out as the cell needs it, and the named layouts holding the parts and seams they promise."""

from __future__ import annotations

import json
import math
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest
from tools_loader import load_tool

from cell import scenario as sc
from cell.pipeline.geometry import robot_arm
from cell.scenario.init import check_layout
from cell.seams.joint import dihedral, find_joints
from cell.seams.truth import true_seams
from cell.types import Polyhedron, WeldMap
from cell.weldmap import read_map


@pytest.fixture(scope="module")
def rc() -> ModuleType:
    return load_tool("random_cells")


def _truth(cell: object) -> dict:
    return json.loads(cell.truth.read_text(encoding="utf-8"))  # type: ignore[attr-defined]


def _drawn_where_the_truth_lies(weldmap: WeldMap) -> None:
    """Every drawn seam is the cell's true seam of the parts as drawn (docs/bodies.md section 3), within 1 um."""
    truth = true_seams(weldmap, find_joints(weldmap), weldmap.parts, np.eye(4))
    for seam in weldmap.seams:
        p0, p1 = truth[seam.id]
        assert np.linalg.norm(p0 - seam.p_start) < 1e-6 and np.linalg.norm(p1 - seam.p_end) < 1e-6, seam.id


def test_same_seed_gives_byte_identical_files(rc: ModuleType, tmp_path: Path) -> None:
    for seed, kind in ((11, "random"), (1001, "random"), (11, "mitred_ladder:33")):
        a, b = rc.make_cell(seed, tmp_path / "a", kind), rc.make_cell(seed, tmp_path / "b", kind)
        assert seed != 1001 or _truth(a)["redraws"] >= 1  # a draw rejected and drawn again: the same again
        for name in rc.FILES:
            assert (a.scenario.parent / name).read_bytes() == (b.scenario.parent / name).read_bytes(), (kind, name)


def test_different_seeds_give_different_cells(rc: ModuleType, tmp_path: Path) -> None:
    a, b = rc.make_cell(11, tmp_path / "a"), rc.make_cell(12, tmp_path / "b")
    for name in rc.FILES:
        assert (a.scenario.parent / name).read_bytes() != (b.scenario.parent / name).read_bytes(), name


def test_twenty_random_cells_load_and_are_laid_out_for_the_cell(rc: ModuleType, tmp_path: Path) -> None:
    kinds, noises, exact, perturbed, features = set(), set(), 0, 0, set()
    for seed in range(20):
        cell = rc.make_cell(seed, tmp_path / f"cell-{seed}")
        truth = _truth(cell)
        scn = sc.load(cell.scenario)
        weldmap = read_map(scn.map_path)
        assert check_layout(scn, weldmap) == [], seed
        robot_arm(scn)  # the arm reaches the scan pose (IKError otherwise)
        joints = find_joints(weldmap)  # every drawn seam has its joint, as the truth says
        assert sorted(joints) == sorted(s["id"] for s in truth["seams"])
        _drawn_where_the_truth_lies(weldmap)
        for s in truth["seams"]:
            j = joints[s["id"]]
            assert (j.abutting, j.receiving) == (s["abutting"], s["receiving"])
            assert 35.0 <= math.degrees(dihedral(weldmap, j)) <= 145.0
        assert len(weldmap.curved) == len(truth["curved_seams"]) and not weldmap.unsupported
        assert [f.name for f in weldmap.fixtures] == [f["name"] for f in truth["fixtures"]]
        fixed = [c for c in scn.cameras.values() if c.mount == "fixed"]
        assert 2 <= len(fixed) <= 4 and sum(c.mount == "eye_in_hand" for c in scn.cameras.values()) == 1
        centre = np.array(truth["placement"]["part_centre_m"])
        for cam in fixed:
            d = np.subtract(cam.eye_m, centre)
            assert 0.8 - 1e-6 <= np.linalg.norm(d) <= 2.2 + 1e-6
            assert 25.0 - 1e-6 <= math.degrees(math.atan2(d[2], math.hypot(d[0], d[1]))) <= 75.0 + 1e-6
            assert cam.calibration.translation_mm == cam.extrinsic_error.translation_mm
            assert cam.calibration.rotation_deg == cam.extrinsic_error.rotation_deg
            if cam.extrinsic_error.translation_mm == 0.0:
                exact += 1
            else:
                perturbed += 1
                assert 0.3 <= cam.extrinsic_error.translation_mm <= 1.0
                assert 0.03 <= cam.extrinsic_error.rotation_deg <= 0.1
        kinds |= {p["kind"] for p in truth["parts"]}
        features |= {k for p in truth["parts"] for k in ("angle_to_base_deg", "angle_to_plates_deg") if k in p}
        features |= {"ends_against"} if truth["ends_against"] else set()
        features |= {"fixture"} if truth["fixtures"] else set()
        features |= {"curved"} if truth["curved_seams"] else set()
        noises.add(scn.noise)
        assert truth["seed"] == seed and truth["kind"] == "random" and truth["redraws"] >= 0
    assert kinds >= {"plate", "box", "rhs", "flat", "brace"} and kinds & {"tube", "pipe"}
    assert noises == {"none", "realistic"} and exact and perturbed
    assert features == {"angle_to_base_deg", "angle_to_plates_deg", "ends_against", "fixture", "curved"}


def test_post_pipes_has_a_square_post_among_two_pipes(rc: ModuleType, tmp_path: Path) -> None:
    cell = rc.make_cell(3, tmp_path, "post_pipes")
    truth, scn = _truth(cell), sc.load(cell.scenario)
    kinds = {p["name"]: p["kind"] for p in truth["parts"]}
    assert kinds == {"PLATE": "plate", "POST": "box", "PIPE_1": "pipe", "PIPE_2": "pipe"}
    _drawn_where_the_truth_lies(read_map(cell.map))
    post = read_map(cell.map).part("POST")
    assert post.is_box and sorted(np.round(post.box.size * 1000, 6))[:2] == [40.0, 40.0]
    assert sorted(s["id"] for s in truth["seams"]) == sorted(f"POST>PLATE:{f}" for f in ("+x", "-x", "+y", "-y"))
    fixed = [c for c in scn.cameras.values() if c.mount == "fixed"]
    assert len(fixed) == 3 and scn.noise == "realistic" and not scn.deviations
    assert all(c.extrinsic_error.translation_mm == c.calibration.translation_mm == 0.0 for c in scn.cameras.values())


def test_web_tube_fillets_end_at_the_tube_wall(rc: ModuleType, tmp_path: Path) -> None:
    cell = rc.make_cell(3, tmp_path, "web_tube")
    weldmap = read_map(cell.map)
    _drawn_where_the_truth_lies(weldmap)
    assert {p.name: p.drawn_as for p in weldmap.parts} == {"PLATE": "MESH", "WEB": "MESH", "TUBE": "MESH"}
    tube = weldmap.part("TUBE").body
    assert isinstance(tube, Polyhedron)
    assert len(weldmap.seams) == 2
    for seam in weldmap.seams:
        ends = np.stack([seam.p_start, seam.p_end])
        to_wall = np.min([tube.face_distance(f, ends) for f in tube.face_names()], axis=0)
        assert sorted(to_wall)[0] <= 0.001 and sorted(to_wall)[1] > 0.1  # one end at the wall, the other far


@pytest.mark.parametrize("angle", [25.0, 44.0, 60.0])
def test_mitred_ladder_brace_at_the_angle_asked(rc: ModuleType, tmp_path: Path, angle: float) -> None:
    cell = rc.make_cell(5, tmp_path, f"mitred_ladder:{angle:g}")
    weldmap = read_map(cell.map)
    _drawn_where_the_truth_lies(weldmap)
    top = [s.id for s in weldmap.seams if s.id.startswith("BRACE>") and s.id.endswith(":top")]
    assert sorted(top) == ["BRACE>RUNG_1:top", "BRACE>RUNG_2:top"]
    rung = weldmap.part("RUNG_1").box
    rung_axis = rung.X_AB[:3, int(np.argmax(rung.size))]
    brace_body = weldmap.part("BRACE").body
    normals = [brace_body.face_plane(f)[0] for f in brace_body.face_names()]
    cheeks = [n for n in normals if abs(n[2]) < 1e-9 and abs(n @ rung_axis) > 1e-6]  # not the ends, top or bottom
    assert len(cheeks) == 2
    for n in cheeks:  # the brace's axis lies along its cheeks
        axis = np.cross(n, [0.0, 0.0, 1.0])
        assert math.degrees(math.acos(abs(axis @ rung_axis))) == pytest.approx(angle, abs=1e-6)
    brace = weldmap.part("BRACE")
    assert not brace.is_box
    gap = brace.vertices()[:, 0].min() - rung.corners()[:, 0].max()
    assert gap == pytest.approx(0.001, abs=1e-9)
    bottom = [s for s in weldmap.seams if s.id.startswith("BRACE>") and s.id.endswith(":bottom")]
    assert len(bottom) == 2 and all(s.length == pytest.approx(0.030 / math.sin(math.radians(angle))) for s in bottom)
    assert _truth(cell)["facts"]["brace_angle_to_rungs_deg"] == angle


def test_unknown_kinds_are_refused(rc: ModuleType, tmp_path: Path) -> None:
    for kind in ("ladder", "mitred_ladder:10", "post_pipes:3"):
        with pytest.raises(ValueError):
            rc.make_cell(1, tmp_path, kind)


def test_command_line_writes_one_folder_per_seed(
    rc: ModuleType, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert rc.main(["--seed", "4", "--count", "2", "--out", str(tmp_path)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 2 and all("seams" in line for line in lines)
    for seed in (4, 5):
        assert sorted(p.name for p in (tmp_path / f"cell-{seed}").iterdir()) == sorted(rc.FILES)
