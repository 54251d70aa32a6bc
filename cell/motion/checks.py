"""The safety gate before motion (REFERENCE.md section 7): find every way a plan could hurt, refuse to run it.

:func:`find_violations` returns one :class:`Violation` per problem (the worst instance of each kind and joint),
each saying what, where (time, joint) and by how much; :func:`check_plan` raises :class:`~cell.errors.PlanError`
when there is any. Checked:

* start: the plan starts at rest at the current state (within ``start_tol``) and inside the position limits;
* limits: position, velocity, acceleration and jerk at every sample when re-sampled at ``rate_hz`` (1 kHz, on
  a grid that keeps every stored sample); jerk is the finite difference of the re-sampled acceleration.
  ``rel_tol`` (1 %) covers rounding and the quintic interpolation of a plan stored coarser than 1 kHz;
* continuity: consecutive segments meet (same time, same configuration), no stored sample jumps further than
  the velocity limit allows over its interval;
* singularities: along Cartesian (LIN) segments, the manipulability stays above ``min_manipulability``
  (joint-interpolated PTP moves may pass through singular poses harmlessly);
* arc: on only during weld segments, switched on and off at exact stops;
* collisions: robot against the obstacles and itself along every segment (conservative advancement, see
  :mod:`cell.motion.collision`), when a checker is given.

Units: SI (rad, rad/s, rad/s^2, rad/s^3, m, s) in the fields; degrees and mm in the messages.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cell.errors import PlanError
from cell.geometry import FloatArray
from cell.motion.collision import CollisionChecker
from cell.motion.program import WeldPlan
from cell.motion.robot import RobotModel


@dataclass(frozen=True)
class Violation:
    """One problem: kind (start_state | position | velocity | acceleration | jerk | jump | singularity | arc |
    collision), a one-line description, where (time t [s], joint name or ""), and by how much (``excess`` in
    the kind's SI unit: rad, rad/s, rad/s^2, rad/s^3, m^3 for manipulability, m for collision depth)."""

    kind: str
    what: str
    t: float
    joint: str = ""
    excess: float = 0.0

    def __str__(self) -> str:
        j = f" {self.joint}" if self.joint else ""
        return f"{self.kind}{j} at t = {self.t:.3f} s: {self.what}"


@dataclass(frozen=True)
class GateOptions:
    """rate_hz: re-sampling rate; rel_tol: relative slack on the velocity/acceleration/jerk limits; start_tol
    [rad]; rest_tol [rad/s] (and [rad/s^2] for the acceleration) for an exact stop; min_manipulability [m^3];
    lin_step [m]: TCP travel between singularity checks on LIN segments."""

    rate_hz: float = 1000.0
    rel_tol: float = 0.01
    start_tol: float = 1e-4
    rest_tol: float = 1e-6
    min_manipulability: float = 0.01
    lin_step: float = 0.002


def _worst(
    kind: str, times: FloatArray, values: FloatArray, limit: FloatArray, names: tuple[str, ...], unit: str, scale: float
) -> list[Violation]:
    """Per joint, the sample where |value| exceeds limit the most."""
    out = []
    excess = np.abs(values) - limit
    for j in np.flatnonzero(np.any(excess > 0.0, axis=0)):
        i = int(np.argmax(excess[:, j]))
        out.append(
            Violation(
                kind,
                f"|{kind}| {abs(values[i, j]) * scale:.4g} {unit} over the limit "
                f"{limit[j] * scale:.4g} {unit} by {excess[i, j] * scale:.3g} {unit}",
                float(times[i]),
                names[j],
                float(excess[i, j]),
            )
        )
    return out


def _resample_times(times: FloatArray, rate_hz: float) -> FloatArray:
    """Times at least ``rate_hz`` apart-or-closer, keeping every stored sample (each interval of the stored
    trajectory is cut into equal parts no longer than 1 / rate_hz)."""
    h = np.diff(times)
    n_sub = np.maximum(np.ceil(h * rate_hz - 1e-6).astype(int), 1)
    start = np.repeat(times[:-1], n_sub)
    first = np.repeat(np.cumsum(n_sub) - n_sub, n_sub)  # index of each interval's first new time
    frac = (np.arange(int(n_sub.sum())) - first) / np.repeat(n_sub, n_sub)
    return np.append(start + np.repeat(h, n_sub) * frac, times[-1])


def find_violations(
    robot: RobotModel,
    plan: WeldPlan,
    q_current: FloatArray,
    *,
    checker: CollisionChecker | None = None,
    options: GateOptions | None = None,
) -> list[Violation]:
    """Every violation of the gate's checks (see the module docstring); an empty list means go."""
    opt = options or GateOptions()
    lim, names = robot.limits, robot.joint_names
    out: list[Violation] = []
    if not plan.segments:
        return out
    traj, _ = plan.joint_trajectory()
    deg = 180.0 / math.pi

    # start state
    q_cur = np.asarray(q_current, dtype=float)
    off = np.abs(traj.q[0] - q_cur)
    for j in np.flatnonzero(off > opt.start_tol):
        out.append(
            Violation(
                "start_state",
                f"plan starts {off[j] * deg:.3f} deg away from the current state",
                0.0,
                names[j],
                float(off[j]),
            )
        )
    if not lim.contains(q_cur):
        out.append(Violation("start_state", "the current state is outside the position limits", 0.0))
    for j in np.flatnonzero(np.abs(traj.qd[0]) > opt.rest_tol):
        out.append(
            Violation(
                "start_state",
                f"plan does not start at rest ({traj.qd[0, j] * deg:.3g} deg/s)",
                0.0,
                names[j],
                float(abs(traj.qd[0, j])),
            )
        )

    # continuity between segments and between stored samples
    for s0, s1 in zip(plan.segments, plan.segments[1:], strict=False):
        gap = np.abs(s0.trajectory.q[-1] - s1.trajectory.q[0])
        if abs(s0.t1 - s1.t0) > 1e-9 or gap.max() > 1e-9:
            jg = int(np.argmax(gap))
            out.append(
                Violation(
                    "jump",
                    f"segments do not meet: {gap[jg] * deg:.3f} deg, {abs(s0.t1 - s1.t0):.3g} "
                    f"s apart ({s0.kind} -> {s1.kind} of {s1.seam_id or 'home'})",
                    s1.t0,
                    names[jg],
                    float(gap[jg]),
                )
            )
    h = np.diff(traj.times)[:, None]
    step = np.abs(np.diff(traj.q, axis=0))
    allowed = lim.v_max * h * (1.0 + opt.rel_tol) + 1e-9
    bad = step > allowed
    for j in np.flatnonzero(bad.any(axis=0)):
        i = int(np.argmax(step[:, j] - allowed[:, j]))
        out.append(
            Violation(
                "jump",
                f"moves {step[i, j] * deg:.3f} deg in {h[i, 0] * 1000:.1f} ms (at most "
                f"{allowed[i, j] * deg:.3f} deg at full speed)",
                float(traj.times[i + 1]),
                names[j],
                float(step[i, j] - allowed[i, j]),
            )
        )

    # limits at rate_hz
    t = _resample_times(traj.times, opt.rate_hz)
    q, qd, qdd = traj.sample(t)
    qddd = np.diff(qdd, axis=0) / np.diff(t)[:, None]
    below, above = lim.q_min - q, q - lim.q_max
    pos = np.maximum(below, above)
    for j in np.flatnonzero(np.any(pos > 1e-9, axis=0)):
        i = int(np.argmax(pos[:, j]))
        out.append(
            Violation(
                "position",
                f"{q[i, j] * deg:.3f} deg is {pos[i, j] * deg:.3g} deg outside "
                f"[{lim.q_min[j] * deg:.1f}, {lim.q_max[j] * deg:.1f}] deg",
                float(t[i]),
                names[j],
                float(pos[i, j]),
            )
        )
    k = 1.0 + opt.rel_tol
    out += _worst("velocity", t, qd, lim.v_max * k, names, "deg/s", deg)
    out += _worst("acceleration", t, qdd, lim.a_max * k, names, "deg/s^2", deg)
    out += _worst("jerk", t[1:], qddd, lim.j_max * k, names, "deg/s^3", deg)

    # singularities along LIN segments; arc switching
    for seg in plan.segments:
        tr = seg.trajectory
        if seg.kind != "move" and seg.speed > 0.0:
            stride = max(1, int(opt.lin_step / (seg.speed * max(float(np.min(np.diff(tr.times), initial=1.0)), 1e-6))))
            idx = np.unique(np.append(np.arange(0, len(tr.times), stride), len(tr.times) - 1))
            m = np.array([robot.manipulability(tr.q[i]) for i in idx])
            i = int(np.argmin(m))
            if m[i] < opt.min_manipulability:
                out.append(
                    Violation(
                        "singularity",
                        f"manipulability {m[i]:.3g} below {opt.min_manipulability:g} "
                        f"on the {seg.kind} of {seg.seam_id}",
                        seg.t0 + float(tr.times[idx[i]]),
                        "",
                        float(opt.min_manipulability - m[i]),
                    )
                )
        if seg.arc_on and seg.kind != "weld":
            out.append(Violation("arc", f"arc on during a {seg.kind} segment", seg.t0))
        if seg.arc_on:
            for end, at in (("on", 0), ("off", -1)):
                v = float(np.max(np.abs(tr.qd[at])))
                acc = float(np.max(np.abs(tr.qdd[at])))
                if v > opt.rest_tol or acc > opt.rest_tol:
                    out.append(
                        Violation(
                            "arc",
                            f"arc {end} while moving ({v * deg:.3g} deg/s, {acc * deg:.3g} "
                            f"deg/s^2) on {seg.seam_id}: needs an exact stop",
                            seg.t0 + float(tr.times[at]),
                            "",
                            max(v, acc),
                        )
                    )

    # collisions
    if checker is not None:
        for seg in plan.segments:
            hit = checker.check_path(seg.trajectory.q, seg.trajectory.times)
            if hit is not None:
                out.append(
                    Violation(
                        "collision",
                        f"{hit.describe().split(' at t =')[0]} during the {seg.kind}"
                        f"{' of ' + seg.seam_id if seg.seam_id else ''}",
                        seg.t0 + hit.t,
                        "",
                        float(-hit.depth),
                    )
                )
    return out


def check_plan(
    robot: RobotModel,
    plan: WeldPlan,
    q_current: FloatArray,
    *,
    checker: CollisionChecker | None = None,
    options: GateOptions | None = None,
) -> None:
    """Raise PlanError naming the violations (the first five and a count) unless the plan passes the gate."""
    found = find_violations(robot, plan, q_current, checker=checker, options=options)
    if found:
        shown = "; ".join(str(v) for v in found[:5])
        more = f" (+{len(found) - 5} more)" if len(found) > 5 else ""
        raise PlanError(f"plan refused by the safety gate, {len(found)} violation(s): {shown}{more}")
