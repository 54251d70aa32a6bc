"""A part on a tilt-rotate positioner welded (docs/positioner.md): scanned and located at home, the seams grouped by
positioner pose, each group's located seams carried into its pose by the kinematics, planned, gated and welded
there; no operator turn."""

from cell.pipeline.positioned.job import weld_on_positioner
from cell.pipeline.positioned.run import PositionerRun

__all__ = ["PositionerRun", "weld_on_positioner"]
