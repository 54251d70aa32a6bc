"""The re-scan policy: which seams, and when to escalate to every visible seam.

The policy is tested against a fake station loop (tests/fakes.py): ``rescan_seams`` replaced by one that
"re-scans" by moving each seam a chosen distance, so the escalation branch is exercised without a simulator. That
``cell weld`` and ``cell rescan`` share it: tests/scenario/test_rescan_path.py.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from fakes import FakeLoop

import cell.pipeline.rescan as loop
from cell.pipeline import Detection, evaluate, rescan_detection
from cell.types import SeamEstimate, SeamStatus, WeldMap


def _found(seam_id: str, confidence: float, y: float = 0.0, end_sigma_m: float = 1e-4) -> SeamEstimate:
    p0, p1 = np.array([0.0, y, 0.0]), np.array([0.1, y, 0.0])
    # within 0.5 mm at 3 sigma across; the ends within 1 mm at 3 sigma unless end_sigma_m says otherwise
    ends = (1e-4, end_sigma_m)
    return SeamEstimate(seam_id, SeamStatus.FOUND, "", p0, p1, confidence, sigma_m=1e-4, end_sigma_m=ends)


def _detection(confidences: dict[str, float], end_sigmas_m: dict[str, float] | None = None) -> Any:
    ends = end_sigmas_m or {}
    estimates = (
        *(_found(k, c, end_sigma_m=ends.get(k, 1e-4)) for k, c in confidences.items()),
        SeamEstimate("under", SeamStatus.NOT_VISIBLE),
    )
    scenario: Any = SimpleNamespace(
        rescan=SimpleNamespace(
            confidence_threshold=0.55, escalate_mm=0.5, max_sigma_m=0.5e-3 / 3.0, max_end_sigma_m=1e-3 / 3.0
        )
    )
    _, summary = evaluate(estimates, {})
    return Detection(scenario, "ours", WeldMap((), (), "mm", "inline"), estimates, {}, {}, summary)


def test_low_mode_rescans_the_doubtful_seams_and_escalates_when_a_closeup_disagrees(monkeypatch: Any) -> None:
    fake = FakeLoop({"b": 0.002})  # a 2 mm disagreement: the fixed cameras are not to be trusted here
    monkeypatch.setattr(loop, "rescan_seams", fake)
    rs, after = rescan_detection(None, _detection({"a": 0.9, "b": 0.3, "c": 0.8}), "low")  # type: ignore[arg-type]
    assert fake.calls == [["b"], ["a", "c"]]  # the doubtful one, then every other visible seam
    assert rs.escalated_mm == pytest.approx(2.0) and [r.id for r in rs.seams] == ["b", "a", "c"]
    assert [e.id for e in after.estimates] == ["a", "b", "c", "under"]


def test_low_mode_rescans_a_seam_whose_end_bound_is_over_the_end_tolerance(monkeypatch: Any) -> None:
    fake = FakeLoop({})
    monkeypatch.setattr(loop, "rescan_seams", fake)
    # "b" is sure across and confident, but its end's 3 sigma (1.2 mm) is over the 1 mm end tolerance; "a"'s 0.9 mm
    # is not.
    det = _detection({"a": 0.9, "b": 0.9}, {"a": 0.3e-3, "b": 0.4e-3})
    rescan_detection(None, det, "low")  # type: ignore[arg-type]
    assert fake.calls == [["b"]]


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
