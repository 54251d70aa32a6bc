"""Calibrating the cell (docs/calibration.md): a ChArUco board seen by every camera, the fixed cameras' poses in the
robot frame (the board on the flange) and the arm camera's on the flange (the board on the table), each with its
covariance, held-out residuals, and the checks that refuse a degenerate pose set or a board of the wrong size.
Values in, values out: the pipeline (:mod:`cell.pipeline.calibration`) moves the arm and takes the images."""

from typing import Literal

HandEyeMethod = Literal["park", "tsai", "daniilidis"]  # OpenCV's calibrateHandEye methods the cell runs

__all__ = ["HandEyeMethod"]
