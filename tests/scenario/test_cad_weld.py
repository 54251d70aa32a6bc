"""A part's CAD to welded seams through the command line: ``cell init PART.step`` (the map made from the STEP
beside the scenario, seams proposed from contacts) then ``cell weld`` on the benchmark part's situation
(tests/cad_parts.py: plate, web, tube, bolt with washer and nut), the real pipeline headless."""

from __future__ import annotations

import json
from typing import Any

import pytest
from cad_parts import TRUE_LINES, write_step
from typer.testing import CliRunner

from cell.cli import app


@pytest.fixture(scope="module")
def welded(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    folder = tmp_path_factory.mktemp("cad_weld")
    step = write_step(folder / "bench.step")
    runner = CliRunner()
    scenario, report = folder / "bench.yaml", folder / "r.json"
    result = runner.invoke(app, ["init", str(step), "--out", str(scenario)])
    assert result.exit_code == 0, result.stderr
    assert (folder / "bench.dxf").is_file() and (folder / "bench.png").is_file()
    result = runner.invoke(app, ["weld", str(scenario), "--sides", "first", "--json", str(report)])
    assert result.exit_code in (0, 3), result.stderr
    data: dict[str, Any] = json.loads(report.read_text())
    return data


def test_every_straight_seam_is_located_within_fences_bars(welded: dict[str, Any]) -> None:
    assert welded["error"] is None
    by_id = {s["id"]: s for s in welded["seams"]}
    assert set(TRUE_LINES) <= set(by_id)
    for sid in TRUE_LINES:
        s = by_id[sid]
        assert s["status"] == "found", s
        assert s["error_mm"]["lateral"] <= 0.2, s  # measured 0.01-0.03 mm (fence1's ours: 0.09 mm mean)
        if s["welded"]:
            assert s["tcp_error_mm"]["rms"] <= 0.2, s  # measured 0.01 mm
    assert any(by_id[sid]["welded"] for sid in TRUE_LINES)  # the fillet away from the tube (the other: below)


@pytest.mark.xfail(
    strict=True,
    reason="one web fillet's far end, beside the tube, is read up close from where the web's points stop, and the tube "
    "thins them unevenly: 0.7 mm off at an end sigma of 1.8 mm, refused (end_uncertain); the other fillet is welded",
)
def test_every_straight_seam_is_welded(welded: dict[str, Any]) -> None:
    by_id = {s["id"]: s for s in welded["seams"]}
    assert all(by_id[sid]["welded"] for sid in TRUE_LINES), {sid: by_id[sid]["weld_reason"] for sid in TRUE_LINES}
