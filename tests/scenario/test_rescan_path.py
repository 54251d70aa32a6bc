"""``cell weld`` and ``cell rescan`` share one re-scan path (``cell.pipeline.rescan``): a close-up that disagrees
with the fixed cameras escalates to every visible seam in both, seen through the same fake loop (tests/fakes.py).
Both start from the session's detection of fence1 (``fence1_detection``) instead of detecting it again."""

from __future__ import annotations

import importlib
import json
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest
from fakes import FakeLoop
from typer.testing import CliRunner

import cell.pipeline.rescan as loop
from cell import pipeline
from cell import scenario as sc
from cell.cli import app
from cell.types import SeamStatus
from cell.types.rescan import Rescan

WELD_MODULE = importlib.import_module("cell.pipeline.weld")  # the module (``cell.pipeline.weld`` is its function)


def test_weld_and_the_rescan_command_share_the_rescan_path(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, fence1_detection: pipeline.Detection
) -> None:
    det = fence1_detection
    scn = det.scenario
    confidences = sorted(e.confidence for e in det.estimates if e.status is SeamStatus.FOUND)
    # Exactly one doubtful seam (the least confident), whose close-up lands 3 mm off: the fixed cameras are wrong.
    # (Tolerances wide enough that no seam is doubtful for its bound across or at an end: the confidence alone picks.)
    rescan = scn.rescan.model_copy(
        update={
            "mode": "low",
            "confidence_threshold": (confidences[0] + confidences[1]) / 2,
            "weld_tolerance_mm": 50.0,
            "end_tolerance_mm": 50.0,
        }
    )
    scn = scn.model_copy(update={"rescan": rescan})
    calls: list[list[str]] = []

    def first_disagrees(station: Any, det: Any, ids: Sequence[str], **kw: Any) -> Rescan:
        fake = FakeLoop({ids[0]: 0.003} if not calls else {})
        out = fake(station, det, ids, **kw)
        calls.extend(fake.calls)
        return out

    monkeypatch.setattr(loop, "rescan_seams", first_disagrees)
    # fence1's detection is the session's (the re-scan options change nothing before the re-scan): the weld and the
    # command detect nothing again; each hands it on as its own, with the scenario it was given.
    detections: list[sc.Scenario] = []

    def detect(scenario: sc.Scenario, method: str | None = None, **_: Any) -> pipeline.Detection:
        assert method is None
        detections.append(scenario)
        return replace(det, scenario=scenario)

    monkeypatch.setattr(WELD_MODULE, "detect", detect)
    monkeypatch.setattr(pipeline, "detect", detect)
    run = pipeline.weld(scn)
    assert detections == [scn]
    assert run.rescan is not None and run.rescan.escalated_mm == pytest.approx(3.0, abs=1e-6)
    assert [len(c) for c in calls] == [1, 11]  # the doubtful seam, then the other 11 visible ones
    # cell rescan --seams ONE: the chosen seam, then (it disagreed) every other visible seam, as in weld.
    calls.clear()
    out = tmp_path / "r.json"
    res = CliRunner().invoke(
        app, ["rescan", "fence1", "--seams", calls_first := det.estimates[0].id, "--json", str(out)]
    )
    assert res.exit_code == 0, res.output
    assert calls[0] == [calls_first] and [len(c) for c in calls] == [1, 11]
    assert json.loads(out.read_text())["rescan"]["seams"] == 12
    assert detections == [scn, sc.load("fence1")]
