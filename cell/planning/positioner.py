"""What a positioner would take for the operator's turn: the same rotation made by one positioner axis, timed as a
jerk-limited rest-to-rest move (Ruckig), the part still clamped (docs/cycle.md, "The turn"). Angles [rad]; time [s]."""

from __future__ import annotations

import math

import numpy as np

from cell.config.motion import PositionerFigures
from cell.motion.limits import JointLimits
from cell.motion.timing import ptp_duration


def positioner_turn_s(angle_rad: float, figures: PositionerFigures | None = None) -> float:
    """[s]: a positioner axis turning through ``angle_rad`` (either sign) from rest to rest at ``figures``'s limits."""
    f = figures or PositionerFigures()
    axis = JointLimits(
        ("turn",),
        np.array([-2.0 * math.pi]),
        np.array([2.0 * math.pi]),
        np.array([f.speed]),
        np.array([f.accel]),
        np.array([f.jerk]),
    )
    return ptp_duration(np.zeros(1), np.array([abs(angle_rad)]), axis)
