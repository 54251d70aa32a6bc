"""The re-scan policy (which seams, when to escalate) and that ``cell weld`` and ``cell rescan`` share it.

The policy is tested against a fake station loop: ``rescan_seams`` replaced by one that "re-scans" by moving each
seam a chosen distance, so the escalation branch is exercised without a simulator. The scenario test then proves
both commands go through the one path: the same fake, seen from ``pipeline.weld`` and from ``cell rescan``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

import cell.pipeline.rescan as loop
from cell import scenario as sc
from cell.pipeline import Detection, evaluate, rescan_detection
from cell.rescan import Rescan, SeamRescan
from cell.types import SeamEstimate, SeamStatus, WeldMap


def _found(seam_id: str, confidence: float, y: float = 0.0) -> SeamEstimate:
    return SeamEstimate(seam_id, SeamStatus.FOUND, "", np.array([0.0, y, 0.0]), np.array([0.1, y, 0.0]), confidence)


class FakeLoop:
    """Stands in for the station-driving loop: a close-up of seam ``s`` lands ``shift_m[s]`` [m] off the first."""

    def __init__(self, shift_m: dict[str, float]) -> None:
        self.shift_m = shift_m
        self.calls: list[list[str]] = []

    def __call__(self, station: Any, det: Any, ids: Sequence[str], **_: Any) -> Rescan:
        self.calls.append(list(ids))
        seams = []
        by_id = {e.id: e for e in det.estimates}
        for sid in ids:
            first = by_id[sid]
            dy = np.array([0.0, self.shift_m.get(sid, 0.0), 0.0])
            close = replace(first, p_start=first.p_start + dy, p_end=first.p_end + dy, confidence=0.99)
            seams.append(SeamRescan(sid, first, close, close, 1.0, None, 1.0, 0.0))
        fused = {r.id: r.fused for r in seams}
        estimates = tuple(fused.get(e.id, e) for e in det.estimates)
        return Rescan(tuple(seams), estimates, (), (), np.zeros(6), True)


def _detection(confidences: dict[str, float]) -> Any:
    estimates = (*(_found(k, c) for k, c in confidences.items()), SeamEstimate("under", SeamStatus.NOT_VISIBLE))
    scenario: Any = SimpleNamespace(rescan=SimpleNamespace(confidence_threshold=0.55, escalate_mm=0.5))
    _, summary = evaluate(estimates, {})
    return Detection(scenario, "ours", WeldMap((), (), "mm", "inline"), estimates, {}, {}, summary)


def test_low_mode_rescans_the_doubtful_seams_and_escalates_when_a_closeup_disagrees(monkeypatch: Any) -> None:
    fake = FakeLoop({"b": 0.002})  # a 2 mm disagreement: the fixed cameras are not to be trusted here
    monkeypatch.setattr(loop, "rescan_seams", fake)
    rs, after = rescan_detection(None, _detection({"a": 0.9, "b": 0.3, "c": 0.8}), "low")  # type: ignore[arg-type]
    assert fake.calls == [["b"], ["a", "c"]]  # the doubtful one, then every other visible seam
    assert rs.escalated_mm == pytest.approx(2.0) and [r.id for r in rs.seams] == ["b", "a", "c"]
    assert [e.id for e in after.estimates] == ["a", "b", "c", "under"]


def test_no_escalation_when_the_closeups_agree_or_every_seam_was_asked_for(monkeypatch: Any) -> None:
    agree = FakeLoop({"b": 0.0001})  # 0.1 mm: within escalate_mm
    monkeypatch.setattr(loop, "rescan_seams", agree)
    rs, _ = rescan_detection(None, _detection({"a": 0.9, "b": 0.3}), "low")  # type: ignore[arg-type]
    assert agree.calls == [["b"]] and rs.escalated_mm == 0.0
    every = FakeLoop({"a": 0.002})
    monkeypatch.setattr(loop, "rescan_seams", every)
    rescan_detection(None, _detection({"a": 0.9, "b": 0.3}), "all")  # type: ignore[arg-type]
    assert every.calls == [["a", "b"]]
    chosen = FakeLoop({"a": 0.002})
    monkeypatch.setattr(loop, "rescan_seams", chosen)
    rescan_detection(None, _detection({"a": 0.9, "b": 0.3}), "low", seam_ids=["a"])  # type: ignore[arg-type]
    assert chosen.calls == [["a"], ["b"]]  # chosen seams, and the same escalation


@pytest.mark.scenario
def test_weld_and_the_rescan_command_share_the_rescan_path(monkeypatch: Any, tmp_path: Any) -> None:
    """Both commands hand their re-scan to ``cell.pipeline.rescan``: a close-up that disagrees escalates in both."""
    import json

    from typer.testing import CliRunner

    from cell import pipeline
    from cell.cli import app

    scn = sc.load("fence1")
    det = pipeline.detect(scn)
    confidences = sorted(e.confidence for e in det.estimates if e.status is SeamStatus.FOUND)
    # Exactly one doubtful seam (the least confident), whose close-up lands 3 mm off: the fixed cameras are wrong.
    rescan = scn.rescan.model_copy(
        update={"mode": "low", "confidence_threshold": (confidences[0] + confidences[1]) / 2}
    )
    scn = scn.model_copy(update={"rescan": rescan})
    calls: list[list[str]] = []

    def first_disagrees(station: Any, det: Any, ids: Sequence[str], **kw: Any) -> Rescan:
        fake = FakeLoop({ids[0]: 0.003} if not calls else {})
        out = fake(station, det, ids, **kw)
        calls.extend(fake.calls)
        return out

    monkeypatch.setattr(loop, "rescan_seams", first_disagrees)
    run = pipeline.weld(scn)
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
