"""The trust benchmark (benchmarks/bench_trust.py) counts what its figures say, on small report dicts made here:
each end's error along the seam (a seam reported reversed included), the sigma coverage, null where the report
has no key, the splice corrections with exact extrinsics, the beads off their joint's end, and a rerun that runs
only the cells not yet stored."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

from cell.errors import UsageError

REPO = Path(__file__).resolve().parents[2]


def _load(name: str) -> ModuleType:
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, REPO / "benchmarks" / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def tm() -> ModuleType:
    _load("trust_curves")  # trust_metrics imports it by name, as bench_trust's path set-up lets it
    return _load("trust_metrics")


@pytest.fixture(scope="module")
def bench() -> ModuleType:
    return _load("bench_trust")


TRUTH = {"start": [0.0, 0.0, 0.0], "end": [0.1, 0.0, 0.0]}  # a 100 mm seam along x [m]


def _seam(sid: str = "A>B", **over: Any) -> dict[str, Any]:
    entry: dict[str, Any] = {
        "id": sid,
        "status": "found",
        "reason_code": None,
        "detected": {"start": [-0.003, 0.001, 0.0], "end": [0.095, 0.001, 0.0]},
        "sigma_mm": 0.5,
        "truth": TRUTH,
    }
    return {**entry, **over}


def _report(seams: list[dict[str, Any]], *, exact: bool = True, applied: bool = False, **over: Any) -> dict[str, Any]:
    err = {"translation_mm": 0.0 if exact else 1.0, "rotation_deg": 0.0 if exact else 0.1}
    return {
        "seams": seams,
        "splice": {"cam_a": {"applied": applied, "applied_mm": 4.6 if applied else 0.0}},
        "config": {"cameras": {"cam_a": {"extrinsic_error": err}, "cam_b": {"extrinsic_error": err}}},
        "error": None,
        **over,
    }


def test_each_end_is_measured_along_the_seam_signed_outward(tm: ModuleType) -> None:
    lateral, (start, end), swapped = tm.seam_errors_mm(_seam()["detected"], TRUTH)
    assert not swapped and lateral == pytest.approx(1.0)
    assert start == pytest.approx(3.0)  # 3 mm before the true start: past the joint
    assert end == pytest.approx(-5.0)  # 5 mm short of the true end


def test_a_seam_reported_reversed_is_matched_end_to_end(tm: ModuleType) -> None:
    detected = {"start": [0.102, 0.0, 0.001], "end": [-0.003, 0.0, 0.001]}
    lateral, (start, end), swapped = tm.seam_errors_mm(detected, TRUTH)
    assert swapped and lateral == pytest.approx(1.0)
    assert (start, end) == (pytest.approx(3.0), pytest.approx(2.0))
    # the end sigmas follow the ends they were stated for: [reported start = true end, reported end = true start]
    rec = tm.seam_record(_seam(detected=detected, end_sigma_mm=[0.5, 1.0]), weld_report=False, rescan_known=False)
    assert rec["end_sigma_mm"] == [1.0, 0.5]
    assert rec["z_ends"] == [pytest.approx(3.0), pytest.approx(4.0)]
    assert rec["z_across"] == pytest.approx(2.0)


def test_coverage_counts_errors_within_one_two_and_three_sigma(tm: ModuleType) -> None:
    c = tm.coverage([0.5, 1.5, 2.5, 3.5, None, 1.0])
    assert c == {"n": 5, "1": 0.4, "2": 0.6, "3": 0.8}
    assert tm.coverage([None]) == {"n": 0, "1": None, "2": None, "3": None}


def test_a_key_the_report_lacks_is_null_never_a_guess(tm: ModuleType) -> None:
    rec = tm.cell_record(_report([_seam()]), "detect")
    seam = rec["seams"][0]
    assert seam["end_sigma_mm"] is None and seam["z_ends"] is None and seam["end_mm"] == [3.0, -5.0]
    blk = tm.block([{**rec, "cell": 0, "error": None, "wall_s": 1.0}], "detect")
    assert blk["coverage_2sigma_ends"] is None and blk["coverage_2sigma_across"] == 1.0
    assert blk["rescanned_share"] is None  # a detection re-scans nothing
    # a weld report without the bead's ends: beads_past_end unknown; with them, counted
    welded = _seam(welded=True, tcp_error_mm={"rms": 0.1, "max": 0.3})
    weld = tm.block([{**tm.cell_record(_report([welded]), "weld"), "cell": 0, "error": None}], "weld")
    assert weld["beads_past_end"] is None and weld["worst_welded_tcp_max_mm"] == 0.3
    assert weld["rescanned"] is None  # the report has no re-scan record at all


def test_weld_figures_count_welded_refused_and_beads_off_the_joint_end(tm: ModuleType) -> None:
    ends_ok = {"short_start": 0.9, "short_end": 0.0, "past_start": 0.0, "past_end": 0.2}
    ends_past = {**ends_ok, "past_end": 1.2}
    seams = [
        _seam("a", welded=True, tcp_error_mm={"rms": 0.1, "max": 0.4, **ends_ok}, rescan={"used": True}),
        _seam("b", welded=True, tcp_error_mm={"rms": 0.2, "max": 0.7, **ends_past}),
        _seam("c", welded=False, weld_reason_code="low_confidence", rescan={"used": False}),
        {"id": "d", "status": "not_found", "reason_code": "no_support", "welded": False},
        {"id": "e", "status": "not_visible", "reason_code": "underside", "welded": False},
    ]
    seams[3]["weld_reason_code"] = "not_located"
    rec = tm.cell_record(_report(seams, rescan={"seams": 2}), "weld")
    f = tm.seam_figures(rec["seams"], "weld")
    assert f["seams_visible"] == 4 and f["located"] == 3 and f["located_share"] == 0.75
    assert f["welded"] == 2 and f["welded_share"] == 0.5 and f["worst_welded_tcp_max_mm"] == 0.7
    assert f["beads_past_end"] == 1 and f["rescanned"] == 2 and f["rescanned_share"] == 0.5
    assert f["refused"] == 2 and f["refused_reasons"] == {"low_confidence": 1, "not_located": 1}
    detect = tm.seam_figures(tm.cell_record(_report(seams), "detect")["seams"], "detect")
    assert detect["refused"] == 1 and detect["refused_reasons"] == {"no_support": 1}


def test_splice_corrections_are_counted_apart_for_exact_and_perturbed_cameras(tm: ModuleType) -> None:
    lines = [
        {**tm.cell_record(_report([_seam()], applied=True), "detect"), "cell": 0, "error": None},
        {**tm.cell_record(_report([_seam()], exact=False, applied=True), "detect"), "cell": 1, "error": None},
        {**tm.cell_record(_report([_seam()]), "detect"), "cell": 2, "error": None},
        {**tm.cell_record(_report([_seam()], splice=None), "detect"), "cell": 3, "error": None},
    ]
    blk = tm.block(lines, "detect")
    assert blk["cells_exact"] == 3 and blk["splice_corrections_exact"] == 1
    assert blk["splice_corrections_exact_max_mm"] == 4.6 and blk["splice_corrections_perturbed"] == 1
    assert [r["splice_applied"] for r in blk["rows"]] == [1, 1, 0, None]


def _fake_run_cell(calls: list[int], tm: ModuleType, fail: int | None = None) -> Any:
    def run_cell(job: Any) -> dict[str, Any]:
        calls.append(job.k)
        line = {"run": job.k, "cell": job.k, "cell_seed": job.cell_seed, "scenario": job.scenario, "error": None}
        if job.k == fail and calls.count(job.k) == 1:  # fails the first time only
            return {"line": {**line, "error": {"type": "RuntimeError", "message": "x", "exit_code": 1}}}
        return {"line": {**line, **tm.cell_record(_report([_seam()]), job.stage), "wall_s": 1.0}, "timings": {}}

    return run_cell


def test_a_rerun_runs_only_the_cells_not_yet_stored(
    bench: ModuleType, tm: ModuleType, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    calls: list[int] = []
    monkeypatch.setattr(bench.tc, "run_cell", _fake_run_cell(calls, tm, fail=1))
    out, store = tmp_path / "trust.json", tmp_path / "store"
    common = ["--seed", "3", "--stage", "detect", "--scenarios", "fence1", "--workers", "1"]
    common += ["--store", str(store), "--out", str(out)]
    assert bench.main(["--cells", "2", *common]) == 0 and calls == [0, 1]
    assert bench.main(["--cells", "3", *common]) == 0 and calls == [0, 1, 2]
    data = json.loads(out.read_text(encoding="utf-8"))
    assert data["detect"]["cells"] == 3 and data["detect"]["cells_run_now"] == 1 and "weld" not in data
    assert [r["cell"] for r in data["detect"]["rows"]] == [0, 1, 2] and data["detect"]["cells_failed"] == 1
    assert data["detect"]["rows"][1]["error"] == "RuntimeError" and data["detect"]["seams_visible"] == 2
    assert bench.main(["--cells", "3", *common, "--retry-failed"]) == 0 and calls == [0, 1, 2, 1]
    data = json.loads(out.read_text(encoding="utf-8"))
    assert data["detect"]["cells_failed"] == 0 and data["detect"]["seams_visible"] == 3
    assert bench.main(["--cells", "3", *common]) == 0 and calls == [0, 1, 2, 1]  # the retried line was kept
    assert bench.main(["--cells", "2", *common, "--fresh"]) == 0 and calls == [0, 1, 2, 1, 0, 1]
    # a cell's seed depends on the benchmark's seed and its index only
    assert data["detect"]["rows"][2]["cell_seed"] == bench.tc.cell_seed(3, 2) != bench.tc.cell_seed(3, 1)
    # the same store for other cells is refused (the option named), not mixed
    with pytest.raises(UsageError, match="--store"):
        bench.open_cells(store, bench.store_params("detect", 4, "random", ["fence1"], None), False)


def test_the_readme_table_shows_a_dash_where_the_report_had_no_figure(tm: ModuleType) -> None:
    from tools_loader import load_tool

    blk = tm.block(
        [{**tm.cell_record(_report([_seam()]), "detect"), "cell": 0, "error": None, "wall_s": 2.0}], "detect"
    )
    blk.update(command="bench_trust.py --cells 1 --stage detect", commit="0" * 40, cells_run_now=1, wall_s=2.0)
    blk["workers"] = 1
    text = load_tool("readme_results").trust_table({"detect": blk})
    row = text.splitlines()[2].split(" | ")
    assert row[0] == "| detect" and row[8] == "100%" and row[9] == "-"  # across covered; no end sigma: a dash
    assert "`bench_trust.py --cells 1 --stage detect`" in text and "weld |" not in text


def _curve(sid: str, status: str = "found", **over: Any) -> dict[str, Any]:
    entry: dict[str, Any] = {"id": sid, "curved": True, "status": status, "reason_code": None}
    if status == "found":
        entry["curve"] = {"closed": True, "sigma_max_mm": 0.3}
    return {**entry, **over}


def test_curved_seams_are_counted_apart_from_the_straight_ones(tm: ModuleType) -> None:
    seams = [
        _seam(welded=True, tcp_error_mm={"max": 0.2}),
        _curve("T>P", error_mm={"rms": 0.2, "max": 0.4, "within_2sigma": 1.0}, welded=True, tcp_error_mm={"max": 0.3}),
        _curve("U>P", error_mm={"rms": 0.5, "max": 0.9, "within_2sigma": 0.8}, weld_reason_code="unreachable"),
        _curve("V>P", "not_found", reason_code="no_support"),
    ]
    recs = tm.cell_record(_report(seams), "weld")["seams"]
    f = tm.seam_figures(recs, "weld")
    assert f["seams_visible"] == 1 and f["located"] == 1  # the straight seam alone
    c = f["curved"]
    assert (c["visible"], c["located"], c["welded"]) == (3, 2, 1)
    assert c["max_mm"] == {"n": 2, "median": pytest.approx(0.65), "max": 0.9}
    assert c["samples_within_2sigma"] == pytest.approx(0.9) and c["curves_within_2sigma"] == 0.5
    assert c["worst_welded_tcp_max_mm"] == 0.3
    assert c["refused_reasons"] == {"no_support": 1, "unreachable": 1}
    from tools_loader import load_tool

    line = load_tool("readme_trust_table").curved_line("weld", c)
    assert "2 of 3 visible located" in line and "max 0.90 mm" in line and "welded 1" in line
    assert line.endswith("not welded: no_support 1, unreachable 1")
