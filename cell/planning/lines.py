"""Straight TCP lines (KRL LIN): IK knots along a line of poses (:func:`solve_line`) and their timing
(:func:`line_trajectory`). Approach, weld, depart and the lifts of a transfer are all such lines.

Frames: everything in the robot base frame R [m]; joints [rad]; time [s].
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import numpy.typing as npt
from scipy.interpolate import CubicSpline

from cell.errors import IKError, TimingError
from cell.geometry import FloatArray
from cell.motion.ik import IKOptions, solve_ik
from cell.motion.limits import JointLimits
from cell.motion.robot import RobotModel
from cell.motion.timing import DEFAULT_DT, Trajectory, path_profile
from cell.planning.failures import LineError, SeamFailure, unreachable
from cell.types.plan import PlanReason

_SLACK = 0.98  # a joint may use this share of its limits


def solve_line(
    robot: RobotModel,
    X: FloatArray,
    q0: FloatArray,
    what: str,
    offset: float,
    step: float,
    max_joint_step: float,
    *,
    ik: IKOptions | None = None,
    probe: Callable[[int, FloatArray], None] | None = None,
) -> FloatArray:
    """Warm-started IK (n, dof) [rad] along poses X (n, 4, 4) in R from q0 (the solution at X[0]), with the solver
    settings ``ik`` (its defaults when None). ``probe(i, q)`` is called with each knot solved after the first (it
    may raise to stop the line there).

    what : the line's name in messages (seam, approach, depart, lift); step [m] between poses; offset [m] where
    the line starts on the candidate's path (the failure's progress). Raises :class:`LineError` when IK fails
    or a joint jumps more than ``max_joint_step`` [rad] between neighbouring poses (a flip).
    """
    out = [q0]
    lim = robot.limits
    for i in range(1, len(X)):
        try:
            q = solve_ik(robot, X[i], out[-1], options=ik)
        except IKError as exc:
            raise LineError(unreachable(exc, X[i], i * step, offset + i * step, what)) from exc
        jump = np.abs(q - out[-1])
        if float(jump.max()) > max_joint_step:
            j = int(np.argmax(jump))
            raise LineError(
                SeamFailure(
                    PlanReason.FLIP,
                    f"joint {lim.names[j]} jumps {math.degrees(jump[j]):.1f} deg at "
                    f"{i * step * 1000:.1f} mm along the {what}",
                    X[i][:3, 3].copy(),
                    offset + i * step,
                )
            )
        out.append(q)
        if probe is not None:
            probe(i, q)
    return np.array(out)


def line_trajectory(
    robot: RobotModel,
    q_knots: npt.ArrayLike,
    length: float,
    direction_R: npt.ArrayLike,
    speed: float,
    accel: float,
    jerk: float,
    *,
    fixed_speed: bool = False,
    dt: float = DEFAULT_DT,
) -> tuple[Trajectory, float]:
    """Time a straight TCP line through its IK knots: (trajectory, TCP speed used [m/s]).

    q_knots : (n, dof) [rad] IK solutions at n evenly spaced points over ``length`` [m] along ``direction_R``
        (3,) (unit, in R), at constant orientation. q(s) is the C2 cubic spline through the knots whose end slopes
        are the exact dq/ds = J^-1 [d; 0]; s(t) is a rest-to-rest Ruckig profile at most ``speed`` [m/s] with
        path acceleration ``accel`` [m/s^2] and jerk ``jerk`` [m/s^3]. When a joint would exceed its velocity,
        acceleration or jerk limit, the path limits are scaled down (the speed too unless ``fixed_speed``: then
        a velocity excess is a TimingError, e.g. a weld too fast for the arm at that pose).
    """
    Q = np.asarray(q_knots, dtype=float)
    d = np.asarray(direction_R, dtype=float)
    s_knots = np.linspace(0.0, length, len(Q))
    twist = np.concatenate([d, np.zeros(3)])
    ends = [np.linalg.solve(robot.jacobian(q, "torch_tcp", "aligned"), twist) for q in (Q[0], Q[-1])]
    spline = CubicSpline(s_knots, Q, axis=0, bc_type=((1, ends[0]), (1, ends[1])))
    return time_spline(spline, Q, robot.limits, length, speed, accel, jerk, fixed_speed=fixed_speed, dt=dt, what="line")


def time_spline(
    spline: CubicSpline,
    Q: FloatArray,
    lim: JointLimits,
    length: float,
    speed: float,
    accel: float,
    jerk: float,
    *,
    fixed_speed: bool,
    dt: float,
    what: str,
) -> tuple[Trajectory, float]:
    """Time a joint path q(s) (``spline`` through the knots Q (n, dof) [rad], s from 0 to ``length`` [m]) by a
    rest-to-rest Ruckig path profile: (trajectory, path speed used [m/s]). The path's speed, acceleration and jerk
    are scaled down until every joint stays within ``_SLACK`` of its limits (the speed too unless ``fixed_speed``:
    then a velocity excess is a TimingError naming the joint); ``what`` names the path in errors."""
    v, a, j = speed, accel, jerk
    for _ in range(8):
        prof = path_profile(length, v, a, j, dt=dt)
        s, sd, sdd = prof.s, prof.sd[:, None], prof.sdd[:, None]
        d1, d2 = spline(s, 1), spline(s, 2)
        q = spline(s)
        qd = d1 * sd
        qdd = d2 * sd**2 + d1 * sdd
        h = np.diff(prof.times)[:, None]
        qddd = np.diff(qdd, axis=0) / h if len(h) else np.zeros((0, Q.shape[1]))
        rv = float(np.max(np.abs(qd) / lim.v_max))
        ra = float(np.max(np.abs(qdd) / lim.a_max))
        rj = float(np.max(np.abs(qddd) / lim.j_max)) if len(qddd) else 0.0
        if max(rv, ra, rj) <= _SLACK:
            q[0], q[-1] = Q[0], Q[-1]  # the knots exactly, not up to spline rounding
            qd[0] = qd[-1] = 0.0
            return Trajectory(prof.times, q, qd, qdd), v
        if rv > _SLACK:
            if fixed_speed:
                k = int(np.argmax(np.max(np.abs(qd) / lim.v_max, axis=0)))
                raise TimingError(
                    f"joint {lim.names[k]} would move at {rv * 100:.0f} % of its velocity limit along the {what} "
                    f"at the travel speed {speed * 1000:.1f} mm/s"
                )
            v *= 0.95 / rv
        if ra > _SLACK:
            a *= 0.95 / ra
        if rj > _SLACK:
            j *= 0.95 / rj
    raise TimingError(f"could not time a {length * 1000:.1f} mm {what} within the joint limits")
