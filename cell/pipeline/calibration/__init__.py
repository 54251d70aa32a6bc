"""``cell calibrate``: the board shown to every camera asked for, the images taken, each camera's pose solved
(:mod:`cell.calibrate`). The fixed cameras see the board on the flange as the arm carries it through poses planned
for good conditioning; the arm's camera sees it lying on the table from poses the arm holds it at. Every pose is
reached by IK and kept clear of the cell before it is taken (:mod:`.images`); the board must be found (most of its
corners) or the pose is skipped. The solve from the images is :mod:`.run`."""

from cell.pipeline.calibration.images import depth_at
from cell.pipeline.calibration.run import OPENCV_METHODS, CalibrationRun, calibrate, calibrate_capture, solve_camera

__all__ = ["OPENCV_METHODS", "CalibrationRun", "calibrate", "calibrate_capture", "depth_at", "solve_camera"]
