"""The optional two-axis tilt-rotate positioner (``robot.positioner``): a KUKA DKP / ABB IRBP A style unit on the
floor, the part clamped on its faceplate (docs/positioner.md).

The part's pose on the faceplate is the map's placement at the positioner's home (``map.X_WM`` with the axes at
``home_deg``): the cell is told where the part lies as it always is, and the clamp holds it there.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from pydantic import model_validator

from cell.geometry import FloatArray, invert, make_pose, rot_z
from cell.scenario.base import Angle, Model, NonNeg, Point3, Pos
from cell.types.positioner import PositionerAxis, TiltRotatePositioner

TILT_MAX_DEG = 180.0  # [deg] no tilt axis turns further either way
ROTATE_MAX_DEG = 720.0  # [deg] a rotate axis may turn twice either way (an endless one is written as +-720)


class AxisSpec(Model):
    """One positioner axis: software limits [deg], speed [deg/s], acceleration [deg/s^2], jerk [deg/s^3]."""

    min_deg: float
    max_deg: float
    speed_deg_s: Pos = 90.0
    accel_deg_s2: Pos = 180.0
    jerk_deg_s3: Pos = 900.0

    def axis(self, name: str) -> PositionerAxis:
        return PositionerAxis(
            name,
            math.radians(self.min_deg),
            math.radians(self.max_deg),
            math.radians(self.speed_deg_s),
            math.radians(self.accel_deg_s2),
            math.radians(self.jerk_deg_s3),
        )


class PositionerSpec(Model):
    """A tilt-rotate positioner: where its base stands on the floor (``base_xyz_m``, turned ``base_yaw_deg`` about
    the vertical; the tilt axis runs along its x), the tilt axis's height and the faceplate's offset from it [mm],
    the faceplate's diameter [mm], the two axes, home, rated payload [kg], repeatability [mm], each axis's rated
    torque [N m] and the part's density [kg/m^3]."""

    type: Literal["tilt-rotate"] = "tilt-rotate"
    base_xyz_m: Point3  # the base's origin in the world (on the floor, under the tilt axis) [m]
    base_yaw_deg: Angle = 0.0  # the base turned about the vertical [deg]: the tilt axis along its x
    tilt_height_mm: Pos = 800.0  # the tilt axis above the base's origin [mm]
    faceplate_offset_mm: float = 100.0  # the clamping surface from the tilt axis along the rotate axis [mm]
    faceplate_diameter_mm: Pos = 600.0
    tilt: AxisSpec = AxisSpec(min_deg=-135.0, max_deg=135.0, speed_deg_s=90.0)
    rotate: AxisSpec = AxisSpec(min_deg=-360.0, max_deg=360.0, speed_deg_s=120.0)
    home_deg: tuple[Angle, Angle] = (0.0, 0.0)  # (tilt, rotate) where the part is loaded and scanned
    payload_kg: Pos = 400.0
    repeatability_mm: NonNeg = 0.1  # a point on the faceplate, one sigma, after a move
    tilt_torque_nm: Pos = 1100.0  # the tilt axis's rated static torque [N m] (a DKP-400 class unit)
    rotate_torque_nm: Pos = 650.0  # the rotate axis's [N m]
    part_density_kg_m3: Pos = 7850.0  # the part's material (steel), for its mass from its volume

    @model_validator(mode="after")
    def _check(self) -> PositionerSpec:
        for name, lo, hi in (("tilt", -TILT_MAX_DEG, TILT_MAX_DEG), ("rotate", -ROTATE_MAX_DEG, ROTATE_MAX_DEG)):
            ax: AxisSpec = getattr(self, name)
            if not lo <= ax.min_deg < ax.max_deg <= hi:
                raise ValueError(
                    f"robot.positioner.{name}: need {lo:g} <= min_deg < max_deg <= {hi:g}, "
                    f"got [{ax.min_deg:g}, {ax.max_deg:g}]"
                )
        t, r = self.home_deg
        if not (self.tilt.min_deg <= t <= self.tilt.max_deg and self.rotate.min_deg <= r <= self.rotate.max_deg):
            raise ValueError(f"robot.positioner.home_deg {list(self.home_deg)} is outside the axes' limits")
        if abs(self.faceplate_offset_mm) >= 2000.0:
            raise ValueError(f"robot.positioner.faceplate_offset_mm {self.faceplate_offset_mm:g}: within +-2000 mm")
        return self

    def X_WP(self) -> FloatArray:
        """(4, 4): the base in the world (upright, turned about the vertical)."""
        return make_pose(rot_z(math.radians(self.base_yaw_deg)), self.base_xyz_m)

    def positioner(self, X_WR: FloatArray) -> TiltRotatePositioner:
        """The positioner as a value in R, SI units."""
        return TiltRotatePositioner(
            np.asarray(invert(np.asarray(X_WR, dtype=float)) @ self.X_WP(), dtype=float),
            self.tilt_height_mm / 1000.0,
            self.faceplate_offset_mm / 1000.0,
            self.faceplate_diameter_mm / 2000.0,
            self.tilt.axis("tilt"),
            self.rotate.axis("rotate"),
            (math.radians(self.home_deg[0]), math.radians(self.home_deg[1])),
            self.payload_kg,
            self.repeatability_mm / 1000.0,
            self.tilt_torque_nm,
            self.rotate_torque_nm,
        )
