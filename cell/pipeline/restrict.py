"""A detection narrowed to some of its seams (a second side's: the seams its turn exposed)."""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import replace

from cell.pipeline.evaluation import evaluate
from cell.pipeline.records import Detection


def restricted(det: Detection, ids: Collection[str]) -> Detection:
    """The detection of only the seams ``ids`` (a second side's): their estimates, truths and metrics."""
    keep = set(ids)
    estimates = tuple(e for e in det.estimates if e.id in keep)
    truths = {k: v for k, v in det.truths.items() if k in keep}
    _, summary = evaluate(estimates, truths)
    metrics = {k: v for k, v in det.metrics.items() if k in keep}
    return replace(det, estimates=estimates, truths=truths, metrics=metrics, summary=summary)
