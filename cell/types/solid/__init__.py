"""A part's solid body as planar polygon faces: the :class:`Polyhedron` (inside tests, face planes, segments
crossing it), its faces' planes and triangles (:mod:`.faces`) and point-to-triangle distances (:mod:`.near`).
Frames: whatever frame the vertices are given in [m]; numpy only."""

from cell.types.solid.near import pair_distance, within
from cell.types.solid.polyhedron import Polyhedron

__all__ = ["Polyhedron", "pair_distance", "within"]
