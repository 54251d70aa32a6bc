"""Options of every stage, as small frozen dataclasses with their defaults: what a scenario can set. One module per
stage; stdlib and numpy only, nothing of the project but :mod:`cell.errors` (an import-linter contract), so the
scenario composes them and every stage imports its options from here without a cycle."""

from cell.config.bounds import Bounds, check_bounds
from cell.config.export import KrlOptions
from cell.config.motion import STICKOUT_MM, CollisionOptions, GateOptions, IKOptions, PlanOptions, ViewOptions
from cell.config.perception import CoverageOptions, HealthOptions, ScreenOptions, SymmetryOptions
from cell.config.rescan import CLOSEUP_OURS_OPTIONS, CLOSEUP_TARGET_SE_M, CONFIDENCE_THRESHOLD, RescanOptions
from cell.config.seams import (
    INDEX_SHARES,
    PART_TOLERANCE_M,
    OursSettings,
    PaperOptions,
    RansacOptions,
    RansacThresholds,
)
from cell.config.sim import BeadStyle

__all__ = [
    "CLOSEUP_OURS_OPTIONS",
    "CLOSEUP_TARGET_SE_M",
    "CONFIDENCE_THRESHOLD",
    "INDEX_SHARES",
    "PART_TOLERANCE_M",
    "STICKOUT_MM",
    "BeadStyle",
    "Bounds",
    "CollisionOptions",
    "CoverageOptions",
    "GateOptions",
    "HealthOptions",
    "IKOptions",
    "KrlOptions",
    "OursSettings",
    "PaperOptions",
    "PlanOptions",
    "RansacOptions",
    "RansacThresholds",
    "RescanOptions",
    "ScreenOptions",
    "SymmetryOptions",
    "ViewOptions",
    "check_bounds",
]
