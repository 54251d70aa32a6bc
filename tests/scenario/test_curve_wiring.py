"""cell weld with a located curved seam: a post's fillet found by the locator is handed to the planner, welded
(in one go or in arcs) and measured against its true curve, and the report, the summary and the exit say so like
a straight seam's; nothing about it is dropped."""

from __future__ import annotations

from pathlib import Path

import pytest
from round_post import SEAM, seen_scenario

from cell.export.reports.report import weld_report
from cell.pipeline.job import WeldJob
from cell.pipeline.weld import weld


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> dict:
    folder: Path = tmp_path_factory.mktemp("post_seen")
    # three 160 x 120 cameras state 0.18 mm (3 sigma 0.54 mm): a 0.6 mm tolerance lets the planner try it; the arm
    # stands 2.2 m from the post, beyond its reach bound (2.01 m from A1 to the torch's tip), so the planner's
    # refusal costs no search (the search's own refusals are tests/unit/test_curve_reach.py's); --rescan all asks
    # its camera for a close-up of the curve the gate would pass
    sc = seen_scenario(folder, "round-post-far", 0.6, robot_y_m=-2.2, eye_in_hand=True)
    run = weld(sc, WeldJob(rescan="all", sides="first"))
    return {"run": run, "rep": weld_report(run)}


def test_a_located_curve_the_arm_cannot_reach_is_reported_with_the_planners_code(report: dict) -> None:
    """The post's fillet is located and handed to the planner, which refuses it (no torch setting holds any of
    it); it is not welded, for the planner's reason, counted in the summary, the report and the programs' header,
    the run partial: nothing about a curve the arm cannot weld is dropped."""
    from cell.cli.turnover import not_welded

    run, rep = report["run"], report["rep"]
    det = run.detection
    est = next(e for e in det.curve_estimates if e.id == SEAM)
    assert est.status.value == "found", est.reason
    entry = next(s for s in rep["seams"] if s["id"] == SEAM)
    w = det.curve_welds[SEAM]
    assert not w.welded and not w.planned and not entry["welded"] and "tcp_error_mm" not in entry
    why, code = entry["weld_reason"], entry["weld_reason_code"]
    assert code == "not_planned" and entry["plan_reason_code"] == "ik_failed", (code, why)
    assert "no torch setting holds it" in why and "the arm reaches 0% of it" in why, why
    assert entry["not_welded"]["code"] == "ik_failed"
    assert (SEAM, "not_planned: ik_failed") in not_welded(rep)  # the programs' header
    assert rep["summary"]["curved"] | {"rms_max_mm": 0, "max_mm": 0} == {
        "seams": 1, "found": 1, "welded": 0, "partial": 0, "manual_mm": 0.0, "not_welded": {"ik_failed": 1},
        "rms_max_mm": 0, "max_mm": 0,
    }  # fmt: skip
    assert SEAM in {u.id for u in det.not_welded}
    assert not run.complete and rep["welded"] == 0


def test_rescan_all_looks_again_at_a_curve_within_the_tolerance_and_says_why_it_could_not(report: dict) -> None:
    """``cell weld --rescan all`` chooses every located curve for a close-up, as ``cell rescan --all`` does, not only
    those over the tolerance (this one's 3-sigma bound, 0.54 mm, is within its 0.6 mm); the arm's camera cannot come
    near it, and the re-scan's record says so rather than nothing."""
    run = report["run"]
    est = next(e for e in run.detection.curve_estimates if e.id == SEAM)
    assert est.sigma_max_m <= run.detection.scenario.rescan.max_sigma_m  # the gate would pass it
    assert run.rescan is not None
    (rec,) = [r for r in run.rescan.curves if r.id == SEAM]
    assert rec.chosen and not rec.views
    assert rec.reason.startswith("no view") and "unreachable" in rec.reason, rec.reason
