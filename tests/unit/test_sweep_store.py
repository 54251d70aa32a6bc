"""cell sweep's folder, summary and task without Ray: resume skips the runs already there and drops a torn line,
a folder of another sweep is refused, a failed run is recorded (and counted apart), and the summary's
probabilities and percentiles follow a hand-made runs.jsonl."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from test_sweep_variations import WELDMAP

from cell import scenario as sc
from cell.errors import UsageError
from cell.sweep import VARY_WORDS, run_task, variation
from cell.sweep.store import RUNS, open_store, sweep_params
from cell.sweep.study import Study, SweepSpec
from cell.sweep.summary import summarize


def _seam(found: bool, lateral: float | None, within: bool, planned: bool = True) -> dict[str, Any]:
    why = ["seen by 0 cameras" if not found else "ends from side face / side face"]
    return {"found": found, "lateral_mm": lateral, "within_tolerance": within, "planned": planned, "reasons": why}


def _result(k: int, seams: dict[str, Any] | None = None, error: dict[str, Any] | None = None) -> dict[str, Any]:
    return {"line": {"run": k, "variation": {"k": k}, "seams": seams or {}, "error": error}, "timings": {"task_s": 1.0}}


@pytest.fixture(scope="module")
def fence1() -> sc.Scenario:
    return sc.load("fence1")


def _params(fence1: sc.Scenario, stage: str = "plan") -> dict[str, Any]:
    return sweep_params(fence1, "map-digest", VARY_WORDS, stage, None, "file-digest")


def test_resume_keeps_whole_runs_and_drops_a_torn_last_line(
    tmp_path: Path, fence1: sc.Scenario, monkeypatch: pytest.MonkeyPatch
) -> None:
    store = open_store(tmp_path, _params(fence1), fresh=False, warn=print)
    for k in (0, 2, 3):
        store.append(_result(k, {"S": _seam(True, 0.2, True)}))
    store.close()
    with (tmp_path / RUNS).open("a") as f:
        f.write('{"run": 4, "seams": {"S": {"fou')  # killed mid-write
    warnings: list[str] = []
    again = open_store(tmp_path, _params(fence1), fresh=False, warn=warnings.append)
    assert sorted(again.lines) == [0, 2, 3]
    assert len(warnings) == 1 and "last line" in warnings[0]
    assert (tmp_path / RUNS).read_text().endswith("}\n") and len((tmp_path / RUNS).read_text().splitlines()) == 3
    # the study sends only the missing runs to the engine
    asked: list[int] = []

    def engine(scenario: Any, todo: Any, stage: Any, on_result: Any, **kw: Any) -> None:
        for v in todo:
            asked.append(v.k)
            on_result(_result(v.k, {"S": _seam(True, 0.3, True)}))

    spec = SweepSpec(fence1, WELDMAP, 5, VARY_WORDS, "plan", None, "map-digest", "file-digest")
    study = Study(spec, tmp_path, count=lambda d, n: None, say=print, warn=print)
    monkeypatch.setattr("cell.sweep.engine.run_sweep", engine)
    summary = study.run()
    assert asked == [1, 4]
    assert summary["done"] == 5 and summary["failed"] == 0
    assert json.loads((tmp_path / "summary.json").read_text())["n"] == 5
    assert (tmp_path / "risk.png").stat().st_size > 0 and (tmp_path / "errors.png").stat().st_size > 0


def test_a_folder_of_another_sweep_is_refused_unless_fresh(tmp_path: Path, fence1: sc.Scenario) -> None:
    open_store(tmp_path, _params(fence1), fresh=False, warn=print).close()
    with pytest.raises(UsageError, match=r"different sweep.*stage.*--fresh"):
        open_store(tmp_path, _params(fence1, "detect"), fresh=False, warn=print)
    assert open_store(tmp_path, _params(fence1, "detect"), fresh=True, warn=print).lines == {}


def test_a_failing_run_returns_its_error(fence1: sc.Scenario, monkeypatch: pytest.MonkeyPatch) -> None:
    def broken(*a: Any, **kw: Any) -> None:
        raise RuntimeError("the simulator fell over")

    monkeypatch.setattr("cell.pipeline.detect", broken)
    out = run_task(fence1, variation(fence1, WELDMAP, 0, ("seed",)), "detect")
    assert out["line"]["seams"] == {}
    assert out["line"]["error"]["type"] == "RuntimeError" and out["line"]["error"]["exit_code"] == 1
    assert "fell over" in out["line"]["error"]["message"] and "task_s" in out["timings"]


def test_summary_probabilities_from_hand_made_runs() -> None:
    lines = [
        _result(0, {"A": _seam(True, 0.2, True), "B": _seam(False, None, False, False)})["line"],
        _result(1, {"A": _seam(True, 0.6, False), "B": _seam(True, 0.1, True)})["line"],
        _result(2, {"A": _seam(True, 0.4, True), "B": _seam(False, None, False, False)})["line"],
        _result(3, {"A": _seam(False, None, False, False), "B": {**_seam(False, None, False, False), "reasons": []}})[
            "line"
        ],
        _result(4, error={"type": "WorkerCrashedError", "message": "died", "exit_code": 1})["line"],
        _result(9, {"A": _seam(True, 9.0, False)})["line"],  # beyond n: not counted
    ]
    s = summarize(lines, ["A", "B"], n=5, stage="plan", engine={"engine": "ray"}, sweep={}, weld_tolerance_mm=0.5)
    assert (s["n"], s["done"], s["failed"]) == (5, 5, 1)
    assert s["failed_runs"] == [{"run": 4, "type": "WorkerCrashedError", "message": "died", "exit_code": 1}]
    a, b = s["seams"]["A"], s["seams"]["B"]
    assert a["runs"] == 4 and a["probability_found"] == 0.75 and a["probability_within_tolerance"] == 0.5
    assert a["probability_planned"] == 0.75 and a["probability_welded"] is None  # nothing moved in a plan sweep
    assert a["lateral_mm"]["p50"] == pytest.approx(0.4) and a["lateral_mm"]["max"] == pytest.approx(0.6)
    assert b["probability_found"] == 0.25 and b["lateral_mm"]["max"] == pytest.approx(0.1)
    # the reasons are those of the runs that did not find (plan) it, numbers aside; a found seam's notes are not
    assert b["reasons"] == [{"reason": "seen by # cameras", "runs": 2}]
