"""Measuring a detection against the truth, when the data come with one (a simulation, a ``--truth`` file)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from cell.geometry import FloatArray
from cell.pipeline.records import Capture
from cell.types import MetricsSummary, SeamEstimate, SeamMetrics, WeldMap


def evaluate(
    estimates: Sequence[SeamEstimate], truth: Mapping[str, tuple[FloatArray, FloatArray]]
) -> tuple[dict[str, SeamMetrics], MetricsSummary]:
    """Per-seam metrics of the found seams and the summary (paper ME, endpoint, lateral, time); no metrics when
    there is no truth (``truth`` empty)."""
    from cell.seams.metrics import evaluate as metrics_of
    from cell.seams.metrics import summarise

    per_seam = metrics_of(estimates, truth) if truth else {}
    return per_seam, summarise(estimates, per_seam)


def truths(cap: Capture, weldmap_R: WeldMap) -> dict[str, tuple[FloatArray, FloatArray]]:
    """True seams from the as-built geometry, in R, keyed by seam id (empty when the station knows no truth)."""
    from cell.seams.truth import true_seams

    if cap.parts_W is None:
        return {}
    design_W = cap.weldmap.transformed(cap.scenario.X_WM, "W")
    return true_seams(design_W, cap.joints, cap.parts_W, cap.scenario.X_WR)


def curve_truths(cap: Capture) -> dict[str, FloatArray]:
    """True curves of the map's curved seams from the as-built geometry, (n, 3) each in R, keyed by seam id (empty
    when the station knows no truth)."""
    from cell.seams.curve_truth import true_curves

    if cap.parts_W is None or not cap.weldmap.curved:
        return {}
    return true_curves(cap.weldmap, cap.parts_W, cap.scenario.X_WM, cap.scenario.X_WR)
