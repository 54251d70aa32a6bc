"""An escalated re-scan: how far a close-up moved its seam from the fixed cameras' estimate
(:func:`end_shift_m`, :func:`largest_shift_mm`), and one re-scan joined from the first seams' and the others'
(:func:`escalated`). When a close-up moves its seam by more than ``rescan.escalate_mm`` the fixed cameras cannot be
trusted here (calibration off, a bumped camera): every other visible seam is re-scanned too
(:func:`cell.pipeline.rescan.rescan_chosen`). Values only; frames: R; metres unless a name says mm.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from cell.geometry import FloatArray
from cell.types import EndSource, SeamEstimate, SeamStatus
from cell.types.rescan import Rescan


def largest_shift_mm(rescan: Rescan) -> float:
    """The largest :func:`end_shift_m` [mm] of the seams whose close-up was used (0 when none was)."""
    return max((end_shift_m(r.before, r.closeup) * 1000.0 for r in rescan.seams if r.used), default=0.0)


def escalated(first: Rescan, more: Rescan, shift_mm: float) -> Rescan:
    """One re-scan of ``first``'s seams and then ``more``'s, escalated because a close-up of ``first`` moved its
    seam by ``shift_mm`` [mm]."""
    return replace(
        more,
        seams=first.seams + more.seams,
        moves=first.moves + more.moves,
        executions=first.executions + more.executions,
        note=f"escalated: a close-up disagreed by {shift_mm:.2f} mm; {more.note}".rstrip("; "),
        timings={k: first.timings.get(k, 0.0) + more.timings.get(k, 0.0) for k in {*first.timings, *more.timings}},
        escalated_mm=shift_mm,
    )


def end_shift_m(before: SeamEstimate, closeup: SeamEstimate | None) -> float:
    """Largest distance [m] between matching ends of two found estimates of one seam (0 when either is missing);
    an end of ``before`` that only the drawn length placed (``drawn``) counts only across the seam: the close-up
    finding where it really is says nothing of the fixed cameras."""
    if closeup is None or before.status is not SeamStatus.FOUND or closeup.status is not SeamStatus.FOUND:
        return 0.0
    a = np.stack([before.p_start, before.p_end])
    t = (a[1] - a[0]) / max(float(np.linalg.norm(a[1] - a[0])), 1e-12)
    drawn = np.array([k is EndSource.DRAWN for k in before.end_source])

    def worst(b: FloatArray) -> float:
        d = b - a
        d[drawn] -= np.outer(d[drawn] @ t, t)  # a drawn end: across the seam only
        return float(np.linalg.norm(d, axis=1).max())

    b = np.stack([closeup.p_start, closeup.p_end])
    return min(worst(b), worst(b[::-1]))
