"""Torch paths along curved seams (arcs, circles, ellipses, saddles, free curves): the located curve resampled and
the torch posed along it, the search for its start, direction and spin, its timing and its place in the plan.
The planner's entry is :func:`cell.planning.plan.plan_welds` with ``curves`` (located :class:`CurveEstimate` s)."""

from cell.planning.curves.path import CurvePath, curve_path, curve_poses
from cell.planning.curves.plan import (
    arc_spans,
    cover_curves,
    curve_procedures,
    in_part,
    weldable,
    whole_or_none,
    with_paths,
)
from cell.planning.curves.search import CurveTask, plan_curve
from cell.planning.curves.timing import curve_pieces, curve_trajectory

__all__ = [
    "CurvePath",
    "CurveTask",
    "arc_spans",
    "cover_curves",
    "curve_path",
    "curve_pieces",
    "curve_poses",
    "curve_procedures",
    "curve_trajectory",
    "in_part",
    "plan_curve",
    "weldable",
    "whole_or_none",
    "with_paths",
]
