"""``cell preview``'s close-ups of a doubtful curve: the first view ``cell weld`` would take of it, planned from the
same detection without moving the arm, is the view the weld's re-scan then takes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from round_post import SEAM, post_map

from cell import scenario as scn
from cell.pipeline.curved.rescan import doubtful_curves, preview_curve_closeups, rescan_curves
from cell.pipeline.detect import detect, read_weldmap
from cell.pipeline.geometry import motion_scene, open_cell

SCENARIO = """
name: round-post-preview
seed: 7
simulation: {noise: none}
map: {file: post.dxf, X_WM: {xyz_m: [0.0, 0.0, 0.90]}}
table: {center_m: [0.0, 0.0, 0.85], size_m: [1.6, 1.2, 0.10]}
robot:
  urdf: kr5_arc.urdf
  X_WR: {xyz_m: [0.0, -0.75, 0.90]}
  home_deg: [-90.0, -100.0, 100.0, 0.0, 45.0, 0.0]
cameras:
  front: {eye_m: [0.0, -0.45, 1.35], target_m: [0.0, 0.0, 0.93], resolution: [160, 120]}
  back_l: {eye_m: [-0.4, 0.25, 1.35], target_m: [0.0, 0.0, 0.93], resolution: [160, 120]}
  back_r: {eye_m: [0.4, 0.25, 1.35], target_m: [0.0, 0.0, 0.93], resolution: [160, 120]}
  eye_in_hand: {mount: eye_in_hand, eye_m: [0.0, -0.3, 1.5], target_m: [0.0, 0.0, 0.93], resolution: [320, 240]}
perception:
  workspace: {min_m: [-0.5, -0.5, 0.905], max_m: [0.5, 0.5, 1.3]}
rescan: {weld_tolerance_mm: 0.3}  # three 160 x 120 cameras state about 0.18 mm: a doubtful curve
"""


def test_the_preview_plans_the_first_close_up_the_weld_takes_of_a_doubtful_curve(tmp_path: Path) -> None:
    post_map(tmp_path / "post.dxf")
    sc = scn.from_yaml(SCENARIO, base_dir=tmp_path)
    wm = read_weldmap(sc)
    with open_cell(sc, wm) as station:
        det = detect(sc, station=station, weldmap=wm)
        assert [c.id for c in doubtful_curves(det)] == [SEAM]
        assert station.arm is not None
        motion = motion_scene(station.arm, det)
        [planned] = preview_curve_closeups(station, det, motion)
        assert planned.seam_id == SEAM and planned.viewpoint is not None, planned.reason
        rs, _ = rescan_curves(station, det, motion=motion)
    assert rs is not None and rs.moves
    np.testing.assert_allclose(rs.moves[0].q[-1], planned.viewpoint.q, atol=1e-9)  # the weld's first close-up
