"""Scenario options reach their stages through the real pipeline, and the report records the resolved scenario."""

from __future__ import annotations

import importlib
from dataclasses import asdict, replace

import pytest

from cell import pipeline
from cell import scenario as sc
from cell.config import OursSettings

FENCE1 = (sc.SCENARIO_DIR / "fence1.yaml").read_text()


def load_text(text: str) -> sc.Scenario:
    return sc.from_yaml(text, sc.SCENARIO_DIR, "test.yaml")


def with_keys(text: str) -> str:
    """fence1 with ``text`` (top-level YAML keys) appended."""
    return FENCE1 + "\n" + text


def test_a_scenario_option_reaches_its_stage_and_the_report_records_it() -> None:
    """Through pipeline.detect: the seam screen's threshold, built from its defaults before the scenario held it,
    turns every found seam into LOW_CONFIDENCE; the report's config is the scenario as resolved."""
    from cell import pipeline
    from cell.export.reports.report import detection_report
    from cell.types import Reason, SeamStatus

    s = load_text(with_keys("locator: {method: ours, options: {target_se_m: 0.0003}}"))
    perception = s.perception.model_copy(update={"screen": replace(s.perception.screen, min_confidence=1.0)})
    det = pipeline.detect(s.model_copy(update={"perception": perception}))
    visible = [e for e in det.estimates if e.status is not SeamStatus.NOT_VISIBLE]
    assert len(visible) == 12 and all(e.code is Reason.LOW_CONFIDENCE for e in visible)
    config = detection_report(det)["config"]
    assert config["perception"]["screen"]["min_confidence"] == 1.0
    assert config["locator"] == {"method": "ours", "options": {**asdict(OursSettings()), "target_se_m": 0.0003}}
    assert config["motion"]["gate"]["rate_hz"] == 1000.0  # every default filled in
    assert sc.from_dict(config, sc.SCENARIO_DIR) == det.scenario  # the record loads back as what ran


def test_a_gate_option_reaches_the_safety_gate(
    monkeypatch: pytest.MonkeyPatch, fence1_detection: pipeline.Detection
) -> None:
    """Through pipeline.weld (a preview): a manipulability bar no arm clears makes the gate, built from its defaults
    before the scenario held it, refuse the plan for singularities. The gate's option changes nothing before the
    plan: the session's detection of fence1 stands in for the weld's own (handed on with the scenario it was given)."""
    from cell.errors import PlanError
    from cell.export.reports.report import weld_report
    from cell.gate import GateRefusedError, ViolationKind

    scn = load_text(with_keys("motion: {gate: {min_manipulability: 1.0}}"))
    asked: list[sc.Scenario] = []

    def detect(scenario: sc.Scenario, method: str | None = None, **_: object) -> pipeline.Detection:
        asked.append(scenario)
        return replace(fence1_detection, scenario=scenario)

    monkeypatch.setattr(importlib.import_module("cell.pipeline.weld"), "detect", detect)
    assert scn.model_copy(update={"motion": fence1_detection.scenario.motion}) == fence1_detection.scenario
    run = pipeline.weld(scn, pipeline.WeldJob(execute=False))
    assert asked == [scn]
    assert isinstance(run.error, GateRefusedError) and run.error.exit_code == PlanError.exit_code
    assert run.violations and run.error.violations == run.violations
    assert {v.kind for v in run.violations} == {ViolationKind.SINGULARITY}
    rep = weld_report(run)
    assert rep["config"]["motion"]["gate"]["min_manipulability"] == 1.0
    assert [v["code"] for v in rep["violations"]] == [ViolationKind.SINGULARITY.value] * len(run.violations)
    assert rep["violations"][0]["detail"] == str(run.violations[0]) and rep["error"]["type"] == "GateRefusedError"
