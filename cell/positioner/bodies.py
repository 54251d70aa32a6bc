"""The positioner's bodies as boxes in R, for the simulator to render and the collision model to miss
(docs/positioner.md, "Bodies"): the pedestal under the tilt axis (still), the cradle from the tilt axis to the
faceplate (tilts) and the faceplate (tilts and rotates; a square as wide as its diameter). Lengths [m]."""

from __future__ import annotations

import numpy as np

from cell.geometry import make_pose
from cell.types import Box, Part
from cell.types.positioner import TiltRotatePositioner

PEDESTAL = "POSITIONER_BASE"
CRADLE = "POSITIONER_CRADLE"
FACEPLATE = "POSITIONER_FACEPLATE"
PLATE_M = 0.03  # [m] the faceplate's thickness
CLEAR_M = 0.10  # [m] the pedestal stops this far below the lowest point the faceplate's disc sweeps


def positioner_parts(pos: TiltRotatePositioner, tilt: float, rotate: float) -> tuple[Part, ...]:
    """The pedestal, the cradle and the faceplate as boxes in R with the axes at (tilt, rotate) [rad]."""
    r, d = pos.faceplate_radius_m, pos.faceplate_offset_m
    top = max(pos.tilt_height_m - r - CLEAR_M, 0.1)  # the pedestal's top: below the disc's sweep
    pedestal = Box(pos.X_RP @ make_pose(p=(0.0, 0.0, top / 2.0)), np.array([0.35, 0.35, top]))
    X_T = pos.X_R_tilt(tilt)
    cradle_len = max(abs(d) - PLATE_M, 0.02)
    sign = 1.0 if d >= 0.0 else -1.0
    cradle = Box(X_T @ make_pose(p=(0.0, 0.0, sign * cradle_len / 2.0)), np.array([0.25, 0.25, cradle_len]))
    plate = Box(pos.X_R_F(tilt, rotate) @ make_pose(p=(0.0, 0.0, -PLATE_M / 2.0)), np.array([2 * r, 2 * r, PLATE_M]))
    return Part(PEDESTAL, pedestal), Part(CRADLE, cradle), Part(FACEPLATE, plate)
