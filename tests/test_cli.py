"""The command line: results on stdout, one-line errors with documented exit codes, the JSON report contract."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from dxf_factory import design, make_maps
from typer.testing import CliRunner

from cell.cli import app
from cell.scenario import SCENARIO_DIR

runner = CliRunner()
REPO = Path(__file__).resolve().parent.parent


def invoke(*args: str) -> tuple[int, str, str]:
    result = runner.invoke(app, list(args))
    return result.exit_code, result.stdout, result.stderr


def assert_one_line_error(code: int, stderr: str, expected_code: int, *needles: str) -> None:
    assert code == expected_code, stderr
    lines = [ln for ln in stderr.strip().splitlines() if ln.startswith("error:")]
    assert len(lines) == 1, stderr
    assert "Traceback" not in stderr
    for n in needles:
        assert n in lines[0], lines[0]


def test_help_and_scenarios() -> None:
    code, out, _ = invoke("--help")
    assert code == 0 and "detect" in out
    code, out, _ = invoke("scenarios")
    assert code == 0
    for name in ("fence1-exact", "fence1", "fence2"):
        assert name in out


def test_map_info_lists_units_parts_and_seams() -> None:
    code, out, _ = invoke("map", "info", str(REPO / "maps" / "fence1.dxf"))
    assert code == 0
    assert "mm" in out
    for part in ("TOP_RAIL", "POST_L", "POST_R", "BOTTOM_RAIL"):
        assert part in out
    assert out.count("POST_L>TOP_RAIL:") == 4


@pytest.mark.parametrize(
    ("content", "needle"),
    [
        (b"\x00\x01\x02 not a drawing \xff" * 50, "DXF"),
        (b"hello, I am a text file\n", "DXF"),
    ],
)
def test_bad_dxf_gives_exit_11(tmp_path: Path, content: bytes, needle: str) -> None:
    bad = tmp_path / "bad.dxf"
    bad.write_bytes(content)
    code, _, err = invoke("map", "info", str(bad))
    assert_one_line_error(code, err, 11, needle)


def test_truncated_dxf_gives_exit_11(tmp_path: Path) -> None:
    good = (REPO / "maps" / "fence1.dxf").read_bytes()
    bad = tmp_path / "truncated.dxf"
    bad.write_bytes(good[: len(good) // 2])
    code, _, err = invoke("map", "info", str(bad))
    assert_one_line_error(code, err, 11, "truncated.dxf")


def test_unitless_dxf_gives_exit_12_and_names_the_fix(tmp_path: Path) -> None:
    parts, seams = design("fence1")
    path = make_maps.write_map(tmp_path / "nounits.dxf", parts, seams, units=None)
    code, _, err = invoke("map", "info", str(path))
    assert_one_line_error(code, err, 12, "map.units")
    code, out, _ = invoke("map", "info", str(path), "--units", "mm")
    assert code == 0 and "POST_L" in out


def test_scenario_with_a_typo_gives_exit_10(tmp_path: Path) -> None:
    text = (SCENARIO_DIR / "fence1.yaml").read_text().replace("seed:", "sede:")
    path = tmp_path / "typo.yaml"
    path.write_text(text.replace("../maps/", str(REPO / "maps") + "/"))
    code, _, err = invoke("detect", str(path))
    assert_one_line_error(code, err, 10, "sede", "seed")


def test_unknown_scenario_and_method(tmp_path: Path) -> None:
    code, _, err = invoke("detect", "fence99")
    assert_one_line_error(code, err, 10, "fence1")
    code, _, err = invoke("detect", "fence1", "--method", "magic")
    assert code == 2 and "paper" in err


@pytest.mark.scenario
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


@pytest.mark.scenario
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
