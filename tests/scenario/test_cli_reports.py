"""The command line on the real pipeline: the JSON report contract, and a late failure that still writes it."""

from __future__ import annotations

import hashlib
import json
import shutil
import subprocess
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import pytest
from typer.testing import CliRunner

from cell import pipeline
from cell import scenario as sc
from cell.cli import app

runner = CliRunner()
REPO = Path(__file__).resolve().parents[2]


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
            assert set(s["error_mm"]) == {"paper_me", "endpoint", "lateral", "end_along"}
        else:
            assert "detected" not in s and s["reason"]
    summary = data["summary"]
    for key in ("found", "paper_me_mean_mm", "endpoint_mean_mm", "lateral_mean_mm", "time_ms_per_seam_median"):
        assert key in summary
    assert cloud.stat().st_size > 10_000


def _detect_returning(
    det: pipeline.Detection, asked: list[tuple[sc.Scenario, str | None, dict[str, object]]]
) -> Callable[..., pipeline.Detection]:
    """``pipeline.detect`` standing in: ``det`` (a detection the session ran once), the CLI's arguments kept."""

    def detect(scenario: sc.Scenario, method: str | None = None, **kw: object) -> pipeline.Detection:
        asked.append((scenario, method, kw))
        return det

    return detect


def _asked_for(asked: list[tuple[sc.Scenario, str | None, dict[str, object]]], name: str) -> None:
    """The CLI asked ``pipeline.detect`` once for scenario ``name`` as shipped, its own method, a cell of its own."""
    ((scenario, method, kw),) = asked
    assert scenario == sc.load(name) and method is None and kw.get("station") is None


def test_alignment_failure_still_writes_every_seam_with_its_reason(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, detected: Callable[..., pipeline.Detection]
) -> None:
    """``cell detect faults/displaced-far``: the session's detection of it at half resolution (tests/conftest.py's
    ``detected``, which test_faults.py asserts is refused as well) stands in for the pipeline's: what is checked
    here, the report and the exit of a refused alignment, does not depend on the cameras' resolution."""
    asked: list[tuple[sc.Scenario, str | None, dict[str, object]]] = []
    monkeypatch.setattr(pipeline, "detect", _detect_returning(detected("faults/displaced-far", True), asked))
    report = tmp_path / "out.json"
    code, _, err = invoke("detect", "faults/displaced-far", "--json", str(report))
    _asked_for(asked, "faults/displaced-far")
    assert code == 3, err  # partial: the report is written, the cause is in it
    assert "error:" in err and "Traceback" not in err
    data = json.loads(report.read_text())
    assert data["error"]["type"] == "AlignmentError" and data["error"]["exit_code"] == 14
    assert len(data["seams"]) == 16
    assert all(s["status"] in ("not_found", "not_visible") for s in data["seams"])
    assert all(s["reason"] for s in data["seams"])
    assert not any("detected" in s for s in data["seams"])


def test_save_cloud_writes_the_spliced_cloud_when_the_alignment_fails_and_says_why_when_none_was_spliced(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, detected: Callable[..., pipeline.Detection]
) -> None:
    """The cloud of a refused alignment is the one to look at: it is saved (every camera's registered points, what
    ``cell locate`` reads back), and the line says how to read it; with no cloud at all, a warning says why."""
    from cell.perception.cloud_files import read_cloud

    det = detected("faults/displaced-far", True)
    assert det.scene is None and det.perceived is not None
    asked: list[tuple[sc.Scenario, str | None, dict[str, object]]] = []
    monkeypatch.setattr(pipeline, "detect", _detect_returning(det, asked))
    cloud = tmp_path / "cloud.ply"
    code, out, err = invoke("detect", "faults/displaced-far", "--save-cloud", str(cloud))
    assert code == 3, err
    assert f"read it back with: cell locate {cloud} --map MAP --frame R --table-z" in out + err
    assert len(read_cloud(cloud, frame="R")) == len(det.perceived.spliced.registered)
    none = replace(det, perceived=None)  # perception itself failed: nothing to save
    monkeypatch.setattr(pipeline, "detect", _detect_returning(none, asked))
    code, out, err = invoke("detect", "faults/displaced-far", "--save-cloud", str(tmp_path / "none.ply"))
    assert code == 3 and not (tmp_path / "none.ply").exists()
    line = next(x for x in err.splitlines() if "--save-cloud" in x)
    assert "nothing written" in line and "no cloud was spliced" in line


def _weld_returning(run: pipeline.WeldRun, then: Callable[[], object]) -> Callable[..., pipeline.WeldRun]:
    """``pipeline.weld`` standing in: the session's run, after ``then`` (what goes wrong late in the run)."""

    def weld(*_: object, **__: object) -> pipeline.WeldRun:
        then()
        return run

    return weld


def test_weld_report_to_stdout_with_provenance_in_report_and_program(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, fence1_run: pipeline.WeldRun
) -> None:
    monkeypatch.setattr(pipeline, "weld", _weld_returning(fence1_run, lambda: None))
    krl = tmp_path / "krl"
    code, out, err = invoke(
        "weld", "fence1", "--sides", "first", "--json", "-", "--program", str(krl), "--format", "json"
    )
    assert code == 0, err
    data = json.loads(out)  # stdout is the report alone: the table (here as JSON rows) went to stderr
    assert data["welded"] == 12 and '"seam": "POST_L>TOP_RAIL:+x"' in err
    prov = data["provenance"]
    assert prov["seed"] == data["config"]["seed"]
    assert prov["scenario_sha256"] == hashlib.sha256(sc.resolve("fence1").read_bytes()).hexdigest()
    assert prov["map_sha256"] == hashlib.sha256(sc.load("fence1").map_path.read_bytes()).hexdigest()
    src = (krl / "WELD_FENCE1.src").read_text()
    assert prov["commit"] in src and prov["scenario_sha256"] in src and prov["map_sha256"] in src
    assert prov["map_sha256"] in (krl / "WELD_FENCE1.dat").read_text()


def test_a_late_failure_loses_only_its_own_output(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, fence1_run: pipeline.WeldRun
) -> None:
    """The report's folder (then the program's) turns into a file during the run: the other output is still
    written, exit 2, and the last line names what was lost."""
    report, krl = tmp_path / "rep" / "r.json", tmp_path / "krl"
    report.parent.mkdir()  # there when checked (a missing folder is refused before the run), then made a file

    def folder_to_file(folder: Path) -> None:
        shutil.rmtree(folder)
        folder.write_text("")

    monkeypatch.setattr(pipeline, "weld", _weld_returning(fence1_run, lambda: folder_to_file(report.parent)))
    code, _, err = invoke("weld", "fence1", "--sides", "first", "--json", str(report), "--program", str(krl))
    assert code == 2, err
    assert "Traceback" not in err and ".part" not in err
    assert err.strip().splitlines()[-1].startswith(f"exit 2: could not write '{report}'")
    assert (krl / "WELD_FENCE1.src").is_file() and (krl / "trajectory.csv").is_file()

    report, krl = tmp_path / "r2.json", tmp_path / "krl2"
    monkeypatch.setattr(pipeline, "weld", _weld_returning(fence1_run, lambda: folder_to_file(krl)))
    code, _, err = invoke("weld", "fence1", "--sides", "first", "--json", str(report), "--program", str(krl))
    assert code == 2, err
    assert err.strip().splitlines()[-1].startswith("exit 2: could not write")
    assert json.loads(report.read_text())["welded"] == 12


def test_a_lost_camera_is_named_on_the_last_line(
    monkeypatch: pytest.MonkeyPatch, detected: Callable[..., pipeline.Detection]
) -> None:
    """``cell detect faults/camera-dead``: the session's detection of it (``detected``, the one test_faults.py
    checks) stands in for the pipeline's, the CLI's arguments checked as it passes them."""
    asked: list[tuple[sc.Scenario, str | None, dict[str, object]]] = []
    monkeypatch.setattr(pipeline, "detect", _detect_returning(detected("faults/camera-dead"), asked))
    code, _, err = invoke("detect", "faults/camera-dead")
    _asked_for(asked, "faults/camera-dead")
    assert code == 3, err
    last = err.strip().splitlines()[-1]
    assert last.startswith("exit 3: camera cam_left lost (") and last.endswith("12/12 visible found"), last


def test_bench_writes_its_run_folder_and_leaves_tracked_files_alone(tmp_path: Path) -> None:
    def status() -> str:
        return subprocess.run(
            ["git", "-C", str(REPO), "status", "--porcelain", "--", "benchmarks"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout

    before = status()
    run = tmp_path / "run"
    code, out, err = invoke("bench", "fence1-exact", "--methods", "ours", "--repeat", "1", "--out", str(run))
    assert code == 0, err
    assert status() == before
    rows = json.loads((run / "bench.json").read_text())
    assert [(r["scenario"], r["method"]) for r in rows] == [("fence1-exact", "ours")]
    prov = json.loads((run / "provenance.json").read_text())
    assert [s["name"] for s in prov["scenarios"]] == ["fence1-exact"] and prov["scenarios"][0]["map_sha256"]
    assert (run / "bench.md").read_text().startswith("<!-- made by cell ")
    assert "| fence1-exact |" in out
