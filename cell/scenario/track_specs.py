"""The optional linear track under the robot base (``robot.track``): an external axis E1, a KUKA KL-style unit.

E1 = 0 is where the base stands in ``robot.X_WR`` (frame R: capture, re-scan and home happen there); the base
moves along ``axis_W`` between ``min_mm`` and ``max_mm``. docs/track.md tells how it is planned.
"""

from __future__ import annotations

import numpy as np
from pydantic import model_validator

from cell.geometry import FloatArray
from cell.scenario.base import Model, Pos, Vec3
from cell.types.track import LinearTrack


class TrackSpec(Model):
    """A linear track: direction in the world, E1 limits about the base's place in X_WR [mm], and the carriage's
    speed [mm/s], acceleration [mm/s^2] and jerk [mm/s^3] limits."""

    axis_W: Vec3 = (1.0, 0.0, 0.0)  # the direction the base moves in, in the world (made a unit vector)
    min_mm: float = -1000.0  # E1's negative software limit [mm] (<= 0)
    max_mm: float = 1000.0  # E1's positive software limit [mm] (>= 0)
    speed_mm_s: Pos = 500.0  # the carriage's speed limit [mm/s]
    accel_mm_s2: Pos = 1000.0  # its acceleration limit [mm/s^2]
    jerk_mm_s3: Pos = 5000.0  # its jerk limit [mm/s^3]

    @model_validator(mode="after")
    def _check(self) -> TrackSpec:
        if not self.min_mm <= 0.0 <= self.max_mm or self.min_mm == self.max_mm:
            raise ValueError(
                f"robot.track: min_mm {self.min_mm} <= 0 <= max_mm {self.max_mm} (E1 = 0 is the base at X_WR), "
                "and the two must differ"
            )
        if sum(v * v for v in self.axis_W) < 1e-12:
            raise ValueError("robot.track.axis_W must not be zero: the direction the base moves in the world")
        return self

    def track(self, X_WR: FloatArray) -> LinearTrack:
        """The track as a value in R (the base at E1 = 0), SI units."""
        axis_R = np.asarray(X_WR, dtype=float)[:3, :3].T @ np.asarray(self.axis_W, dtype=float)
        return LinearTrack(
            axis_R,
            self.min_mm / 1000.0,
            self.max_mm / 1000.0,
            self.speed_mm_s / 1000.0,
            self.accel_mm_s2 / 1000.0,
            self.jerk_mm_s3 / 1000.0,
        )
