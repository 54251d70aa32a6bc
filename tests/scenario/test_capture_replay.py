"""A capture folder replayed through the recorded-data station gives ``cell detect``'s report, number for number,
and the replay path never loads the simulator."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from cell import pipeline
from cell import scenario as sc
from cell.cli.capture import write_simulated
from cell.export.reports.report import detection_report
from cell.recorded import read_capture
from cell.recorded.cell_file import replay_scenario
from cell.station.recorded import RecordedStation

# What a replay may change: when and how long (provenance, timings), the map file's name (copied beside cell.yaml),
# the simulation section the capture's cell.yaml leaves out, and what the data were (a replay simulates nothing: its
# source is "capture" and its noise null, checked below).
UNCOMPARED = ("provenance", "timings_s", "time_ms", "time_ms_per_seam_median", "source", "noise")


def numbers(report: dict[str, Any]) -> dict[str, Any]:
    """The report without what a replay may change (module comment)."""

    def strip(x: Any) -> Any:
        if isinstance(x, dict):
            return {k: strip(v) for k, v in x.items() if k not in UNCOMPARED}
        if isinstance(x, list):
            return [strip(v) for v in x]
        return x

    out = strip(report)
    out["config"] = {k: v for k, v in out["config"].items() if k != "simulation"}
    out["config"]["map"] = {k: v for k, v in out["config"]["map"].items() if k != "file"}
    return dict(out)


def replayed(folder: Path) -> pipeline.Detection:
    """``cell detect --capture folder`` in process: the capture's cell, its images through the recorded station."""
    station = RecordedStation.open(folder)
    return pipeline.detect(replay_scenario(station.recorded), station=station)


def half_resolution(s: sc.Scenario) -> sc.Scenario:
    """The cameras at half resolution: enough for a fault's refusals, a quarter of the pixels to render."""
    cams = {
        n: c.model_copy(update={"resolution": (c.resolution[0] // 2, c.resolution[1] // 2)})
        for n, c in s.cameras.items()
    }
    return s.model_copy(update={"cameras": cams})


@pytest.fixture(scope="module")
def dead_camera(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, pipeline.Detection]:
    """faults/two-cameras-dead (half resolution: the eye-in-hand camera alone, a cheap fault) captured to a
    folder, and ``pipeline.detect`` of the same cell."""
    scn = half_resolution(sc.load("faults/two-cameras-dead"))
    folder = write_simulated(scn, tmp_path_factory.mktemp("dead") / "capture", source="faults/two-cameras-dead")
    return folder, pipeline.detect(scn)


def test_a_fence1_capture_replays_to_the_same_report(tmp_path: Path, fence1_detection: pipeline.Detection) -> None:
    folder = write_simulated(fence1_detection.scenario, tmp_path / "capture", source="fence1")
    rec = read_capture(folder)
    assert rec.truth_parts_W is not None and "eye_in_hand" in rec.X_RF  # truth apart, the flange pose recorded
    # The eye-in-hand camera rides on the flange: its pose is the flange's with a fixed offset of a few cm.
    assert 0.01 < np.linalg.norm((np.linalg.inv(rec.X_RF["eye_in_hand"]) @ rec.X_RC("eye_in_hand"))[:3, 3]) < 0.3
    det = replayed(folder)
    assert det.error is None and det.summary.found > 0
    replay, simulated = detection_report(det), detection_report(fence1_detection)
    assert (replay["source"], replay["noise"]) == ("capture", None)
    assert (simulated["source"], simulated["noise"]) == ("simulation", "realistic")
    assert numbers(replay) == numbers(simulated)


def test_a_fault_capture_replays_to_the_same_report_without_the_simulator(
    tmp_path: Path, dead_camera: tuple[Path, pipeline.Detection]
) -> None:
    """``cell detect --capture DIR`` in a process of its own: the report of the simulated run, and neither pybullet
    nor the simulated cell ever imported."""
    folder, simulated = dead_camera
    report = tmp_path / "replay.json"
    code = f"""
import sys
from cell.cli import app
code = app(["-q", "detect", "--capture", {str(folder)!r}, "--json", {str(report)!r}], standalone_mode=False)
print("RESULT", code, "pybullet" in sys.modules, "cell.sim.cell" in sys.modules)
"""
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=False)
    assert done.stdout.splitlines()[-1:] == ["RESULT 3 False False"], done.stderr[-2000:]  # 3: seams not found
    data = json.loads(report.read_text())
    assert sorted(c.split(":")[0] for c in data["lost_cameras"]) == ["cam_left", "cam_right"]
    assert numbers(data) == numbers(detection_report(simulated))
