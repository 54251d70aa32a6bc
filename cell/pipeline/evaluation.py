"""Measuring a detection against the truth, when the data come with one (a simulation, a ``--truth`` file)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from cell.geometry import FloatArray
from cell.types import MetricsSummary, SeamEstimate, SeamMetrics


def evaluate(
    estimates: Sequence[SeamEstimate], truth: Mapping[str, tuple[FloatArray, FloatArray]]
) -> tuple[dict[str, SeamMetrics], MetricsSummary]:
    """Per-seam metrics of the found seams and the summary (paper ME, endpoint, lateral, time); no metrics when
    there is no truth (``truth`` empty)."""
    from cell.seams.metrics import evaluate as metrics_of
    from cell.seams.metrics import summarise

    per_seam = metrics_of(estimates, truth) if truth else {}
    return per_seam, summarise(estimates, per_seam)
