"""Seam accuracy against ground truth, metres in (frame R), millimetres out: the paper's ME, the end points' error,
the lateral error and each end's signed error along the true seam (their definitions: docs/report.md)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from cell.geometry import FloatArray, point_line_distance
from cell.types import SeamEstimate, SeamStatus
from cell.types.seams import MetricsSummary, SeamMetrics

_MM = 1000.0


def segment_errors(
    p_start: FloatArray, p_end: FloatArray, t_start: FloatArray, t_end: FloatArray
) -> tuple[float, float, float, bool]:
    """(paper_me_mm, endpoint_mm, lateral_mm, swapped) of a detected segment against the true one, all in R
    [m]."""
    det = np.stack([np.asarray(p_start, float), np.asarray(p_end, float)])
    tru = np.stack([np.asarray(t_start, float), np.asarray(t_end, float)])
    direct = np.linalg.norm(det - tru, axis=1).sum()
    crossed = np.linalg.norm(det[::-1] - tru, axis=1).sum()
    swapped = bool(crossed < direct)
    if swapped:
        det = det[::-1]
    diff = det - tru
    paper = float(np.mean(np.abs(diff[:, 0]) + np.abs(diff[:, 1])))
    endpoint = float(np.mean(np.linalg.norm(diff, axis=1)))
    lateral = float(np.max(point_line_distance(det, tru[0], tru[1])))
    return paper * _MM, endpoint * _MM, lateral * _MM, swapped


def end_errors_along(
    p_start: FloatArray, p_end: FloatArray, t_start: FloatArray, t_end: FloatArray
) -> tuple[float, float]:
    """Signed error [mm] of each end of a detected segment along the true seam t_start -> t_end (all (3,), R [m]),
    in the true seam's order (a reversed detection matched first): positive past the true end (outwards, the
    located seam longer), negative short of it."""
    det = np.stack([np.asarray(p_start, float), np.asarray(p_end, float)])
    tru = np.stack([np.asarray(t_start, float), np.asarray(t_end, float)])
    if np.linalg.norm(det[::-1] - tru, axis=1).sum() < np.linalg.norm(det - tru, axis=1).sum():
        det = det[::-1]
    axis = tru[1] - tru[0]
    u = axis / max(float(np.linalg.norm(axis)), 1e-12)
    return float(-(det[0] - tru[0]) @ u) * _MM, float((det[1] - tru[1]) @ u) * _MM


def seam_metrics(estimate: SeamEstimate, t_start: FloatArray, t_end: FloatArray) -> SeamMetrics:
    """Errors of one locator answer against its true seam (t_start_R, t_end_R) (3,) [m]; NaN when not
    found."""
    time_ms = estimate.time_s * _MM
    if estimate.status is not SeamStatus.FOUND:
        nan = float("nan")
        return SeamMetrics(estimate.id, estimate.status, nan, nan, nan, time_ms, end_along_mm=(nan, nan))
    paper, endpoint, lateral, swapped = segment_errors(estimate.p_start, estimate.p_end, t_start, t_end)
    along = end_errors_along(estimate.p_start, estimate.p_end, t_start, t_end)
    return SeamMetrics(estimate.id, estimate.status, paper, endpoint, lateral, time_ms, swapped, along)


def evaluate(
    estimates: Sequence[SeamEstimate], truths: Mapping[str, tuple[FloatArray, FloatArray]]
) -> dict[str, SeamMetrics]:
    """:func:`seam_metrics` of every found estimate, keyed by seam id (each needs a true seam of the same
    id)."""
    missing = [e.id for e in estimates if e.id not in truths]
    if missing:
        raise KeyError(f"no true seam for {', '.join(missing)}; true seams: {', '.join(truths)}")
    return {e.id: seam_metrics(e, *truths[e.id]) for e in estimates if e.status is SeamStatus.FOUND}


def _mean(v: list[float]) -> float:
    return float(np.mean(v)) if v else float("nan")


def summarise(estimates: Sequence[SeamEstimate], per_seam: Mapping[str, SeamMetrics]) -> MetricsSummary:
    """Counts, mean and 95th percentile of the paper ME, mean endpoint and lateral errors, median time per
    seam.

    per_seam : seam id -> :class:`SeamMetrics` of the found seams (as :func:`evaluate` returns); entries of
    seams
        that were not found are ignored.
    """
    found = [m for m in per_seam.values() if m.found]
    paper = [m.paper_me_mm for m in found]
    times = [e.time_s * _MM for e in estimates if e.status is not SeamStatus.NOT_VISIBLE]
    return MetricsSummary(
        seams=len(estimates),
        visible=len(times),
        found=sum(e.status is SeamStatus.FOUND for e in estimates),
        paper_me_mean_mm=_mean(paper),
        paper_me_p95_mm=float(np.percentile(paper, 95)) if paper else float("nan"),
        endpoint_mean_mm=_mean([m.endpoint_mm for m in found]),
        lateral_mean_mm=_mean([m.lateral_mm for m in found]),
        time_ms_per_seam_median=float(np.median(times)) if times else float("nan"),
    )
