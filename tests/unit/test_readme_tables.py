"""The result tables of the cell's commands (tools/readme_cell_tables.py, in docs/results.md) say what their rows
say: the sentence templates of the fault table, the time format, why a seam was not welded; and a changed result
file makes the check of docs/results.md fail until the tables are rendered again."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from tools_loader import load_tool

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def tables() -> ModuleType:
    return load_tool("readme_cell_tables")


def _fault(**over: Any) -> dict[str, Any]:
    row: dict[str, Any] = {
        "scenario": "faults/x",
        "exit_code": 0,
        "visible": 12,
        "found": 12,
        "welded": 12,
        "status_counts": {"found": 12, "not_visible": 4},
        "weld_reason_counts": {"not_visible": 4},
        "tcp_max_mm": 0.2034,
        "rescan": {"seams": 0, "used": 0, "motion_s": 0.0, "escalated_mm": 0.0},
        "lost_cameras": [],
        "not_found_reasons": [],
        "occluded_reasons": [],
        "error": None,
    }
    return {**row, **over}


def test_a_clean_run_welds_every_seam(tables: ModuleType) -> None:
    assert tables.fault_sentence(_fault()) == "welds every visible seam"


def test_a_lost_camera_is_named_with_its_reason_and_the_rescan_counted(tables: ModuleType) -> None:
    row = _fault(
        lost_cameras=["cam_left: no usable image: 0 valid pixels"],
        rescan={"seams": 3, "used": 2, "motion_s": 6.9, "escalated_mm": 0.0},
    )
    assert tables.fault_sentence(row) == (
        'drops cam_left ("no usable image: 0 valid pixels"); re-scans 3 seams up close (2 used)'
    )


def test_an_escalation_says_by_how_much(tables: ModuleType) -> None:
    row = _fault(rescan={"seams": 12, "used": 12, "motion_s": 14.6, "escalated_mm": 1.3209})
    assert tables.fault_sentence(row) == "a close-up disagrees by 1.32 mm: re-scans every seam up close (12 used)"


def test_a_refusal_quotes_the_error_and_leaves_out_the_seams_it_explains(tables: ModuleType) -> None:
    row = _fault(
        exit_code=3,
        found=0,
        welded=0,
        status_counts={"not_found": 12, "not_visible": 4},
        not_found_reasons=["not searched: the fit failed"],
        error={"type": "AlignmentError", "message": "the fit failed"},
    )
    assert tables.fault_sentence(row) == (
        'refuses the alignment ("the fit failed"), every seam `not_found` with that reason'
    )
    line = tables.faults_table([{**row, "tcp_max_mm": None}]).splitlines()[-1]
    assert line.endswith("| 0/12 | - | 3 |")


def test_seams_not_found_quote_their_one_reason(tables: ModuleType) -> None:
    row = _fault(status_counts={"found": 6, "not_found": 8}, not_found_reasons=["part P is not in the cloud"])
    assert tables.fault_sentence(row) == '8 seams `not_found` ("part P is not in the cloud"), never welded'


def test_the_fault_table_keeps_its_order(tables: ModuleType) -> None:
    rows = [_fault(scenario=s) for s in ("faults/zzz-new", "faults/ladder-shifted", "faults/camera-dead")]
    names = [line.split(" | ")[0].removeprefix("| ") for line in tables.faults_table(rows).splitlines()[2:]]
    assert names == ["camera-dead (cam_left)", "ladder-shifted (one rung pitch)", "zzz-new"]


@pytest.mark.parametrize(
    ("us", "text"), [(78.4, "78 us"), (100.0, "100 us"), (500.0, "0.5 ms"), (510.0, "0.51 ms"), (10_412.0, "10.4 ms")]
)
def test_times_as_the_tables_write_them(tables: ModuleType, us: float, text: str) -> None:
    assert tables._time(us) == text


def test_a_seam_not_welded_says_why_by_its_code(tables: ModuleType) -> None:
    seam = {"id": "A>B:-z", "paper_me_mm": None, "lateral_mm": None, "welded": False}
    run = {
        "seams": [
            {**seam, "reason_code": "underside", "weld_reason_code": "not_visible", "weld_reason": "underside: ..."},
            {**seam, "reason_code": None, "weld_reason_code": "not_planned", "weld_reason": "beyond reach"},
        ],
        "cycle_time_s": 10.0,
        "arc_time_s": 5.0,
        "rescan": None,
        "timings_s": {"total_s": 1.0},
    }
    lines = tables.weld_table(run).splitlines()
    assert lines[2] == "| A>B:-z | - | no: against the table (flip) | - | - | - |"
    assert lines[3] == "| A>B:-z | - | no: not planned | - | - | - |"
    assert "no close-up re-scan" in lines[-1]


def test_results_check_fails_on_a_changed_fault_result(tmp_path: Path) -> None:
    readme_results = load_tool("readme_results")
    results = tmp_path / "results"
    shutil.copytree(REPO / "benchmarks" / "results", results)
    rows = json.loads((results / "faults.json").read_text(encoding="utf-8"))
    rows[0]["exit_code"] = 99
    (results / "faults.json").write_text(json.dumps(rows), encoding="utf-8")
    doc, readme = tmp_path / "results.md", tmp_path / "README.md"
    shutil.copy(REPO / "docs" / "results.md", doc)
    shutil.copy(REPO / "README.md", readme)
    args = ["--doc", str(doc), "--readme", str(readme), "--results", str(results)]
    assert readme_results.main(["--check", *args]) == 1
    assert readme_results.main(args) == 0
    assert "| 99 |" in doc.read_text(encoding="utf-8")
    assert readme_results.main(["--check", *args]) == 0


def test_cameras_lost_for_the_same_reason_are_named_together(tables: ModuleType) -> None:
    row = _fault(lost_cameras=["cam_right: dead", "cam_left: dead", "eye: salt"])
    assert tables.fault_sentence(row) == 'drops cam_right and cam_left ("dead"), eye ("salt")'
