"""The curved seams of a run: located by the run's method and measured against their true curves where the station
knows them; the answers of a run that searched nothing; a located curve carried into another frame."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import replace

import numpy as np

from cell.geometry import FloatArray, transform_points
from cell.seams.curved.locate import locate_curves
from cell.seams.curved.metrics import curve_error
from cell.types import Reason, SeamScene, SeamStatus, WeldMap
from cell.types.curve_estimate import CurveEstimate, CurveMetrics


def curve_results(
    method: str,
    scene: SeamScene,
    truths: Mapping[str, FloatArray],
    calibration: Callable[[FloatArray], float] | None = None,
) -> tuple[tuple[CurveEstimate, ...], dict[str, CurveMetrics]]:
    """Every curved seam of ``scene``'s map located by ``method``, and the found ones' errors against ``truths``
    (seam id -> true curve (n, 3), in the scene's frame; empty without a truth). ``calibration``: the cameras'
    calibration sigma [m] of a curve through given samples (n, 3), added to each found curve's sigmas."""
    estimates = locate_curves(method, scene)
    if calibration is not None:
        estimates = tuple(with_calibration(e, calibration(np.asarray(e.p_RS))) for e in estimates)
    metrics = {
        e.id: curve_error(e, np.asarray(truths[e.id]))
        for e in estimates
        if e.status is SeamStatus.FOUND and e.id in truths
    }
    return estimates, metrics


def with_calibration(est: CurveEstimate, sigma_cal: float) -> CurveEstimate:
    """``est`` (found) with a calibration term ``sigma_cal`` [m] in quadrature with every sample's sigma and each
    end's (a camera's pose error moves its points rigidly: the whole curve, along it as much as across)."""
    if est.status is not SeamStatus.FOUND or sigma_cal <= 0.0:
        return est
    ends = est.end_sigma_m
    return replace(
        est,
        sigma_m=np.hypot(np.asarray(est.sigma_m), sigma_cal),
        end_sigma_m=(math.hypot(ends[0], sigma_cal), math.hypot(ends[1], sigma_cal)) if any(ends) else ends,
    )


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
