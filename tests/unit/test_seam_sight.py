"""Which cameras see each seam's two faces (cell/rescan/sight.py, the close-up view's own test), ``cell init``'s fixed
cameras laid out by it (a web standing along x and along y: both fillets seen) and ``cell scenario check``'s line per
seam and its warning for a seam no camera of the first scan sees."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from dxf_factory import web_on_plate
from typer.testing import CliRunner

from cell import scenario as sc
from cell.cli import app
from cell.config.motion import ViewOptions
from cell.geometry import look_at
from cell.pipeline import read_weldmap
from cell.rescan.sight import Blind, camera_sight, first_scan_sight, lens, occluders, seam_target
from cell.scenario.init import layout
from cell.seams.joint import find_joints
from cell.weldmap import read_map

runner = CliRunner()
REPO = Path(__file__).resolve().parents[2]


def _fixed_faces(scenario_path: Path) -> dict[str, list[list[str]]]:
    """Seam id -> per face, the fixed cameras that see it (the eye-in-hand camera left out)."""
    scn = sc.load(scenario_path)
    fixed = {n for n, c in scn.cameras.items() if c.mount == "fixed"}
    out = {}
    for s in first_scan_sight(scn, read_weldmap(scn)):
        out[s.seam_id] = [[c.camera for c in s.face_seen_by(k) if c.camera in fixed] for k in (0, 1)]
    return out


@pytest.mark.parametrize("along", ["x", "y"])
def test_init_places_fixed_cameras_that_see_both_fillets_of_a_web(tmp_path: Path, along: str) -> None:
    dxf = web_on_plate(tmp_path / f"web_{along}.dxf", along)
    out = tmp_path / f"web_{along}.yaml"
    result = runner.invoke(app, ["init", str(dxf), "--out", str(out)])
    assert result.exit_code == 0, result.stderr
    seen = _fixed_faces(out)
    assert len(seen) == 2
    for sid, faces in seen.items():
        assert faces[0] and faces[1], (sid, faces)  # the web's side and the plate's top, each by a fixed camera
    check = runner.invoke(app, ["scenario", "check", str(out)])
    assert check.exit_code == 0 and check.stdout.startswith("ok:"), check.stdout + check.stderr
    assert check.stdout.count("both faces seen by") == 2


def test_the_shipped_pair_sees_a_web_along_x_edge_on(tmp_path: Path) -> None:
    """The rule before the faces were looked at (a pair either side along x, in the web's mid-plane) sees neither
    web side: the prediction can fail, and does where the issue saw it fail."""
    weldmap = read_map(web_on_plate(tmp_path / "w.dxf", "x"))
    lay = layout(weldmap)  # no sight: the shipped pair
    X_WM = np.eye(4)
    X_WM[:3, 3] = lay.X_WM_xyz
    map_W = weldmap.transformed(X_WM, "W")
    joints = find_joints(map_W)
    view = ViewOptions()
    for sid, joint in joints.items():
        target, parts = seam_target(map_W, joint), occluders(map_W, joint)
        for name, (eye, t) in lay.cameras.items():
            cam = lens(name, look_at(eye, t, (0.0, 1.0, 0.0)), (1280, 720), 65.0, 0.1, 4.0, 72.0, 80.0)
            c = camera_sight(cam, target, parts, 0.9, view)
            assert c.blind[0] is Blind.GRAZING and c.incidence_deg[0] == pytest.approx(90.0, abs=1.0), (sid, name)
            assert c.sees(1)  # the plate's top is in full view


def test_why_a_camera_misses_a_face(tmp_path: Path) -> None:
    """Each test of the view apart: edge-on, behind another part, out of the image, out of range."""
    weldmap = read_map(web_on_plate(tmp_path / "w.dxf", "x", wall=True))
    joints = find_joints(weldmap)
    view = ViewOptions()

    def at(
        sid: str, eye: tuple[float, float, float], look: np.ndarray | None = None, far: float = 4.0
    ) -> tuple[Blind | None, ...]:
        joint = joints[sid]
        target, parts = seam_target(weldmap, joint), occluders(weldmap, joint)
        assert [p.name for p in parts] == ["WALL"]
        aim = target.mid if look is None else look
        cam = lens("c", look_at(eye, aim, (0.0, 1.0, 0.0)), (1280, 720), 65.0, 0.1, far, 72.0, 80.0)
        return camera_sight(cam, target, parts, 0.0, view).blind

    mid = seam_target(weldmap, joints["WEB>PLATE:+y"]).mid
    beyond_wall = (mid[0], mid[1] + 0.6, mid[2] + 0.5)  # the web's +y face behind the wall
    over = (mid[0], mid[1] + 0.03, mid[2] + 1.0)  # straight above the fillet: the web's side edge-on
    assert at("WEB>PLATE:+y", beyond_wall)[0] is Blind.OCCLUDED
    assert at("WEB>PLATE:+y", over)[0] is Blind.GRAZING and at("WEB>PLATE:+y", over)[1] is None
    assert at("WEB>PLATE:+y", over, look=mid + np.array([2.0, 0.0, 0.0]))[0] is Blind.OUT_OF_VIEW
    front = (mid[0], mid[1] - 0.6, mid[2] + 0.5)  # the other fillet from its own side, the wall behind the web
    assert at("WEB>PLATE:-y", front) == (None, None)
    assert at("WEB>PLATE:-y", front, far=0.5) == (Blind.OUT_OF_RANGE, Blind.OUT_OF_RANGE)


def test_the_layout_by_faces_keeps_fence2s_shipped_cell() -> None:
    """fence2's pair of fixed cameras sees every face some place about it could: kept as shipped, the scan pose too."""
    from functools import partial

    from cell.cli.sight_lines import arm_torch
    from cell.rescan.sight import pose_sight

    sight = partial(pose_sight, torch_C=arm_torch("kr5_arc.urdf", ViewOptions()))
    lay = layout(read_map(REPO / "maps" / "fence2.dxf"), sight)
    shipped = sc.load("fence2")
    assert sorted(lay.cameras) == ["cam_left", "cam_right"] and lay.closeup_only == ()
    for name, (eye, target) in lay.cameras.items():
        np.testing.assert_allclose(eye, shipped.cameras[name].eye_m, atol=1e-9)
        np.testing.assert_allclose(target, shipped.cameras[name].target_m, atol=1e-9)
    np.testing.assert_allclose(lay.eye_in_hand[1], shipped.cameras["eye_in_hand"].target_m, atol=1e-9)


def test_scenario_check_warns_for_a_seam_no_camera_sees(tmp_path: Path) -> None:
    """The web along x with its far camera moved into the web's plane: its +y fillet is seen by no camera of the
    first scan; the check warns in one line with a place that would see it and what the close-up would do, and
    still exits 0."""
    dxf = web_on_plate(tmp_path / "web_x.dxf", "x")
    out = tmp_path / "web_x.yaml"
    assert runner.invoke(app, ["init", str(dxf), "--out", str(out)]).exit_code == 0
    scn = sc.load(out)
    far = next(n for n in scn.cameras if n.startswith("cam_far"))
    eye = scn.cameras[far].eye_m
    text = out.read_text().replace(f"eye_m: [{eye[0]}, {eye[1]}, {eye[2]}]", f"eye_m: [1.0, 0.0, {eye[2]}]")
    assert text != out.read_text()
    moved = tmp_path / "moved.yaml"
    moved.write_text(text)
    result = runner.invoke(app, ["scenario", "check", str(moved)])
    assert result.exit_code == 0, result.stderr
    assert result.stdout.startswith("1 warning(s):")
    warnings = [ln for ln in result.stderr.splitlines() if ln.startswith("warning: seam ")]
    assert len(warnings) == 1, result.stderr
    w = warnings[0]
    assert w.startswith("warning: seam WEB>PLATE:+y: no camera of the first scan sees face WEB +y;")
    assert "a fixed camera at [0.15, 0.8" in w and "would see both faces" in w  # on the far side, as init put it
    assert "the close-up will: a view from 0.3" in w or "the close-up will: a view from 0.4" in w
    assert "WEB>PLATE:+y: face WEB +y by no camera (edge-on to " in result.stdout
    assert "WEB>PLATE:-y: both faces seen by" in result.stdout
