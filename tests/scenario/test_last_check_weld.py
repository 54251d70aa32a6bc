"""The last check before the arc and the gate's body test, through the real pipeline: a seam whose estimate is
corrupted after the re-scan (its end run on 30 mm along the receiving face, with a tiny sigma: confidently wrong)
fails the last check, is re-scanned up close, and the close-up disagrees with its end by far more than their
sigmas: the end is as uncertain as the disagreement, and the seam is refused (``end_uncertain``); a seam whose
end a third part overlaps by less than the last check allows is dropped by the safety gate. Nothing is welded
along either."""

from __future__ import annotations

import importlib
from dataclasses import replace
from typing import Any

import numpy as np
import pytest

from cell import pipeline
from cell import scenario as sc
from cell.export.reports.report import weld_report
from cell.geometry import make_pose
from cell.types import Box, Part, PlanReason, SeamStatus, WeldReason

weld_stage = importlib.import_module("cell.pipeline.weld")  # the module (``cell.pipeline.weld`` is also the function)

BAD = "POST_R>TOP_RAIL:+x"
GOOD = "POST_R>TOP_RAIL:+z"
FAR = "POST_L>TOP_RAIL:+x"  # the other post's: nowhere near the first's top corner


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
    assert bad.code is WeldReason.END_UNCERTAIN and bad.check is None  # the close-up put the check right, not the end
    assert run.rescan is not None and BAD in {r.id for r in run.rescan.seams}  # re-scanned before it was refused
    assert run.plan is not None and BAD not in run.plan.order  # nothing planned along it
    assert by_id[GOOD].welded and by_id[GOOD].check is None  # the other seam passes and is welded
    entry = next(s for s in weld_report(run)["seams"] if s["id"] == BAD)
    assert entry["weld_reason_code"] == "end_uncertain"
    assert max(entry["end_sigma_mm"]) > 10.0  # half the 30 mm the two disagreed by


def test_a_third_part_over_a_seams_end_passes_the_last_check_but_not_the_gate(monkeypatch: pytest.MonkeyPatch) -> None:
    """A small part stands over the end of a seam in the aligned map, the end 2 mm inside it: within what the
        last check allows an end (half the build tolerance), but the wire tip would burn 2 mm into it. The safety gate
        drops that seam alone (``enters_body``), with the part's name; a seam of the other post is welded (the top seam
    of the same corner would pass through the part too: with both at fault the whole plan is refused)."""
    original = weld_stage.rescan_weldable
    placed: list[Part] = []

    def with_a_block(*args: Any, **kw: Any) -> Any:
        rs, det, hopeless = original(*args, **kw)
        e = next(e for e in det.estimates if e.id == BAD)
        d = (e.p_end - e.p_start) / np.linalg.norm(e.p_end - e.p_start)
        block = Part("BLOCK", Box(make_pose(p=e.p_end + 0.002 * d), np.full(3, 0.008)))
        placed.append(block)
        ss = det.scene.seam_scene
        scene = replace(
            det.scene, seam_scene=replace(ss, weldmap=replace(ss.weldmap, parts=(*ss.weldmap.parts, block)))
        )
        return rs, replace(det, scene=scene), hopeless

    monkeypatch.setattr(weld_stage, "rescan_weldable", with_a_block)
    run = pipeline.weld(sc.load("fence1"), only={BAD, FAR})
    assert placed
    by_id = {w.id: w for w in run.seams}
    bad = by_id[BAD]
    assert not bad.welded and bad.check is None  # the last check let it through ...
    assert bad.code is WeldReason.NOT_PLANNED and "BLOCK" in bad.reason  # ... the gate did not
    assert run.plan is not None and run.plan.outcome(BAD).code is PlanReason.ENTERS_BODY
    assert by_id[FAR].welded
