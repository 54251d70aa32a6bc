"""The positioner's bodies as boxes in R, for the simulator to render and the collision model to miss
(docs/positioner.md, "Bodies"): the pedestal under the tilt axis (still), the cradle from the tilt axis to the
faceplate (tilts) and the faceplate (tilts and rotates; a square as wide as its diameter). Lengths [m]."""

from __future__ import annotations

import math

import numpy as np

from cell.geometry import make_pose
from cell.types import Box, Part
from cell.types.positioner import TiltRotatePositioner

PEDESTAL = "POSITIONER_BASE"
CRADLE = "POSITIONER_CRADLE"
FACEPLATE = "POSITIONER_FACEPLATE"
PLATE_M = 0.03  # [m] the faceplate's thickness
CLEAR_M = 0.10  # [m] the pedestal stops this far below the lowest point the tilting bodies sweep
CRADLE_M = 0.12  # [m] the block under a faceplate that hangs below the tilt axis


def positioner_parts(pos: TiltRotatePositioner, tilt: float, rotate: float) -> tuple[Part, ...]:
    """The pedestal, the cradle and the faceplate as boxes in R with the axes at (tilt, rotate) [rad]. The cradle
    joins the tilt axis to the faceplate's back when the faceplate stands above the axis; when it hangs below it (a
    drop centre, the part's weight near the axis) it is a block under the faceplate (the side arms left out)."""
    r, d = pos.faceplate_radius_m, pos.faceplate_offset_m
    back = d - PLATE_M  # the faceplate's back along the rotate axis from the tilt axis
    lo, hi = (0.0, back) if back > 0.02 else (back - CRADLE_M, back)
    sweep = math.hypot(r, max(abs(lo), abs(hi)))  # how far below the axis the tilting bodies reach
    top = max(pos.tilt_height_m - sweep - CLEAR_M, 0.1)  # the pedestal's top: below that sweep
    pedestal = Box(pos.X_RP @ make_pose(p=(0.0, 0.0, top / 2.0)), np.array([0.35, 0.35, top]))
    X_T = pos.X_R_tilt(tilt)
    cradle = Box(X_T @ make_pose(p=(0.0, 0.0, (lo + hi) / 2.0)), np.array([0.25, 0.25, hi - lo]))
    plate = Box(pos.X_R_F(tilt, rotate) @ make_pose(p=(0.0, 0.0, -PLATE_M / 2.0)), np.array([2 * r, 2 * r, PLATE_M]))
    return Part(PEDESTAL, pedestal), Part(CRADLE, cradle), Part(FACEPLATE, plate)
