"""Options of motion (:mod:`cell.motion`): the planner, its collision model, the IK solver, the safety gate and
the close-up views. Units SI (m, rad, s) unless a name says otherwise (``_deg``, ``_px``)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

# Wire stick-out [mm] beyond the contact tip in the URDF's torch_tcp (robots/build_kr5_arc.py STICKOUT): the
# scenario's robot.stickout_mm and WeldProcess.from_spec default to it.
STICKOUT_MM = 15.0


@dataclass(frozen=True)
class CollisionOptions:
    """The collision model of the arm and the obstacles (:class:`~cell.motion.collision.CollisionChecker`).

    part_inflation, table_inflation : growth of obstacle boxes on every side [m].
    tcp_clearance : torch shapes within this distance of the wire tip are cut away [m].
    max_step : most an arm point may move between two checks [m].
    min_clearance : a distance below this counts as contact [m].
    table_name : which obstacle is the table. tcp_frame : the wire tip's frame in the URDF.
    """

    part_inflation: float = 0.002
    table_inflation: float = 0.0
    tcp_clearance: float = 0.035
    max_step: float = 0.05
    min_clearance: float = 0.0
    table_name: str = "TABLE"
    tcp_frame: str = "torch_tcp"


@dataclass(frozen=True)
class IKOptions:
    """Solver settings (defaults suit a 6-axis arm of about 1.5 m reach)."""

    pos_tol: float = 1e-5  # [m] 0.01 mm
    rot_tol: float = np.radians(0.01)  # [rad] 0.01 deg
    max_iters: int = 60  # per attempt
    restarts: int = 12  # extra attempts from random configurations, only when an rng is given
    damping: float = 1e-6  # lambda^2 of the damped least squares [m^2]
    max_step: float = 0.5  # [rad] largest joint change per iteration
    restart_margin: float = np.radians(5.0)  # [rad] random restarts stay this far inside the limits


@dataclass(frozen=True)
class PlanOptions:
    """Planner settings (the cell-specific welding figures live in the scenario's ``process``)."""

    spacing: float = 0.0025  # [m] IK knots along the weld
    line_spacing: float = 0.005  # [m] IK knots along approach/depart
    spin_step: float = math.radians(45.0)  # [rad] spins tried about the torch axis
    angle_step: float = math.radians(5.0)  # [rad] widening of work/travel angles within their tolerance
    max_full: int = 4  # candidates solved along the whole seam per angle setting
    max_joint_step: float = math.radians(10.0)  # [rad] largest joint change between knots (flip)
    min_manipulability: float = 0.01  # [m^3] below this a Cartesian move counts as singular
    weld_accel: float = 0.5  # [m/s^2] path acceleration of the weld ramps
    weld_jerk: float = 5.0  # [m/s^3]
    line_accel: float = 5.0  # [m/s^2] approach/depart (the joint limits scale it down where they bind)
    line_jerk: float = 100.0  # [m/s^3]
    # Arc-off motions approximated at the points between them (cell/planning/blend.py): at most this fraction of
    # each of two neighbouring motions is left out at their point [0, 0.5]; 0: an exact stop at every point.
    blend: float = 0.5
    # Shorter approach and depart lines [m] a transfer between two seams may meet, shortest first, where its motions
    # are free with them (cell/planning/short_lines.py): every 5 mm to 20 mm, then 30 and 40 mm (each length is
    # one more collision check of every strategy that fails: the 5 mm knots beyond 20 mm cost a fifth of the
    # planner's time for a few tenths of a second per side, docs/cycle.md); the process's are the longest. (): none.
    short_lines: tuple[float, ...] = (0.005, 0.01, 0.015, 0.02, 0.03, 0.04)
    transfer_lift: float = 0.15  # [m] via-points this far above the highest obstacle when a transfer collides
    # A seam ending on the table where the torch meets the table is welded from at most this far above it [m]
    # (never more than a third of the seam); 0: such a seam is refused.
    table_stand_off_max: float = 0.015
    # The hose package's A6 window: A6 stays within a6_window of a6_center (cable travel of the dress pack wound
    # round the wrist); each seam's free spin and wrist are chosen to keep it there. inf: no limit.
    a6_window: float = math.radians(185.0)  # [rad] either side of the centre
    a6_center: float = 0.0  # [rad] A6 where the hose package hangs untwisted
    dt: float = 0.001  # [s] sample period: 1 kHz, the rate the safety gate re-samples at
    # The collision model of the whole run: the plan, the safety gate and every close-up view use one checker.
    collision: CollisionOptions = field(default_factory=CollisionOptions)
    ik: IKOptions = field(default_factory=IKOptions)  # every IK of the plan (and the arm's scan configuration)


@dataclass(frozen=True)
class GateOptions:
    """Thresholds of the safety gate (:func:`~cell.gate.find_violations`).

    rate_hz : re-sampling rate [Hz]. rel_tol : relative slack on the velocity/acceleration/jerk limits.
    start_tol : how far the plan may start from the arm's configuration [rad].
    rest_tol : joint speed [rad/s] (and acceleration [rad/s^2]) below which an exact stop is at rest.
    min_manipulability : below this a configuration counts as singular [m^3].
    lin_step : TCP travel between singularity checks on LIN segments [m].
    body_depth : how deep [m] the TCP or the wire may lie inside a part's body before the path counts as entering
        it (the TCP sits in the joint's corner, on both parts' faces, within the seam's position error).
    body_step : TCP travel between the samples of that check [m].
    """

    rate_hz: float = 1000.0
    rel_tol: float = 0.01
    start_tol: float = 1e-4
    rest_tol: float = 1e-6
    min_manipulability: float = 0.01
    lin_step: float = 0.002
    body_depth: float = 0.001
    body_step: float = 0.0005


@dataclass(frozen=True)
class ViewOptions:
    """Candidate grid and acceptance thresholds of a close-up view (lengths [m], angles [deg])."""

    distances_m: tuple[float, ...] = (0.36, 0.40, 0.44, 0.33)  # D415 minimum range ~0.3 m; TCP 0.3 m ahead
    preferred_distance_m: float = 0.36
    tilts_deg: tuple[float, ...] = (0.0, 15.0, -15.0, 30.0, -30.0)  # about the seam, towards face A (+) or B
    slants_deg: tuple[float, ...] = (0.0, 20.0, -20.0, 40.0, -40.0)  # along the seam
    # The seam's angle in the image (a turn about the line of sight to its midpoint, which stays put): the
    # wrist reaches some of these and not others.
    rolls_deg: tuple[float, ...] = (0.0, 180.0, 20.0, -20.0, 160.0, -160.0, 40.0, -40.0, 140.0, -140.0)
    image_offset_deg: float = 11.0  # the seam's midpoint this far above the image centre (torch below)
    max_incidence_deg: float = 72.0  # largest angle between a line of sight and a weld face's normal
    face_strip_m: float = 0.03  # width of each weld face next to the seam that must be in view
    # A seam no grid pose sees (a lap plate's side in a 67 mm channel beside a 168 mm upright) is tried once more
    # on these tilts, with this incidence limit and this strip: a grazing close-up is better than none (the
    # re-scan asks it only for a seam the fixed cameras did not find; empty: never).
    fallback_tilts_deg: tuple[float, ...] = (-22.5, 22.5, -7.5, 7.5, -37.5, 37.5, -30.0, 30.0)
    fallback_max_incidence_deg: float = 80.0  # the fallback grid's incidence limit
    fallback_face_strip_m: float = 0.015  # the fallback grid's face strip
    end_margin_m: float = 0.01  # the seam's line beyond its ends that must be in view
    image_margin_px: float = 24.0  # kept free along the image border
    torch_radius_m: float = 0.03  # the torch's radius about its axis, with margin (URDF body: 22 mm)
    torch_margin_px: float = 12.0
    occlusion_margin_m: float = 0.001  # parts grown by this for the line-of-sight test
    distance_weight_deg_per_m: float = 200.0  # score: 10 deg of incidence for 5 cm off the preferred distance
    camera_frame: str = "camera_optical"
    tcp_frame: str = "torch_tcp"
    flange_frame: str = "tool0"
    dt: float = 0.004  # [s] sample period of the move
    ik: IKOptions = field(default_factory=IKOptions)  # the camera pose's IK

    def __post_init__(self) -> None:
        if not self.distances_m or min(self.distances_m) <= 0.0:
            raise ValueError(f"view distances_m must be positive, got {self.distances_m}")
        if not 0.0 < self.max_incidence_deg < 90.0:
            raise ValueError(f"max_incidence_deg must be in (0, 90), got {self.max_incidence_deg}")
        if not 0.0 < self.fallback_max_incidence_deg < 90.0:
            raise ValueError(f"fallback_max_incidence_deg must be in (0, 90), got {self.fallback_max_incidence_deg}")


@dataclass(frozen=True)
class PositionerFigures:
    """A tilt-rotate positioner's turning axis as the report's estimate assumes it (nominal figures of a 400 kg
    class unit; the positioner itself is not modelled): speed [rad/s], acceleration [rad/s^2], jerk [rad/s^3]. Only
    the axis's motion is counted: the part stays clamped, nobody confirms."""

    speed: float = math.radians(90.0)
    accel: float = math.radians(180.0)
    jerk: float = math.radians(900.0)
