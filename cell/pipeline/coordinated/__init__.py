"""Curved seams welded on a positioner by coordinated motion (docs/positioner.md, "Coordinated motion"): planned
and gated by :mod:`cell.coordinated`, played in the simulator with the part turning, measured in the part's frame."""

from cell.pipeline.coordinated.job import weld_curves_coordinated

__all__ = ["weld_curves_coordinated"]
