"""``cell rescan`` on a round part: the seen post's doubtful fillet is re-scanned up close on ``cell weld``'s curve
loop, brought within the tolerance, and reported before and after in the JSON and on the console; a curve already
within it, asked for by id, is looked at once along its whole length."""

from __future__ import annotations

import json
from pathlib import Path

from round_post import SEAM, seen_yaml
from typer.testing import CliRunner

from cell import scenario as scn
from cell.cli import app
from cell.pipeline.curved.rescan_all import rescan_all
from cell.pipeline.detect import detect, read_weldmap
from cell.pipeline.geometry import open_cell


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


def test_a_curve_within_the_tolerance_asked_for_by_id_is_looked_at_once(tmp_path: Path) -> None:
    sc = scn.load(seen_yaml(tmp_path, "round-post-within", 0.6, eye_in_hand=True))  # 0.2 mm allowed: within
    wm = read_weldmap(sc)
    with open_cell(sc, wm) as station:
        det = detect(sc, station=station, weldmap=wm)
        [before] = det.curve_estimates
        assert before.sigma_max_m < sc.rescan.max_sigma_m  # mode low leaves it (tests/unit/test_curve_rescan_choice.py)
        rs, after = rescan_all(station, det, "low", seam_ids=[SEAM])
    assert not rs.seams  # no straight seam asked for
    [r] = rs.curves
    assert r.chosen and len(r.views) == 1 and r.weight > 0.9
    assert r.after.sigma_max_m < 0.5 * before.sigma_max_m
    assert after.curve_estimates == (r.after,) and after.curve_metrics[SEAM].within_2sigma == 1.0
