"""The last check before the arc, through the real pipeline: a seam whose estimate is corrupted after the re-scan
(its end run on 30 mm along the receiving face, with a tiny sigma: confidently wrong) is re-scanned up close, still
cannot be where it is said to be, and is refused with its own reason; nothing is welded along it."""

from __future__ import annotations

import importlib
from dataclasses import replace
from typing import Any

import numpy as np
import pytest

from cell import pipeline
from cell import scenario as sc
from cell.export.report import weld_report
from cell.types import LastCheck, SeamStatus, WeldReason

weld_stage = importlib.import_module("cell.pipeline.weld")  # the module (``cell.pipeline.weld`` is also the function)

BAD = "POST_R>TOP_RAIL:+x"
GOOD = "POST_R>TOP_RAIL:+z"


def test_a_corrupted_seam_is_rescanned_then_refused_not_welded(monkeypatch: pytest.MonkeyPatch) -> None:
    original = weld_stage.rescan_weldable

    def corrupted(*args: Any, **kw: Any) -> Any:
        rs, det, hopeless = original(*args, **kw)
        ests = []
        for e in det.estimates:
            if e.id == BAD and e.status is SeamStatus.FOUND:
                d = (e.p_end - e.p_start) / np.linalg.norm(e.p_end - e.p_start)
                e = replace(e, p_end=e.p_end + 0.030 * d, sigma_m=1e-5, confidence=0.99)
            ests.append(e)
        return rs, replace(det, estimates=tuple(ests)), hopeless

    monkeypatch.setattr(weld_stage, "rescan_weldable", corrupted)
    run = pipeline.weld(sc.load("fence1"), only={BAD, GOOD})
    by_id = {w.id: w for w in run.seams}
    bad = by_id[BAD]
    assert not bad.welded and not bad.planned
    assert bad.code is WeldReason.LAST_CHECK and bad.check is not None
    assert bad.check.code is LastCheck.LENGTH  # still about 15 mm too long after the close-up's fusion
    assert bad.check.value_m > bad.check.limit_m
    assert run.rescan is not None and BAD in {r.id for r in run.rescan.seams}  # re-scanned before it was refused
    assert run.plan is not None and BAD not in run.plan.order  # nothing planned along it
    assert by_id[GOOD].welded and by_id[GOOD].check is None  # the other seam passes and is welded
    entry = next(s for s in weld_report(run)["seams"] if s["id"] == BAD)
    assert entry["weld_reason_code"] == "last_check" and entry["last_check"]["code"] == "length"
    assert entry["last_check"]["value_mm"] > entry["last_check"]["limit_mm"] > 6.0  # the build tolerance and more
