"""The ends' benchmark (benchmarks/bench_ends.py) counts what its table says, and the committed results hold the
calibration the end sigmas cite (cell/seams/sigma.py): about 95 % of ours' located ends within 2 end sigmas."""

from __future__ import annotations

import json
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from tools_loader import load_bench

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def bench() -> ModuleType:
    return load_bench("bench_ends")


def _row(seam: str, along: tuple[float, float], sigma: tuple[float, float], **kw: Any) -> dict[str, Any]:
    return {
        "group": "scenarios",
        "scenario": "s",
        "method": "ours",
        "seam": seam,
        "sigma_mm": 0.1,
        "lateral_mm": 0.1,
        "end_along_mm": list(along),
        "end_sigma_mm": list(sigma),
        "end_source": ["edge", "drawn"],
        "p_start_mm": [0.0, 0.0, 0.0],
        "p_end_mm": [100.0, 0.0, 0.0],
        **kw,
    }


def test_coverage_counts_ends_within_their_sigmas(bench: ModuleType) -> None:
    rows = [_row("a", (0.1, -0.3), (0.1, 0.1)), _row("b", (0.25, 5.0), (0.1, 6.0), lateral_mm=0.3)]
    table = {r["group"]: r for r in bench.coverage(rows)}
    s = table["scenarios"]
    assert s["ends_1sigma"] == pytest.approx(0.5)  # 0.1 and 5 of 6
    assert s["ends_2sigma"] == pytest.approx(0.5)  # 0.3 > 0.2 and 0.25 > 0.2 miss
    assert s["ends_3sigma"] == pytest.approx(1.0)
    assert s["across_2sigma"] == pytest.approx(0.5)
    assert s["end_error_max_mm"] == pytest.approx(5.0) and s["end_error_max_sigmas"] == pytest.approx(3.0)
    sources = {r["source"]: r for r in bench.by_source(rows)}
    assert sources["edge"]["ends"] == 2 and sources["drawn"]["within_2sigma"] == pytest.approx(0.5)


def test_compare_measures_moves_across_and_along(bench: ModuleType) -> None:
    old = [_row("a", (0.0, 0.0), (0.1, 0.1))]
    new = [_row("a", (0.0, 0.0), (0.1, 0.1), p_start_mm=[-2.0, 0.0, 0.0], p_end_mm=[100.0, 0.3, 0.0])]
    moved = bench.compare(new, old)
    assert moved["seams_in_both"] == 1
    assert moved["across_max_mm"] == pytest.approx(0.3) and moved["ends_moved_max_mm"] == pytest.approx(2.0)


def test_committed_results_cover_ours_ends_at_two_sigma() -> None:
    data = json.loads((REPO / "benchmarks" / "results" / "ends.json").read_text())
    rows = {(r["method"], r["group"]): r for r in data["coverage"]}
    assert rows[("ours", "scenarios")]["ends_2sigma"] >= 0.95
    assert rows[("ours", "faults")]["ends_2sigma"] >= 0.95
