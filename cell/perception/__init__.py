"""Perception (paper sections 3.2-3.5): depth images -> spliced, filtered clouds in R -> map aligned to them.

The only part of the cell that uses open3d, and only through :mod:`cell.perception._open3d` (imported lazily).
"""

from cell.perception.align import Alignment, align_map, sample_map
from cell.perception.deproject import clouds_in_robot_frame, crop, deproject
from cell.perception.perceive import Perceived, perceive
from cell.perception.ply import load_ply, save_ply
from cell.perception.preprocess import downsample, preprocess
from cell.perception.splice import Registration, Spliced, splice

__all__ = [
    "Alignment",
    "Perceived",
    "Registration",
    "Spliced",
    "align_map",
    "clouds_in_robot_frame",
    "crop",
    "deproject",
    "downsample",
    "load_ply",
    "perceive",
    "preprocess",
    "sample_map",
    "save_ply",
    "splice",
]
