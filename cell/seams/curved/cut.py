"""Where a curved seam meets a third part (a gusset, a rail across the tube), the located curve stops outside it:
the samples inside it (grown by a margin) left out, the longest run kept, its ends placed against that part."""

from __future__ import annotations

from collections.abc import Set
from dataclasses import replace

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.seams.sigma import GAP_SIGMA_M
from cell.types import Reason, SeamStatus, WeldMap
from cell.types.curve_estimate import CurveEstimate


def outside_parts(wm: WeldMap, p: FloatArray, own: Set[str], margin_m: float) -> npt.NDArray[np.bool_]:
    """(n,) which points p (n, 3) lie outside every part of ``wm`` not named in ``own``, grown by ``margin_m``."""
    keep = np.ones(len(p), bool)
    for part in wm.parts:
        if part.name in own or not len(p):
            continue
        near = np.linalg.norm(p - part.center, axis=1) <= part.radius + margin_m
        if near.any():
            idx = np.flatnonzero(near)
            keep[idx[part.contains(p[idx], margin_m)]] = False
    return keep


def _runs(keep: npt.NDArray[np.bool_], closed: bool) -> list[tuple[int, int]]:
    """(start, stop) index runs of True in ``keep`` (a closed curve's run may wrap past the end: stop > n)."""
    n = len(keep)
    if closed and keep.any() and not keep.all():
        shift = int(np.argmin(keep))  # start the scan at a gap, so no run wraps
        return [(a + shift, b + shift) for a, b in _runs(np.roll(keep, -shift), False)]
    if not n:
        return []
    edges = np.diff(np.concatenate([[0], keep.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist(), strict=True))


def longest_run(est: CurveEstimate, keep: npt.NDArray[np.bool_]) -> CurveEstimate:
    """``est`` cut to its longest run of samples with ``keep`` True: an open curve whose ends stand against the part
    that cut it (their sigma along: the as-built gap's, :data:`~cell.seams.sigma.GAP_SIGMA_M`, and the sample
    step's); NOT_FOUND when no sample is kept."""
    runs = _runs(keep, est.closed)
    if not runs or max(b - a for a, b in runs) < 2:
        why = f"curved seam {est.id}: the whole curve lies inside other parts of the map"
        return CurveEstimate(est.id, SeamStatus.NOT_FOUND, why, code=Reason.NO_SUPPORT)
    a, b = max(runs, key=lambda r: r[1] - r[0])
    idx = np.arange(a, b) % len(keep)
    step = float(np.linalg.norm(np.diff(est.p_RS[idx], axis=0), axis=1).mean())
    cut_sigma = float(np.hypot(GAP_SIGMA_M, step / np.sqrt(12.0)))
    start = cut_sigma if (est.closed or not keep[0] or a > 0) else est.end_sigma_m[0]
    end = cut_sigma if (est.closed or not keep[-1] or b < len(keep)) else est.end_sigma_m[1]
    return replace(
        est,
        p_RS=est.p_RS[idx],
        n_abutting_R=est.n_abutting_R[idx],
        n_receiving_R=est.n_receiving_R[idx],
        sigma_m=est.sigma_m[idx],
        closed=False,
        end_sigma_m=(start, end),
    )
