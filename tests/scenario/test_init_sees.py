"""A plate with a web standing on it, along x and along y: ``cell init`` lays out fixed cameras that see both fillets,
and ``cell detect`` finds both; with the cameras in the web's plane (the layout before it looked at the faces) the
fixed cameras find neither, and ``cell preview`` plans the very close-up views ``cell weld`` then takes."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from dxf_factory import web_on_plate
from typer.testing import CliRunner

from cell import pipeline
from cell import scenario as sc
from cell.cli import app
from cell.export.reports.report import weld_report
from cell.pipeline.job import WeldJob
from cell.scenario.init import scenario_text

runner = CliRunner()


@pytest.mark.parametrize("along", ["x", "y"])
def test_init_then_detect_finds_both_fillets(tmp_path: Path, along: str) -> None:
    dxf = web_on_plate(tmp_path / f"web_{along}.dxf", along)
    scenario, report = tmp_path / f"web_{along}.yaml", tmp_path / "r.json"
    assert runner.invoke(app, ["init", str(dxf), "--out", str(scenario)]).exit_code == 0
    result = runner.invoke(app, ["detect", str(scenario), "--json", str(report)])
    assert result.exit_code == 0, result.stderr
    seams = json.loads(report.read_text())["seams"]
    assert len(seams) == 2
    for s in seams:  # measured 0.06-0.95 mm (seed 1, realistic noise)
        assert s["status"] == "found" and s["error_mm"]["paper_me"] <= 1.5, s


def test_preview_plans_the_closeups_weld_takes(tmp_path: Path) -> None:
    """The fixed cameras in the web's mid-plane find neither fillet; the preview plans a close-up of each and the
    weld takes exactly those views (the same planner from the same start), and finds both there."""
    dxf = web_on_plate(tmp_path / "web_x.dxf", "x")
    path = tmp_path / "old.yaml"
    text, _ = scenario_text(dxf, path)  # no sight: the pair either side along x
    path.write_text(text)
    scn = sc.load(path)
    preview = pipeline.weld(scn, WeldJob(execute=False))
    assert all(e.status.value == "not_found" for e in preview.detection.estimates)
    planned = {c.seam_id: c for c in preview.closeups}
    assert sorted(planned) == ["WEB>PLATE:+y", "WEB>PLATE:-y"]
    rep = {s["id"]: s for s in weld_report(preview)["seams"]}
    for sid, c in planned.items():
        assert c.viewpoint is not None and c.planned, c.reason
        assert rep[sid]["closeup_plan"]["planned"] and rep[sid]["closeup_plan"]["distance_mm"] == pytest.approx(
            360, abs=90
        )
        assert "cell weld would re-scan it up close from" in rep[sid]["weld_reason"]
    weld = pipeline.weld(scn, WeldJob())
    assert weld.rescan is not None
    taken = {r.id: r for r in weld.rescan.seams}
    for sid, c in planned.items():
        vp = taken[sid].viewpoint
        assert vp is not None and c.viewpoint is not None
        np.testing.assert_allclose(vp.X_RC, c.viewpoint.X_RC, atol=1e-6)
        assert taken[sid].fused.status.value == "found"
