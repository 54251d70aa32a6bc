"""Checks that turn faults into reasons, one module each (this module keeps their old import path):

- :mod:`cell.perception.camera_health`: is a camera's data fit to splice (run by perception before splicing)?
- :mod:`cell.perception.alignment_checks`: does the map, as aligned, lie where the part is in the cloud?
- :mod:`cell.perception.seam_screen`: which seams the locator found must not be welded (missing part, occluded,
  too uncertain)?
"""

from cell.perception.alignment_checks import (
    Alternative,
    SymmetryOptions,
    alignment_alternatives,
    check_alignment_unique,
    check_parts_seen,
    missing_parts,
    part_coverage,
)
from cell.perception.camera_health import HealthOptions, ImageHealth, agreement, disagreeing_cameras, image_health
from cell.perception.seam_screen import ScreenOptions, foreign_points, screen

__all__ = [
    "Alternative",
    "HealthOptions",
    "ImageHealth",
    "ScreenOptions",
    "SymmetryOptions",
    "agreement",
    "alignment_alternatives",
    "check_alignment_unique",
    "check_parts_seen",
    "disagreeing_cameras",
    "foreign_points",
    "image_health",
    "missing_parts",
    "part_coverage",
    "screen",
]
