"""A two-axis tilt-rotate positioner (KUKA DKP, ABB IRBP A style) as a value, numpy only, with its forward kinematics.

Frames (docs/positioner.md, "Frames"): P is the positioner's base (z up, the tilt axis along its x at height
``tilt_height_m``); F is the faceplate (origin at the centre of its clamping surface, z out of it, along the rotate
axis). X_P_F(tilt, rotate) = Trans(0, 0, h) Rx(tilt) Trans(0, 0, d) Rz(rotate): at tilt 0 the faceplate faces up.
Angles [rad], lengths [m], speeds [rad/s], accelerations [rad/s^2], jerks [rad/s^3].
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from cell.geometry import FloatArray, make_pose, readonly, rot_x, rot_z


@dataclass(frozen=True)
class PositionerAxis:
    """One axis: its name (``tilt``, ``rotate``), software limits [q_min, q_max] [rad], speed, acceleration and
    jerk limits."""

    name: str
    q_min: float
    q_max: float
    v_max: float
    a_max: float
    j_max: float

    def __post_init__(self) -> None:
        if not self.q_min < self.q_max:
            raise ValueError(f"positioner {self.name}: limits [{self.q_min}, {self.q_max}] rad must be increasing")
        if min(self.v_max, self.a_max, self.j_max) <= 0.0:
            raise ValueError(f"positioner {self.name}: speed, acceleration and jerk limits must be positive")

    def contains(self, q: float, tol: float = 1e-9) -> bool:
        return self.q_min - tol <= q <= self.q_max + tol


@dataclass(frozen=True)
class TiltRotatePositioner:
    """The positioner in the robot frame R.

    X_RP : (4, 4) its base in R (upright: its z is the world's up). tilt_height_m : the tilt axis above P's
    origin. faceplate_offset_m : the clamping surface from the tilt axis along the rotate axis (negative: below
    it). faceplate_radius_m : the faceplate's radius (its body, for rendering and collisions). tilt, rotate : the
    two axes. home : (tilt, rotate) where the part is loaded and scanned [rad]. payload_kg : the rated payload.
    repeatability_m : how far a point on the faceplate lands from where the kinematics put it (one sigma).
    tilt_torque_nm, rotate_torque_nm : each axis's rated torque [N m].
    """

    X_RP: FloatArray
    tilt_height_m: float
    faceplate_offset_m: float
    faceplate_radius_m: float
    tilt: PositionerAxis
    rotate: PositionerAxis
    home: tuple[float, float] = (0.0, 0.0)
    payload_kg: float = 400.0
    repeatability_m: float = 0.0001
    tilt_torque_nm: float = 1100.0  # the tilt axis's rated static torque [N m]
    rotate_torque_nm: float = 650.0  # the rotate axis's [N m]

    def __post_init__(self) -> None:
        X = np.asarray(self.X_RP, dtype=float)
        if X.shape != (4, 4) or not np.all(np.isfinite(X)):
            raise ValueError("TiltRotatePositioner: X_RP must be a finite (4, 4) pose")
        object.__setattr__(self, "X_RP", readonly(X))
        if not (self.tilt.contains(self.home[0]) and self.rotate.contains(self.home[1])):
            raise ValueError(f"TiltRotatePositioner: home {self.home} rad is outside the axes' limits")
        if self.faceplate_radius_m <= 0.0 or self.payload_kg <= 0.0 or self.repeatability_m < 0.0:
            raise ValueError("TiltRotatePositioner: faceplate radius and payload must be positive")

    def X_P_F(self, tilt: float, rotate: float) -> FloatArray:
        """(4, 4): the faceplate in the base frame P at the axis values (tilt, rotate) [rad]."""
        up = make_pose(p=(0.0, 0.0, self.tilt_height_m))
        out = make_pose(p=(0.0, 0.0, self.faceplate_offset_m))
        return up @ make_pose(rot_x(tilt)) @ out @ make_pose(rot_z(rotate))

    def X_R_F(self, tilt: float, rotate: float) -> FloatArray:
        """(4, 4): the faceplate in R at (tilt, rotate) [rad]."""
        return np.asarray(self.X_RP @ self.X_P_F(tilt, rotate), dtype=float)

    def X_R_tilt(self, tilt: float) -> FloatArray:
        """(4, 4): the tilting body's frame in R (on the tilt axis, z along the rotate axis) at ``tilt`` [rad]."""
        return np.asarray(self.X_RP @ make_pose(p=(0.0, 0.0, self.tilt_height_m)) @ make_pose(rot_x(tilt)), float)

    def move(self, tilt: float, rotate: float, start: tuple[float, float] | None = None) -> FloatArray:
        """(4, 4) X_R_new_old: the rigid motion in R that carries whatever is clamped on the faceplate from the axis
        values ``start`` (default: home) to (tilt, rotate)."""
        t0, r0 = self.home if start is None else start
        return np.asarray(self.X_R_F(tilt, rotate) @ np.linalg.inv(self.X_R_F(t0, r0)), dtype=float)

    def up_F(self, tilt: float, rotate: float) -> FloatArray:
        """(3,): the world's up (against gravity) seen in F at (tilt, rotate): (sin t sin r, sin t cos r, cos t)
        when P stands upright."""
        R_RF = self.X_R_F(tilt, rotate)[:3, :3]
        return np.asarray(R_RF.T @ self.up_R, dtype=float)

    @property
    def up_R(self) -> FloatArray:
        """(3,): the world's up in R (P's z: the positioner stands upright)."""
        return np.asarray(self.X_RP[:3, 2], dtype=float)

    def within(self, tilt: float, rotate: float) -> bool:
        return self.tilt.contains(tilt) and self.rotate.contains(rotate)


def wrap_near(angle: float, ref: float) -> float:
    """``angle`` plus the whole turns that bring it nearest to ``ref`` [rad]."""
    return angle + 2.0 * math.pi * round((ref - angle) / (2.0 * math.pi))


@dataclass(frozen=True)
class WeldPosition:
    """A seam's welding position by ISO 6947 (docs/positioner.md, "ISO 6947"): its code (``PA``, ``PB``, ``PD``,
    ``PE``, ``PF``, ``PG``), slope S and rotation R [deg], the worst over its waypoints against the position asked
    (``target``), and whether that worst is within the tolerance (slope within 5 deg, rotation within 10 deg)."""

    code: str
    slope_deg: float
    rotation_deg: float
    target: str = ""
    within: bool = False


@dataclass(frozen=True)
class ExternalAxes:
    """A positioner's axes as one program writes them (docs/positioner.md, "Programs"): their values for the whole
    program [deg] (the positioner stands still while the arm welds), the KRL E numbers they take (E2, E3: E1 is the
    linear track's), their limits [deg], the machine data of the kinematic chain (``MACHINE_DEF[machine]``), the
    RAPID mechanical unit, X_FB (4, 4): the program's base on the faceplate (the part's frame) [m], and
    ``via_deg``: the axes' values on the way to ``values_deg`` [deg], in order (a route that keeps the part clear
    of the arm at home; empty: the axes move straight)."""

    values_deg: tuple[float, float]
    limits_deg: tuple[tuple[float, float], tuple[float, float]]
    names: tuple[str, str] = ("tilt", "rotate")
    numbers: tuple[int, int] = (2, 3)
    machine: int = 2
    unit: str = "STN1"
    X_FB: FloatArray = field(default_factory=lambda: np.eye(4))
    via_deg: tuple[tuple[float, float], ...] = ()

    def by_number(self) -> dict[int, float]:
        """E number -> value [deg]."""
        return dict(zip(self.numbers, self.values_deg, strict=True))


def external_axes(
    pos: TiltRotatePositioner,
    tilt: float,
    rotate: float,
    X_FB: FloatArray | None = None,
    via: Sequence[tuple[float, float]] = (),
) -> ExternalAxes:
    """The positioner's axes at (tilt, rotate) [rad] as a program writes them (E2, E3; the part's base ``X_FB`` on
    the faceplate, default the faceplate's own frame; ``via``: (tilt, rotate) [rad] on the way there)."""
    lim = ((pos.tilt.q_min, pos.tilt.q_max), (pos.rotate.q_min, pos.rotate.q_max))
    return ExternalAxes(
        (math.degrees(tilt), math.degrees(rotate)),
        tuple((math.degrees(a), math.degrees(b)) for a, b in lim),  # type: ignore[arg-type]
        X_FB=np.eye(4) if X_FB is None else np.asarray(X_FB, dtype=float),
        via_deg=tuple((math.degrees(t), math.degrees(r)) for t, r in via),
    )
