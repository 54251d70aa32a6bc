"""The welding planner's settings (:class:`PlanOptions`): code defaults only; the cell's figures come from the
scenario's ProcessSpec through :class:`~cell.motion.torch.WeldProcess`."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from cell.motion.collision import CollisionOptions


@dataclass(frozen=True)
class PlanOptions:
    """Planner settings (code defaults; the cell-specific figures live in the scenario's ProcessSpec)."""

    spacing: float = 0.0025  # [m] IK knots along the weld
    line_spacing: float = 0.005  # [m] IK knots along approach/depart
    spin_step: float = math.radians(45.0)  # [rad] spins tried about the torch axis
    angle_step: float = math.radians(5.0)  # [rad] widening of work/travel angles within their tolerance
    max_full: int = 4  # candidates solved along the whole seam per angle setting
    max_joint_step: float = math.radians(10.0)  # [rad] largest joint change between knots (flip)
    min_manipulability: float = 0.01  # [m^3] below this a Cartesian move counts as singular
    weld_accel: float = 0.5  # [m/s^2] path acceleration of the weld ramps
    weld_jerk: float = 5.0  # [m/s^3]
    line_accel: float = 2.0  # [m/s^2] approach/depart
    line_jerk: float = 20.0  # [m/s^3]
    transfer_lift: float = 0.15  # [m] via-points this far above the highest obstacle when a transfer collides
    dt: float = 0.001  # [s] sample period: 1 kHz, the rate the safety gate re-samples at
    collision: CollisionOptions = field(default_factory=CollisionOptions)
