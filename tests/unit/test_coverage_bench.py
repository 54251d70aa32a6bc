"""The coverage benchmark (benchmarks/bench_coverage.py) counts what its table says, and the committed results hold
the calibration the sigma models cite (cell/seams/sigma.py): about 95 % of the scenarios' seams within 2 sigma."""

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
    return load_bench("bench_coverage")


def _row(method: str, group: str, sigma_mm: float, lateral_mm: float, endpoint_mm: float) -> dict[str, Any]:
    return {
        "group": group,
        "method": method,
        "sigma_mm": sigma_mm,
        "lateral_mm": lateral_mm,
        "endpoint_mm": endpoint_mm,
        "confidence": 1.0,
        "reason": "",
    }


def test_coverage_counts_errors_within_two_and_three_sigma(bench: ModuleType) -> None:
    rows = [
        _row("ours", "scenarios", 0.1, 0.05, 0.05),  # within 2 sigma
        _row("ours", "scenarios", 0.1, 0.25, 0.15),  # within 3, not 2 (lateral); endpoint within 2
        _row("ours", "scenarios", 0.1, 0.40, 0.40),  # outside both
        _row("ours", "faults", 0.1, 0.01, 0.01),
    ]
    table = {(r["method"], r["group"]): r for r in bench.coverage(rows)}
    s = table["ours", "scenarios"]
    assert (
        s["found"] == 3 and s["lateral_2sigma"] == pytest.approx(1 / 3) and s["lateral_3sigma"] == pytest.approx(2 / 3)
    )
    assert s["endpoint_2sigma"] == pytest.approx(2 / 3) and s["lateral_max_mm"] == 0.40
    assert table["ours", "all"]["found"] == 4 and table["ours", "all"]["lateral_2sigma"] == pytest.approx(0.5)
    assert [r["group"] for r in bench.coverage(rows)] == ["scenarios", "faults", "all"]


def test_the_committed_calibration_covers_about_95_percent_on_the_scenarios() -> None:
    data = json.loads((REPO / "benchmarks" / "results" / "coverage.json").read_text(encoding="utf-8"))
    scenarios = {r["method"]: r for r in data["coverage"] if r["group"] == "scenarios"}
    assert set(scenarios) == {"ours", "paper", "ransac"}
    for method, r in scenarios.items():
        assert r["lateral_2sigma"] >= 0.90, method  # measured 95-99 %
        # Not inflated either: twice the median sigma is about the 95th percentile of the error (the paper's 1.80
        # against 1.77 mm, RANSAC's 3.2 against 3.14); a sigma that adapts to its seam covers more than 95 %.
        lateral = sorted(x["lateral_mm"] for x in data["rows"] if x["method"] == method and x["group"] == "scenarios")
        p95 = lateral[int(0.95 * len(lateral))]
        # Ours is calibrated on random cells nobody tuned it for (docs/trust.md section 4), where its errors are
        # wider: on the scenarios it was developed on it is pessimistic, twice its median sigma 2.3 times the 95th
        # percentile (0.326 against 0.143 mm), and must not grow further.
        wide = 2.5 if method == "ours" else 1.5
        assert 0.67 * p95 <= 2.0 * r["sigma_median_mm"] <= wide * p95, method
    # Ours' standard error, widened by SE_INFLATION (calibrated on random cells), covers the scenarios alone
    # (measured 100 %; unwidened it was 88 %): the floor stands for what the fit cannot see.
    assert data["calibration"]["scenarios"]["ours_se_alone_lateral_2sigma"] >= 0.95
