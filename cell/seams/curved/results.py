"""The curved seams of a run: located by the run's method and measured against their true curves where the station
knows them; the answers of a run that searched nothing; a located curve carried into another frame."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

import numpy as np

from cell.geometry import FloatArray, transform_points
from cell.seams.curved.locate import locate_curves
from cell.seams.curved.metrics import curve_error
from cell.types import Reason, SeamScene, SeamStatus, WeldMap
from cell.types.curve_estimate import CurveEstimate, CurveMetrics


def curve_results(
    method: str, scene: SeamScene, truths: Mapping[str, FloatArray]
) -> tuple[tuple[CurveEstimate, ...], dict[str, CurveMetrics]]:
    """Every curved seam of ``scene``'s map located by ``method``, and the found ones' errors against ``truths``
    (seam id -> true curve (n, 3), in the scene's frame; empty without a truth)."""
    estimates = locate_curves(method, scene)
    metrics = {
        e.id: curve_error(e, np.asarray(truths[e.id]))
        for e in estimates
        if e.status is SeamStatus.FOUND and e.id in truths
    }
    return estimates, metrics


def not_searched(weldmap: WeldMap, why: str) -> tuple[CurveEstimate, ...]:
    """Every curved seam of ``weldmap`` NOT_FOUND with ``why`` (perception or the alignment failed: no search)."""
    return tuple(
        CurveEstimate(c.id, SeamStatus.NOT_FOUND, f"no seam search: {why}", code=Reason.NO_SEARCH)
        for c in weldmap.curved
    )


def carried(est: CurveEstimate, X_BA: FloatArray) -> CurveEstimate:
    """``est`` (in frame A) in frame B, for a rigid X_BA (4, 4)."""
    if est.status is not SeamStatus.FOUND:
        return est
    R = np.asarray(X_BA)[:3, :3]
    return replace(
        est,
        p_RS=transform_points(X_BA, est.p_RS),
        n_abutting_R=est.n_abutting_R @ R.T,
        n_receiving_R=est.n_receiving_R @ R.T,
    )
