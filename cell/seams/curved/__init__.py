"""Curved seams located in the cloud: the two surfaces a curved seam lies on fitted locally (a cylinder, a plane),
intersected, sampled, with a sigma across the seam at every sample (docs/curves.md)."""

from cell.seams.curved.locate import CURVE_METHODS, locate_curves

__all__ = ["CURVE_METHODS", "locate_curves"]
