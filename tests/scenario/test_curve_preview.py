"""``cell preview``'s close-ups of a doubtful curve: the first view ``cell weld`` would take of it, planned from the
same detection without moving the arm, is the view the weld's re-scan then takes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from round_post import SEAM, seen_scenario

from cell.pipeline.curved.rescan import doubtful_curves, preview_curve_closeups, rescan_curves
from cell.pipeline.detect import detect, read_weldmap
from cell.pipeline.geometry import motion_scene, open_cell


def test_the_preview_plans_the_first_close_up_the_weld_takes_of_a_doubtful_curve(tmp_path: Path) -> None:
    sc = seen_scenario(tmp_path, "round-post-preview", 0.3, eye_in_hand=True)  # 0.18 mm sigma: a doubtful curve
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
