"""A curved weld timed: the joints along the curve as a C2 spline in the length welded, the length in time a
rest-to-rest Ruckig profile at the travel speed (the arm's joint limits scale the ramps, never the travel speed);
with its approach and depart lines and the procedure's craters, the seam's pieces for the plan
(docs/curves-welding.md section 3).

Frames: everything in the robot base frame R [m]; joints [rad]; time [s]."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.interpolate import CubicSpline

from cell.config.motion import PlanOptions
from cell.geometry import FloatArray
from cell.motion.robot import RobotModel
from cell.motion.timing import DEFAULT_DT, Trajectory
from cell.planning.lines import line_trajectory, time_spline
from cell.planning.passes import with_craters
from cell.planning.seam_search import SeamSolution
from cell.planning.transfers import Piece
from cell.process.torch import WeldProcess
from cell.types.procedure import WeldProcedure


def curve_trajectory(
    robot: RobotModel,
    q_knots: FloatArray,
    s_knots: FloatArray,
    speed: float,
    accel: float,
    jerk: float,
    *,
    dt: float = DEFAULT_DT,
) -> Trajectory:
    """The weld along a curve through its IK knots q_knots (n, dof) [rad] at the lengths welded s_knots (n,) [m]:
    q(s) the not-a-knot cubic spline through the knots, s(t) from rest to rest at exactly ``speed`` [m/s] in its
    middle, path acceleration ``accel`` [m/s^2] and jerk ``jerk`` [m/s^3] scaled down where a joint would pass its
    acceleration or jerk limit. TimingError when a joint would pass its velocity limit at the travel speed."""
    Q = np.asarray(q_knots, dtype=float)
    s_k = np.asarray(s_knots, dtype=float)
    spline = CubicSpline(s_k, Q, axis=0)
    length = float(s_k[-1])
    traj, _ = time_spline(spline, Q, robot.limits, length, speed, accel, jerk, fixed_speed=True, dt=dt, what="curve")
    return traj


def curve_pieces(
    robot: RobotModel,
    process: WeldProcess,
    options: PlanOptions,
    sol: SeamSolution,
    procedure: WeldProcedure | None,
) -> list[Piece]:
    """Approach (a line along the torch axis), the weld along the curve (its craters held at rest where the
    procedure has them) and the depart of a solved curved seam, timed at the procedure's travel speed (the
    process's without one). Raises TimingError."""
    speed = procedure.travel_speed_mm_s / 1000.0 if procedure is not None else process.travel_speed
    app, weld, dep = curve_lines(robot, replace(process, travel_speed=speed), options, sol)
    craters = procedure or WeldProcedure(name="default")  # the crater filled at the end, as a controller's default
    return [app, with_craters(weld, craters.crater_start_s, craters.crater_end_s, options.dt), dep]


def curve_lines(robot: RobotModel, process: WeldProcess, options: PlanOptions, sol: SeamSolution) -> list[Piece]:
    """Approach, weld along the curve at ``process.travel_speed`` (no craters) and depart of one solved pass of a
    curved seam (the pieces :func:`cell.planning.passes.pass_pieces` joins pass after pass). Raises TimingError."""
    pr, opt = process, options
    X = sol.X_weld
    s = np.linspace(0.0, sol.task.length, len(X))
    approach = float(np.linalg.norm(X[0][:3, 3] - sol.X_approach[:3, 3]))  # the search may have shortened them
    depart = float(np.linalg.norm(X[-1][:3, 3] - sol.X_depart[:3, 3]))
    app, v_app = line_trajectory(
        robot, sol.q_approach, approach, X[0][:3, 2], pr.approach_speed, opt.line_accel, opt.line_jerk, dt=opt.dt
    )
    weld = curve_trajectory(robot, sol.q_weld, s, pr.travel_speed, opt.weld_accel, opt.weld_jerk, dt=opt.dt)
    dep, v_dep = line_trajectory(
        robot, sol.q_depart, depart, -X[-1][:3, 2], pr.approach_speed, opt.line_accel, opt.line_jerk, dt=opt.dt
    )
    return [Piece("approach", app, v_app, X[0]), Piece("weld", weld, pr.travel_speed, X[-1]),
            Piece("depart", dep, v_dep, sol.X_depart)]  # fmt: skip
