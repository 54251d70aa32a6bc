"""``cell rescan`` on a round part: the seen post's doubtful fillet is re-scanned up close on ``cell weld``'s curve
loop, brought within the tolerance, and reported before and after in the JSON and on the console; on a linear
track, a post beyond reach from E1 = 0 is looked at with the carriage abreast of it, and once within the tolerance,
asked for by id, looked at once more."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from round_post import SEAM, seen_yaml
from typer.testing import CliRunner

from cell import scenario as scn
from cell.cli import app
from cell.pipeline.curved.rescan import preview_curve_closeups
from cell.pipeline.curved.rescan_all import chosen_curves, rescan_all
from cell.pipeline.detect import detect, read_weldmap
from cell.pipeline.geometry import motion_scene, open_cell


def test_cell_rescan_brings_a_doubtful_curve_within_the_tolerance_and_reports_it(tmp_path: Path) -> None:
    # three 160 x 120 cameras state about 0.17 mm; a 0.3 mm tolerance allows 0.1 mm at 3 sigma: a doubtful curve
    path = seen_yaml(tmp_path, "round-post-rescan", 0.3, eye_in_hand=True)
    out = tmp_path / "r.json"
    res = CliRunner().invoke(app, ["rescan", str(path), "--json", str(out)])
    assert res.exit_code == 0, res.output
    rep = json.loads(out.read_text())
    [entry] = [s for s in rep["seams"] if s.get("curved")]
    r, curve = entry["rescan"], entry["curve"]
    assert entry["id"] == SEAM and entry["status"] == "found"
    assert r["chosen"] and r["views"] == 1 and r["used"] and r["weight"] > 0.9, r
    assert r["sigma_max_mm_before"] > 0.15 and curve["sigma_max_mm"] < 0.05  # 0.17 -> 0.035 mm measured
    assert r["within_tolerance"] and r["reason"] == ""
    assert curve["closed"] and r["end_sigma_mm_before"] is None  # a full circle: no ends
    assert 0.2 < r["distance_mm"][0] / 1000.0 < 0.5 and r["motion_s"] > 0.0
    # against the true curve (simulation): within its 2 sigma before and after, no worse for the close-up
    assert entry["error_mm_before"]["within_2sigma"] == 1.0 and entry["error_mm"]["within_2sigma"] == 1.0
    assert entry["error_mm"]["max"] < 0.06 and entry["error_mm"]["rms"] <= entry["error_mm_before"]["rms"]
    assert entry["reason"].startswith("re-scanned up close (1 close-ups")
    assert rep["rescan"]["curves"] == {"seams": 1, "used": 1, "within_tolerance": 1}
    assert rep["rescan"]["motion_s"] > r["motion_s"] and rep["rescan"]["returned_to_scan_pose"]  # the way back too
    assert f"curve {SEAM}: sigma max 0.1" in res.output and "(within the tolerance); 1 close-ups" in res.output
    assert "1 curves re-scanned, 1 now within the tolerance" in res.output


FAR_POST = """
name: far-post
seed: 33
simulation: {noise: none}
map: {file: ../maps/post_plate.dxf, X_WM: {xyz_m: [1.0, 0.25, 0.90]}}
table: {center_m: [0.0, 0.0, 0.85], size_m: [3.0, 1.2, 0.10]}
robot:
  urdf: kr5_arc.urdf
  X_WR: {xyz_m: [-1.0, -0.75, 0.90]}
  home_deg: [-90.0, -100.0, 100.0, 0.0, 45.0, 0.0]
  track: {axis_W: [1.0, 0.0, 0.0], min_mm: -200.0, max_mm: 2400.0, speed_mm_s: 1000.0, accel_mm_s2: 1500.0,
          jerk_mm_s3: 6000.0}
cameras:
  front: {eye_m: [1.0, -0.2, 1.35], target_m: [1.0, 0.25, 0.93], resolution: [160, 120]}
  back_l: {eye_m: [0.6, 0.5, 1.35], target_m: [1.0, 0.25, 0.93], resolution: [160, 120]}
  back_r: {eye_m: [1.4, 0.5, 1.35], target_m: [1.0, 0.25, 0.93], resolution: [160, 120]}
  eye_in_hand: {mount: eye_in_hand, eye_m: [-0.45, -0.2, 1.8], target_m: [0.0, 0.25, 0.93], resolution: [320, 240]}
perception:
  workspace: {min_m: [0.85, 0.10, 0.905], max_m: [1.15, 0.40, 1.05]}
rescan: {weld_tolerance_mm: 0.3}
"""  # track-post's post 2 m along the track (1 m further): beyond the arm's reach from E1 = 0


def test_on_a_track_the_close_up_is_taken_with_the_carriage_abreast_of_the_curve() -> None:
    """... and ``cell preview`` plans that view, carriage and all."""
    sc = scn.from_yaml(FAR_POST)
    wm = read_weldmap(sc)
    with open_cell(sc, wm) as station:
        det = detect(sc, station=station, weldmap=wm)
        assert station.arm is not None
        motion = motion_scene(station.arm, det)
        [planned] = preview_curve_closeups(station, det, motion)
        rs, after = rescan_all(station, det, "low", motion=motion)
        # within the tolerance now: mode low leaves it; asked for by id it is looked at once more, whole
        assert chosen_curves(after, "low")[0] == []
        again, _ = rescan_all(station, after, "low", seam_ids=[SEAM], motion=motion)
    [r] = rs.curves
    assert r.chosen and len(r.views) == 1 and r.after.sigma_max_m <= sc.rescan.max_sigma_m, r.reason
    assert 1.9 < r.views[0].e1_m < 2.1  # abreast of the post, 10 mm grid
    assert planned.viewpoint is not None and planned.viewpoint.e1_m == r.views[0].e1_m
    np.testing.assert_allclose(planned.viewpoint.q, r.views[0].q, atol=1e-9)
    carriage = [m.e1 for m in rs.moves if m.e1 is not None]
    assert [round(float(e[-1]), 3) for e in carriage] == [round(r.views[0].e1_m, 3), 0.0]  # out, and back to 0
    assert rs.returned and rs.note == ""
    assert r.motion_s > 2.0  # the carriage's 2 m is its own (0.9 s of it the view's move, measured)
    [r2] = again.curves
    assert r2.chosen and r2.before.sigma_max_m == r.after.sigma_max_m and len(r2.views) == 1
    assert 1.9 < r2.views[0].e1_m < 2.1  # abreast of its worst stretch, the whole curve's this time
    assert r2.after.sigma_max_m <= r.after.sigma_max_m + 1e-6 and not again.seams and again.returned
