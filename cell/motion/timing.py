"""Jerk-limited timing with Ruckig, the only module that imports ruckig: state-to-state motions only, a rest-to-rest
PTP timed as a KRC4 drives it, a weld as a one-axis profile of the path length; any result but Working/Finished
raises :class:`~cell.errors.TimingError` (docs/reference.md section 9).
Units: joints [rad], [rad/s], [rad/s^2], [rad/s^3]; path length [m], [m/s], [m/s^2], [m/s^3]; time [s]."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
import ruckig

from cell.errors import TimingError
from cell.geometry import FloatArray
from cell.motion.limits import JointLimits
from cell.types.trajectory import PathProfile, Trajectory

DEFAULT_DT = 0.004  # [s] sample period (250 Hz)
_END_TOL = 1e-8  # how far Ruckig's end state may be from the target before it is an error [rad, rad/s]


def _vec(name: str, value: npt.ArrayLike | None, dof: int) -> FloatArray:
    arr = np.zeros(dof) if value is None else np.asarray(value, dtype=float)
    if arr.shape != (dof,) or not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be {dof} finite values, got shape {arr.shape}")
    return arr


def _solve(inp: ruckig.InputParameter, what: str) -> ruckig.Trajectory:
    """Run Ruckig offline; TimingError unless the result is Working or Finished."""
    otg = ruckig.Ruckig(inp.degrees_of_freedom)
    traj = ruckig.Trajectory(inp.degrees_of_freedom)
    try:
        result = otg.calculate(inp, traj)
    except (ruckig.RuckigError, RuntimeError) as exc:  # invalid input raises instead of returning a result
        raise TimingError(f"Ruckig rejected the {what}: {' '.join(str(exc).split())}") from exc
    if result not in (ruckig.Result.Working, ruckig.Result.Finished):
        raise TimingError(f"Ruckig returned {result.name} for the {what}; only Working or Finished are success")
    return traj


def _sample_times(duration: float, dt: float) -> FloatArray:
    """0, dt, 2 dt, ... and the exact end ``duration`` [s]."""
    if not dt > 0.0:
        raise ValueError(f"sample period dt must be positive, got {dt}")
    n = max(math.ceil(duration / dt - 1e-9), 0)
    return np.append(np.arange(n) * dt, duration) if duration > 0.0 else np.zeros(1)


def _at_times_loop(traj: ruckig.Trajectory, times: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """pos, vel, acc (n, dof) from Ruckig's own evaluation, one call per time."""
    rows = [traj.at_time(float(t)) for t in times]
    return tuple(np.array([r[i] for r in rows]) for i in range(3))  # type: ignore[return-value]


def _at_times(traj: ruckig.Trajectory, times: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """pos, vel, acc (n, dof) at times (n,), evaluated from the profiles' constant-jerk phases in one go.

    Each joint's profile has 7 phases (durations t, jerks j, start states p, v, a). Profiles with a brake or
    acceleration pre/post phase (start or goal outside the limits) fall back to Ruckig's at_time.
    """
    sections = traj.profiles
    if len(sections) != 1 or any(p.brake.duration > 0.0 or p.accel.duration > 0.0 for p in sections[0]):
        return _at_times_loop(traj, times)
    profs = sections[0]
    dof = len(profs)
    ends = np.cumsum([x.t for x in profs], axis=1)  # (dof, 7) end time of each phase
    # (n, dof) phase index: the number of phase ends at or before t (so zero-length phases are skipped)
    # One sorted search for all joints: joint d's phase ends and the times are shifted by d * span.
    span = float(ends[:, -1].max() + times[-1]) + 1.0
    shift = np.arange(dof) * span
    flat = (ends[:, :6] + shift[:, None]).ravel()
    k = np.searchsorted(flat, times[:, None] + shift[None, :], side="right") - 6 * np.arange(dof)[None, :]
    starts = np.concatenate((np.zeros((dof, 1)), ends[:, :6]), axis=1)  # (dof, 7)
    # phase start states and jerks, (dof, 5, 7): p, v, a, j, start time
    coef = np.array([[x.p[:7], x.v[:7], x.a[:7], x.j, s] for x, s in zip(profs, starts.tolist(), strict=True)])
    g = coef[np.arange(dof)[None, :], :, k]  # (n, dof, 5)
    p, v, a, j = g[..., 0], g[..., 1], g[..., 2], g[..., 3]
    tau = times[:, None] - g[..., 4]
    return p + tau * (v + tau * (a / 2.0 + tau * j / 6.0)), v + tau * (a + tau * j / 2.0), a + tau * j


def _checked_states(
    q0: npt.ArrayLike,
    q1: npt.ArrayLike,
    limits: JointLimits,
    v0: npt.ArrayLike | None,
    v1: npt.ArrayLike | None,
) -> tuple[FloatArray, FloatArray]:
    """(2, dof) positions and velocities of start and goal; TimingError when outside the limits."""
    dof = limits.dof
    q = np.array([_vec("q0", q0, dof), _vec("q1", q1, dof)])  # (2, dof): start, goal
    v = np.array([_vec("v0", v0, dof), _vec("v1", v1, dof)])
    outside = (q < limits.q_min - 1e-9) | (q > limits.q_max + 1e-9)
    if outside.any():
        row = int(np.argmax(outside.any(axis=1)))
        bad = [n for n, o in zip(limits.names, outside[row], strict=True) if o]
        raise TimingError(
            f"ptp {('start', 'goal')[row]} configuration is outside the position limits at {', '.join(bad)}"
        )
    if (np.abs(v) > limits.v_max * (1 + 1e-9)).any():
        raise TimingError("ptp start or goal velocity exceeds the joint velocity limits")
    return q, v


def _line_solve(q: FloatArray, limits: JointLimits) -> ruckig.Trajectory | None:
    """The profile u(t) from rest at 0 to rest at 1 of the straight joint line q[0] -> q[1] (None: no motion).

    Axis j moves dq_j u(t), so its velocity, acceleration and jerk are dq_j times u's: u's limits are the
    smallest of v_max_j / |dq_j| (and likewise for a and j) over the moving axes. The line stays inside the
    position limits (a box holding both ends), and a rest-to-rest profile never overshoots its target.
    """
    dq = np.abs(q[1] - q[0])
    moving = dq > 0.0
    if not moving.any():
        return None
    inp = ruckig.InputParameter(1)
    inp.current_position, inp.current_velocity, inp.current_acceleration = [0.0], [0.0], [0.0]
    inp.target_position, inp.target_velocity, inp.target_acceleration = [1.0], [0.0], [0.0]
    inp.max_velocity = [float(np.min(limits.v_max[moving] / dq[moving]))]
    inp.max_acceleration = [float(np.min(limits.a_max[moving] / dq[moving]))]
    inp.max_jerk = [float(np.min(limits.j_max[moving] / dq[moving]))]
    return _solve(inp, "point-to-point move")


def _ruckig_solve(
    q: FloatArray, v: FloatArray, limits: JointLimits, acc: FloatArray | None = None
) -> ruckig.Trajectory:
    """A move with boundary velocities (and accelerations ``acc`` (2, dof), default 0): one Ruckig solve over all
    joints within all limits (phase-synchronised when the start and goal states allow it, else time-synchronised)."""
    dof = limits.dof
    inp = ruckig.InputParameter(dof)
    a = np.zeros((2, dof)) if acc is None else acc
    inp.current_position, inp.current_velocity, inp.current_acceleration = q[0].tolist(), v[0].tolist(), a[0].tolist()
    inp.target_position, inp.target_velocity, inp.target_acceleration = q[1].tolist(), v[1].tolist(), a[1].tolist()
    inp.max_velocity = limits.v_max.tolist()
    inp.max_acceleration = limits.a_max.tolist()
    inp.max_jerk = limits.j_max.tolist()
    inp.min_position, inp.max_position = limits.q_min.tolist(), limits.q_max.tolist()
    inp.synchronization = ruckig.Synchronization.Phase
    traj = _solve(inp, "point-to-point move")
    # Ruckig returns Working even when a joint overshoots its range (a start velocity towards a near limit
    # that cannot be braked in time): check the exact extrema of each joint's profile.
    over = [
        n
        for n, b, lo, hi in zip(limits.names, traj.position_extrema, limits.q_min, limits.q_max, strict=True)
        if b.min < lo - 1e-9 or b.max > hi + 1e-9
    ]
    if over:
        raise TimingError(
            f"ptp move leaves the position limits at {', '.join(over)} (the start velocity cannot be braked in time)"
        )
    return traj


def ptp(
    q0: npt.ArrayLike,
    q1: npt.ArrayLike,
    limits: JointLimits,
    *,
    v0: npt.ArrayLike | None = None,
    v1: npt.ArrayLike | None = None,
    dt: float = DEFAULT_DT,
) -> Trajectory:
    """Jerk-limited joint move from (q0, v0, 0) to (q1, v1, 0), all joints starting and arriving together.

    q0, q1 : (dof,) [rad] within the position limits; v0, v1 : (dof,) [rad/s], default rest. From rest to rest
    (the default) it is a KRC PTP: every sample lies on the straight joint line q0 -> q1 (see the module
    docstring), the fastest such move within the limits. Velocity, acceleration, jerk and position stay within
    ``limits``; sampled every ``dt`` [s] plus the exact end. Raises TimingError when the states are outside the
    limits or Ruckig finds no trajectory.
    """
    q, v = _checked_states(q0, q1, limits, v0, v1)
    if not v.any():
        line = _line_solve(q, limits)
        if line is None:
            z = np.zeros((1, limits.dof))
            return Trajectory(np.zeros(1), q[1][None, :], z, z.copy())
        times = _sample_times(float(line.duration), dt)
        u, ud, udd = (x[:, 0] for x in _at_times(line, times))
        if abs(u[-1] - 1.0) > _END_TOL or abs(ud[-1]) > _END_TOL:
            raise TimingError("Ruckig's point-to-point profile does not end at rest at the goal")
        dq = q[1] - q[0]
        qs, qds, qdds = q[0] + u[:, None] * dq, ud[:, None] * dq, udd[:, None] * dq
        qs[-1], qds[-1], qdds[-1] = q[1], 0.0, 0.0  # the goal exactly, not up to rounding
        return Trajectory(times, qs, qds, qdds)
    traj = _ruckig_solve(q, v, limits)
    times = _sample_times(float(traj.duration), dt)
    qs, qds, qdds = _at_times(traj, times)
    if np.max(np.abs(qs[-1] - q[1])) > _END_TOL or np.max(np.abs(qds[-1] - v[1])) > _END_TOL:
        raise TimingError("Ruckig's point-to-point move does not end at the goal state")
    qs[-1], qds[-1], qdds[-1] = q[1], v[1], 0.0  # the goal exactly, not up to rounding
    return Trajectory(times, qs, qds, qdds)


def ptp_duration(
    q0: npt.ArrayLike,
    q1: npt.ArrayLike,
    limits: JointLimits,
    *,
    v0: npt.ArrayLike | None = None,
    v1: npt.ArrayLike | None = None,
) -> float:
    """Duration [s] of :func:`ptp` for the same move, without sampling it (cheap: for ordering and costs)."""
    q, v = _checked_states(q0, q1, limits, v0, v1)
    if not v.any():
        line = _line_solve(q, limits)
        return 0.0 if line is None else float(line.duration)
    return float(_ruckig_solve(q, v, limits).duration)


def connect(
    start: tuple[npt.ArrayLike, npt.ArrayLike, npt.ArrayLike],
    goal: tuple[npt.ArrayLike, npt.ArrayLike, npt.ArrayLike],
    limits: JointLimits,
    *,
    dt: float = DEFAULT_DT,
) -> Trajectory:
    """The time-optimal jerk-limited move from one moving state (q, qd, qdd) (dof,) each to another, all joints
    arriving together (a controller's blend between two motions). Raises TimingError when a state is outside
    the limits, Ruckig finds no trajectory or the move would leave the position limits."""
    q, v = _checked_states(start[0], goal[0], limits, start[1], goal[1])
    acc = np.array([_vec("a0", start[2], limits.dof), _vec("a1", goal[2], limits.dof)])
    if (np.abs(acc) > limits.a_max * (1 + 1e-9)).any():
        raise TimingError("blend start or goal acceleration exceeds the joint acceleration limits")
    traj = _ruckig_solve(q, v, limits, acc)
    times = _sample_times(float(traj.duration), dt)
    qs, qds, qdds = _at_times(traj, times)
    if np.max(np.abs(qs[-1] - q[1])) > _END_TOL or np.max(np.abs(qds[-1] - v[1])) > _END_TOL:
        raise TimingError("Ruckig's blend does not end at the goal state")
    qs[-1], qds[-1], qdds[-1] = q[1], v[1], acc[1]
    return Trajectory(times, qs, qds, qdds)


def ptp_line_deviation(q_path: npt.ArrayLike) -> float:
    """Largest distance [rad] of any joint of a path (n, dof) from the straight joint segment between its first
    and last rows: per sample, q minus its nearest point on the segment, the largest absolute component."""
    Q = np.asarray(q_path, dtype=float)
    d = Q[-1] - Q[0]
    n2 = float(d @ d)
    if n2 == 0.0:
        return float(np.max(np.abs(Q - Q[0])))
    u = np.clip((Q - Q[0]) @ d / n2, 0.0, 1.0)
    return float(np.max(np.abs(Q - Q[0] - u[:, None] * d[None, :])))


def path_profile(
    length_m: float, speed_mps: float, a_max: float, j_max: float, *, dt: float = DEFAULT_DT
) -> PathProfile:
    """s(t) from rest at 0 to rest at ``length_m`` [m], at most ``speed_mps`` [m/s] (the travel speed).

    a_max [m/s^2], j_max [m/s^3] bound the path acceleration and jerk; on a long enough seam the middle
    part runs at exactly the travel speed. Raises TimingError for non-positive inputs or when Ruckig fails.
    """
    values = {"length_m": length_m, "speed_mps": speed_mps, "a_max": a_max, "j_max": j_max}
    bad = [k for k, v in values.items() if not (math.isfinite(v) and v > 0.0)]
    if bad:
        raise TimingError(f"path_profile needs positive finite {', '.join(bad)}; got {values}")
    inp = ruckig.InputParameter(1)
    inp.current_position, inp.current_velocity, inp.current_acceleration = [0.0], [0.0], [0.0]
    inp.target_position, inp.target_velocity, inp.target_acceleration = [float(length_m)], [0.0], [0.0]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [float(speed_mps)], [float(a_max)], [float(j_max)]
    traj = _solve(inp, f"path profile over {length_m:.4f} m")
    times = _sample_times(float(traj.duration), dt)
    s, sd, sdd = _at_times(traj, times)
    if abs(s[-1, 0] - length_m) > _END_TOL or abs(sd[-1, 0]) > _END_TOL:
        raise TimingError("Ruckig's path profile does not end at rest at the path length")
    s[-1], sd[-1], sdd[-1] = length_m, 0.0, 0.0
    return PathProfile(times, s[:, 0], sd[:, 0], sdd[:, 0])
