"""``cell sweep`` through Ray once in the suite (Ray's start is most of its cost): tasks run in Ray's workers,
come back as they finish, and a run that fails in its worker is recorded with its error, never raised; a second
sweep into the same folder has nothing left to run and starts no Ray."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from cell import pipeline
from cell import scenario as sc
from cell.sweep.study import Study, SweepSpec
from cell.sweep.task import run_task, weld_seams
from cell.sweep.variations import VARY_WORDS, variation


def test_sweep_on_ray_records_failed_runs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    fence1 = sc.load("fence1")
    weldmap = pipeline.read_weldmap(fence1)
    # the workers cannot read this scenario's map: each run fails at once in its worker (cheap), as any failure would
    broken = fence1.model_copy(update={"map": fence1.map.model_copy(update={"file": "no-such-map.dxf"})})
    spec = SweepSpec(broken, weldmap, 2, VARY_WORDS, "detect", None, "map", "file")
    counts: list[tuple[int, int]] = []
    study = Study(spec, tmp_path, count=lambda d, n: counts.append((d, n)), say=print, warn=print, workers=1)
    summary = study.run()
    assert summary["engine"] == "ray" and summary["engine_version"]
    assert (summary["n"], summary["done"], summary["failed"]) == (2, 2, 2)
    assert {r["type"] for r in summary["failed_runs"]} == {"MapError"}
    lines = [json.loads(t) for t in (tmp_path / "runs.jsonl").read_text().splitlines()]
    assert sorted(ln["run"] for ln in lines) == [0, 1] and counts[-1] == (2, 2)
    # what a worker wrote is what the task gives in this process (the same bytes but the run's key)
    here = run_task(broken, variation(broken, weldmap, 1, VARY_WORDS), "detect")["line"]
    there = next(ln for ln in lines if ln["run"] == 1)
    assert {k: v for k, v in there.items() if k not in ("key", "error")} == {
        k: v for k, v in here.items() if k != "error"
    }
    assert there["error"]["message"] == here["error"]["message"]

    def no_ray(*a: Any, **kw: Any) -> None:
        raise AssertionError("a finished sweep starts no Ray")

    monkeypatch.setattr("cell.sweep.engine.run_sweep", no_ray)
    assert Study(spec, tmp_path, count=lambda d, n: None, say=print, warn=print).run()["done"] == 2


def test_a_weld_runs_seams_as_a_sweep_line(fence1_run: pipeline.WeldRun) -> None:
    """The session's fence1 weld read as a sweep's ``weld`` line and as a ``plan`` line: the planned torch path's
    TCP error against the true seam is the executed one's (the arm follows its plan), and a seam against the
    table is neither found nor planned."""
    scn = fence1_run.detection.scenario
    weld = weld_seams(fence1_run, scn, "weld")
    plan = weld_seams(fence1_run, scn, "plan")
    welded = [s for s, r in weld.items() if r["welded"]]
    assert len(welded) == 12 and all(weld[s]["weld_rms_mm"] is not None for s in welded)
    for s in welded:
        assert plan[s]["plan_tcp_rms_mm"] == pytest.approx(weld[s]["weld_rms_mm"], abs=0.1)
        assert weld[s]["found"] and weld[s]["within_tolerance"] == (weld[s]["lateral_mm"] <= 0.5)
    under = weld["POST_L>TOP_RAIL:-z"]
    assert not under["found"] and not under["planned"] and under["code"] == "not_visible"
    json.dumps(weld, allow_nan=False)  # plain JSON values
