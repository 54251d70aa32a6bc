"""The command line on the real pipeline: the JSON report contract, and a late failure that still writes it."""

from __future__ import annotations

import json
from pathlib import Path

from typer.testing import CliRunner

from cell.cli import app

runner = CliRunner()


def invoke(*args: str) -> tuple[int, str, str]:
    result = runner.invoke(app, list(args))
    return result.exit_code, result.stdout, result.stderr


def test_detect_writes_the_report_contract(tmp_path: Path) -> None:
    report = tmp_path / "out.json"
    cloud = tmp_path / "cloud.ply"
    code, out, err = invoke("detect", "fence1-exact", "--json", str(report), "--save-cloud", str(cloud))
    assert code in (0, 3), err
    assert "found" in out and "paper ME" in out
    data = json.loads(report.read_text())
    assert data["scenario"] == "fence1-exact"
    assert data["frame"] == "R"
    assert len(data["X_WR"]) == 4 and len(data["X_WR"][0]) == 4
    assert len(data["seams"]) == 16
    ids = [s["id"] for s in data["seams"]]
    assert len(set(ids)) == 16
    for s in data["seams"]:
        assert {"id", "status", "reason", "truth", "time_ms"} <= set(s)
        if s["status"] == "found":
            assert len(s["detected"]["start"]) == 3
            assert set(s["error_mm"]) == {"paper_me", "endpoint", "lateral"}
        else:
            assert "detected" not in s and s["reason"]
    summary = data["summary"]
    for key in ("found", "paper_me_mean_mm", "endpoint_mean_mm", "lateral_mean_mm", "time_ms_per_seam_median"):
        assert key in summary
    assert cloud.stat().st_size > 10_000


def test_alignment_failure_still_writes_every_seam_with_its_reason(tmp_path: Path) -> None:
    report = tmp_path / "out.json"
    code, _, err = invoke("detect", "faults/displaced-far", "--json", str(report))
    assert code == 3, err  # partial: the report is written, the cause is in it
    assert "error:" in err and "Traceback" not in err
    data = json.loads(report.read_text())
    assert data["error"]["type"] == "AlignmentError" and data["error"]["exit_code"] == 14
    assert len(data["seams"]) == 16
    assert all(s["status"] in ("not_found", "not_visible") for s in data["seams"])
    assert all(s["reason"] for s in data["seams"])
    assert not any("detected" in s for s in data["seams"])
