"""The scaling table of docs/results.md (tools/readme_results.py) shows perceive + align + locate against capture
and planning per seam from ``scaling.json``'s rows, and dashes where a row has none (a scenario without an arm,
rows measured before)."""

from __future__ import annotations

from typing import Any

from tools_loader import load_tool


def _row(name: str, **extra: Any) -> dict[str, Any]:
    method = {"found": 12, "ms_per_seam_median": 1.5, "lateral_mean_mm": 0.071}
    return {
        "scenario": name,
        "seams": 16,
        "visible": 12,
        "points_dense": 653752,
        "points_voxel": 12021,
        "capture_s": 1.6,
        "perceive_s": 1.2,
        "align_s": 0.5,
        "methods": {"ours": method, "paper": method, "ransac": method},
        **extra,
    }


def test_scaling_table_gives_the_ratio_to_capture_and_planning_per_seam() -> None:
    table = load_tool("readme_results").scaling_table(
        [
            _row(
                "fence1",
                detect_vs_capture={"capture_s": 1.6, "perceive_align_locate_s": 1.2},
                planning={"seams_planned": 12, "seams_asked": 12, "cpu_s_per_planned_seam": 0.1704},
            ),
            _row("ladder"),
        ]
    )
    lines = table.splitlines()
    assert "perceive + align + locate / capture" in lines[0] and "planning CPU s / planned seam" in lines[0]
    assert "| 1.60 | 1.20 | 0.50 | 0.75 |" in lines[2] and lines[2].endswith("| 12 / 12 | 0.170 |")
    assert (
        lines[3].startswith("| ladder (26 rungs) |") and "| 0.50 | - |" in lines[3] and lines[3].endswith("| - | - |")
    )
