"""What a cell is: the map and its placement, the part as built, the table, the robot, the cameras and their
sensor model, the workspace. Lengths in metres (``_m``) or millimetres (``_mm``), angles in degrees (``_deg``)."""

from __future__ import annotations

import math
from typing import Annotated, Literal

import numpy as np
from pydantic import Field, model_validator

from cell.config import STICKOUT_MM
from cell.geometry import FloatArray, look_at, pose_from_xyz_rpy
from cell.scenario.base import Angle, Angles3, Model, NonNeg, Point3, Pos, Vec3
from cell.scenario.layer_specs import LayerSpec
from cell.scenario.positioner_specs import PositionerSpec
from cell.scenario.track_specs import TrackSpec


class PoseSpec(Model):
    """A pose given as translation [m] and fixed-axis roll, pitch, yaw [deg]."""

    xyz_m: Point3 = (0.0, 0.0, 0.0)
    rpy_deg: Angles3 = (0.0, 0.0, 0.0)

    @property
    def X(self) -> FloatArray:
        return pose_from_xyz_rpy(self.xyz_m, np.radians(self.rpy_deg))


class MapSpec(Model):
    """The welding map: a DXF file (relative to the scenario file) and where its origin sits in the world."""

    file: str
    units: Literal["mm", "cm", "m", "in"] | None = None  # the DXF's units; wins over its $INSUNITS, with a warning
    layers: LayerSpec = LayerSpec()  # which layers hold parts, fixtures (obstacles) and seams: docs/maps.md
    X_WM: PoseSpec = PoseSpec()  # nominal placement of the drawing on the table (what the cell is told)


class Deviation(Model):
    """How one part was built differently from the drawing (as-built minus designed), in the part's own frame."""

    size_mm: Vec3 = (0.0, 0.0, 0.0)
    offset_mm: Vec3 = (0.0, 0.0, 0.0)
    rpy_deg: Vec3 = (0.0, 0.0, 0.0)
    # Bent in an arc of this sagitta [mm] over its length, as ``simulation.bow: {part, mm}`` (docs/bodies.md section 7)
    bow_mm: Annotated[float, Field(ge=-20.0, le=20.0)] = 0.0


class TableSpec(Model):
    """The welding table, a box: centre and size in the world [m]."""

    center_m: Point3
    size_m: tuple[Pos, Pos, Pos]

    @property
    def top_z(self) -> float:
        return self.center_m[2] + self.size_m[2] / 2.0

    def holds(self, p_W: Vec3) -> bool:
        """Whether the world point lies inside the table's box."""
        return all(abs(p_W[k] - self.center_m[k]) < self.size_m[k] / 2.0 for k in range(3))


class RobotSpec(Model):
    """Which robot and where its base stands (X_WR = pose of the robot base frame R in the world)."""

    urdf: str | None = None  # relative to the repository's robots/ folder; None: no arm in the cell
    X_WR: PoseSpec = PoseSpec()
    home_deg: tuple[Angle, ...] | None = None  # A1..An [deg]; each also within its joint's limits (the URDF's)
    # Wire stick-out [mm] beyond the contact tip in the URDF's torch_tcp (robots/build_kr5_arc.py STICKOUT): the
    # torch planner stands the TCP off the seam by contact_tip_distance_mm minus this (0 by default).
    stickout_mm: Pos = STICKOUT_MM
    track: TrackSpec | None = None  # a linear track (external axis E1) under the base: docs/track.md
    positioner: PositionerSpec | None = None  # a tilt-rotate positioner holding the part: docs/positioner.md


class NoiseSpec(Model):
    """Depth sensor model (docs/reference.md section 2). ``active_stereo`` follows the RealSense D4xx error model."""

    model: Literal["none", "active_stereo", "structured_light"] = "active_stereo"
    baseline_m: Pos = 0.055  # D415 [m]
    subpixel_px: NonNeg = 0.08  # RMS subpixel disparity error [px]
    disparity_step_px: NonNeg = 1.0 / 32.0  # disparity quantisation [px]
    depth_unit_m: NonNeg = 0.0001  # depth output quantisation [m]
    edge_invalid_fraction: Annotated[float, Field(ge=0.0, le=1.0)] = 0.09  # at depth discontinuities
    edge_flying_fraction: Annotated[float, Field(ge=0.0, le=1.0)] = 0.5  # of those, how many come back mixed
    edge_jump_m: Pos = 0.02  # depth step that counts as a discontinuity [m]
    grazing_dropout_deg: Annotated[float, Field(gt=0.0, le=90.0)] = 80.0  # incidence beyond which pixels drop
    colour_sigma: NonNeg = 2.0  # the colour image's pixel noise, RMS [grey levels of 255]
    colour_blur_px: NonNeg = 0.7  # the lens' blur of the colour image, a Gaussian's sigma [px]


class ExtrinsicErrorSpec(Model):
    """Calibration error of a camera pose: magnitudes, directions drawn from the scenario seed."""

    translation_mm: NonNeg = 0.0
    rotation_deg: NonNeg = 0.0


class CalibrationSpec(Model):
    """How well a camera's pose is known: the residual of its calibration as a calibration report states it (RMS of
    the whole error, translation and rotation). What the cell is told, not what the simulation draws
    (``extrinsic_error``). It is the prior on the camera's pose when the splice registers it (:mod:`cell.perception.
    pose_prior`: a correction only where the data outweigh it, a disagreement beyond three of its sigmas drops the
    camera), and a seam seen by this camera alone carries it in its sigma (:mod:`cell.perception.calibration`);
    0 (the default) says the calibration is within the locator's own floor: the camera is never moved."""

    translation_mm: NonNeg = 0.0
    rotation_deg: NonNeg = 0.0


class DistortionSpec(Model):
    """A lens' Brown-Conrady distortion (OpenCV's k1, k2, p1, p2, k3 on normalised image coordinates): radial
    (k1, k2, k3) and tangential (p1, p2). All zero (the default): a pinhole."""

    k1: float = 0.0
    k2: float = 0.0
    p1: float = 0.0
    p2: float = 0.0
    k3: float = 0.0

    @property
    def coefficients(self) -> tuple[float, float, float, float, float]:
        return (self.k1, self.k2, self.p1, self.p2, self.k3)


class SensorErrorSpec(Model):
    """How a simulated camera's own model is off what it states (what only a simulation knows; a calibration's
    intrinsics check and every run's table check look for it): its depth reads ``depth_scale`` times the true
    depth, its true focal length is ``focal_scale`` times the stated one."""

    depth_scale: Annotated[float, Field(gt=0.5, lt=2.0)] = 1.0
    focal_scale: Annotated[float, Field(gt=0.5, lt=2.0)] = 1.0


class CameraSpec(Model):
    """A depth camera looking from ``eye_m`` at ``target_m`` (world) with a pinhole of the given size and field."""

    mount: Literal["fixed", "eye_in_hand"] = "fixed"
    eye_m: Point3
    target_m: Point3
    up: Vec3 = (0.0, 0.0, 1.0)
    resolution: tuple[Annotated[int, Field(ge=16, le=4096)], Annotated[int, Field(ge=16, le=4096)]] = (
        1280,
        720,
    )
    hfov_deg: Annotated[float, Field(gt=1.0, lt=170.0)] = 65.0
    near_m: Annotated[float, Field(ge=0.05)] = 0.1
    far_m: Pos = 4.0
    noise: NoiseSpec = NoiseSpec()
    extrinsic_error: ExtrinsicErrorSpec = ExtrinsicErrorSpec()
    calibration: CalibrationSpec = CalibrationSpec()
    # The pose a calibration measured (``cell calibrate``, applied with ``--calibration``): a fixed camera's X_RC
    # in the robot base frame, the arm camera's X_FC in the flange frame tool0. Given, the cell is told this pose
    # (a simulation renders from eye_m/target_m still, and its extrinsic_error no longer applies).
    measured: PoseSpec | None = None
    # The lens: a simulation renders through it, and the cell undistorts with it, unless a calibration measured
    # another (``measured_distortion``, applied with ``--calibration``): then the cell is told that one.
    distortion: DistortionSpec = DistortionSpec()
    measured_distortion: DistortionSpec | None = None
    sensor_error: SensorErrorSpec = SensorErrorSpec()

    @model_validator(mode="after")
    def _check(self) -> CameraSpec:
        if self.far_m <= self.near_m:
            raise ValueError(f"far_m ({self.far_m}) must be greater than near_m ({self.near_m})")
        if math.dist(self.eye_m, self.target_m) < 1e-6:
            raise ValueError("eye_m and target_m coincide")
        return self

    @property
    def X_WC(self) -> FloatArray:
        """True pose of the optical frame in the world."""
        return look_at(self.eye_m, self.target_m, self.up)

    @property
    def told_distortion(self) -> tuple[float, float, float, float, float]:
        """The lens model the cell is told: the calibration's when there is one, else the stated."""
        return (self.measured_distortion or self.distortion).coefficients

    @property
    def fx_px(self) -> float:
        return 0.5 * self.resolution[0] / math.tan(math.radians(self.hfov_deg) / 2.0)


class WorkspaceSpec(Model):
    """Passthrough crop in the world [m]: only points inside this box are kept (paper eq. 2)."""

    min_m: Point3
    max_m: Point3

    @model_validator(mode="after")
    def _check(self) -> WorkspaceSpec:
        if any(lo >= hi for lo, hi in zip(self.min_m, self.max_m, strict=True)):
            raise ValueError(f"workspace min_m {self.min_m} must be below max_m {self.max_m} on every axis")
        return self
