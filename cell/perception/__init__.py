"""Perception (paper sections 3.2-3.5): depth images -> spliced, filtered clouds in R -> map aligned to them.

The only part of the cell that uses open3d, and only through :mod:`cell.perception._open3d` (imported lazily).
"""

from cell.perception.align.checks import (
    Alternative,
    SymmetryOptions,
    alignment_alternatives,
    check_alignment,
    check_alignment_unique,
    check_parts_seen,
    missing_parts,
    part_coverage,
)
from cell.perception.align.fit import Alignment, align_map, sample_map
from cell.perception.camera_health import HealthOptions, ImageHealth, agreement, disagreeing_cameras, image_health
from cell.perception.deproject import clouds_in_robot_frame, crop, deproject
from cell.perception.perceive import Perceived, perceive
from cell.perception.ply import load_ply, save_ply
from cell.perception.preprocess import downsample, preprocess
from cell.perception.seam_screen import ScreenOptions, foreign_points, screen
from cell.perception.splicing.decision import Registration
from cell.perception.splicing.splice import Spliced, splice

__all__ = [
    "Alignment",
    "Alternative",
    "HealthOptions",
    "ImageHealth",
    "Perceived",
    "Registration",
    "ScreenOptions",
    "Spliced",
    "SymmetryOptions",
    "agreement",
    "align_map",
    "alignment_alternatives",
    "check_alignment",
    "check_alignment_unique",
    "check_parts_seen",
    "clouds_in_robot_frame",
    "crop",
    "deproject",
    "disagreeing_cameras",
    "downsample",
    "foreign_points",
    "image_health",
    "load_ply",
    "missing_parts",
    "part_coverage",
    "perceive",
    "preprocess",
    "sample_map",
    "save_ply",
    "screen",
    "splice",
]
