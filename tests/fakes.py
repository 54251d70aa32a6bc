"""Test doubles shared by the unit and the scenario tests: a re-scan loop that moves no arm.

``FakeLoop`` replaces ``cell.pipeline.rescan.rescan_seams`` (the loop that drives the station) so the re-scan
policy (which seams, when to escalate) runs without a simulator, and a scenario run can be made to disagree.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from cell.types.rescan import Rescan, SeamRescan


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
