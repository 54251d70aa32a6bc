"""A curved seam welded with the positioner turning the part: the tilt set so the fillet lies in PA, the rotate axis
turning each point of the seam under the torch, the arm solved at every knot for what the seam's deviation leaves
(a few millimetres where the part is clamped off centre); approach, weld, crater and depart, and the moves from and
back to home, timed together by Ruckig over the arm's and the positioner's axes and gated together
(docs/positioner.md, "Coordinated motion"). Frames: R the robot base, F the faceplate at home [m]; joints [rad]."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np
from scipy.interpolate import CubicSpline

from cell.config.motion import PlanOptions
from cell.coordinated.axes import CurveInF, knots_in_R, pa_axes, positions
from cell.coordinated.gate import MovingScene, joint_limits, off_limits
from cell.coordinated.record import CoordinatedWeld
from cell.errors import MotionError, PlanError
from cell.geometry import FloatArray
from cell.motion.ik import solve_ik, solve_path
from cell.motion.robot import RobotModel
from cell.motion.timing import ptp
from cell.planning.curves import CurvePath, curve_path, curve_poses
from cell.planning.curves.weave import curve_offsets
from cell.planning.failures import LineError
from cell.planning.lines import line_trajectory, solve_line, time_spline
from cell.planning.passes import with_craters
from cell.planning.transfers import Piece
from cell.process.torch import WeldProcess
from cell.process.weave import knot_spacing
from cell.types.curve_estimate import CurveEstimate
from cell.types.positioner import TiltRotatePositioner
from cell.types.procedure import Weave, WeldProcedure
from cell.types.trajectory import Trajectory

SPINS_DEG = (0.0, 90.0, -90.0, 180.0, 45.0, -45.0, 135.0, -135.0)  # the torch's spin about its axis, tried in turn
CHECK_STRIDE = 10  # the gate checks every this many samples (1 kHz): the motion between them is bounded anyway


def _in_F(X_FR: FloatArray, path: CurvePath) -> CurveInF:
    R, o = X_FR[:3, :3], X_FR[:3, 3]
    return CurveInF(path.p_R @ R.T + o, path.t_R @ R.T, path.n_a_R @ R.T, path.n_b_R @ R.T, path.s)


def _with_axes(traj: Trajectory, axes: FloatArray) -> FloatArray:
    """(n, dof + 2): the arm's samples with the positioner standing at ``axes`` (2,)."""
    return np.column_stack([traj.q, np.broadcast_to(axes, (len(traj.times), 2))])


def _line(robot: RobotModel, X0: FloatArray, q0: FloatArray, dist: float, back: float, what: str,
          opt: PlanOptions) -> FloatArray:  # fmt: skip
    """IK knots (k, dof) from the torch pose X0 (4, 4) backed off ``back`` * ``dist`` [m] along its axis."""
    k = max(2, math.ceil(dist / opt.line_spacing) + 1)
    X = np.repeat(X0[None], k, axis=0)
    X[:, :3, 3] = X0[:3, 3] + np.linspace(0.0, dist, k)[:, None] * (back * X0[:3, 2])
    try:
        return solve_line(robot, X, q0, what, 0.0, dist / (k - 1), opt.max_joint_step)
    except LineError as e:
        raise PlanError(f"the {what}: {e.failure.where}") from e


def _motion(
    robot: RobotModel,
    pos: TiltRotatePositioner,
    process: WeldProcess,
    opt: PlanOptions,
    X_RT: FloatArray,
    Q: FloatArray,
    axes: FloatArray,
    s: FloatArray,
    speed: float,
    procedure: WeldProcedure,
    start: tuple[FloatArray, FloatArray],
) -> tuple[list[tuple[str, FloatArray, FloatArray, bool]], float]:
    """The timed pieces (kind, times, states (n, dof + 2), arc on) from ``start`` (arm, axes) through the weld and
    back home, and the travel speed used [m/s]. Raises PlanError (TimingError) where a piece cannot be built."""
    lim = joint_limits(robot.limits, pos)
    Q8 = np.column_stack([Q, axes])
    weld, v = time_spline(CubicSpline(s, Q8, axis=0), Q8, lim, float(s[-1]), speed, opt.weld_accel, opt.weld_jerk,
                          fixed_speed=True, dt=opt.dt, what="coordinated weld")  # fmt: skip
    weld = with_craters(Piece("weld", weld, v, X_RT[-1]), procedure.crater_start_s, procedure.crater_end_s, opt.dt)[1]
    app_q = _line(robot, X_RT[0], Q[0], process.approach, -1.0, "approach", opt)[::-1]
    dep_q = _line(robot, X_RT[-1], Q[-1], process.depart, -1.0, "depart", opt)
    z0, z1 = X_RT[0][:3, 2], X_RT[-1][:3, 2]
    app, _ = line_trajectory(robot, app_q, process.approach, z0, process.approach_speed, opt.line_accel,
                             opt.line_jerk, dt=opt.dt)  # fmt: skip
    dep, _ = line_trajectory(robot, dep_q, process.depart, -z1, process.approach_speed, opt.line_accel,
                             opt.line_jerk, dt=opt.dt)  # fmt: skip
    x0 = np.concatenate(start)
    into = ptp(x0, np.concatenate([app_q[0], axes[0]]), lim, dt=opt.dt)
    home = np.concatenate([start[0], np.asarray(pos.home)])
    out = ptp(np.concatenate([dep_q[-1], axes[-1]]), home, lim, dt=opt.dt)
    pieces = [
        ("transfer", into.times, into.q, False),
        ("approach", app.times, _with_axes(app, axes[0]), False),
        ("weld", weld.times, weld.q, True),
        ("depart", dep.times, _with_axes(dep, axes[-1]), False),
        ("retreat", out.times, out.q, False),
    ]
    return pieces, v


def _gated(scene: MovingScene, pos: TiltRotatePositioner, robot: RobotModel,
           pieces: list[tuple[str, FloatArray, FloatArray, bool]]) -> None:  # fmt: skip
    """PlanError naming the piece where an axis leaves its limits or the arm or torch meets anything."""
    lim = joint_limits(robot.limits, pos)
    for kind, times, x, _ in pieces:
        why = off_limits(lim, x)
        if why is not None:
            raise PlanError(f"the {kind}: {why}")
        keep = np.unique(np.r_[np.arange(0, len(times), CHECK_STRIDE), len(times) - 1])
        hit = scene.check(times[keep], x[keep])
        if hit is not None:
            raise PlanError(f"the {kind}: {hit.describe()}")


def _joined(pieces: list[tuple[str, FloatArray, FloatArray, bool]]) -> tuple[FloatArray, ...]:
    times: list[FloatArray] = []
    xs: list[FloatArray] = []
    arcs: list[FloatArray] = []
    spans: list[tuple[str, float, float]] = []
    t = 0.0
    for kind, tt, x, arc in pieces:
        first = 0 if not times else 1  # each piece starts where the last one ended
        times.append(t + tt[first:])
        xs.append(x[first:])
        arcs.append(np.full(len(tt) - first, arc))
        spans.append((kind, t, t + float(tt[-1])))
        t += float(tt[-1])
    return np.concatenate(times), np.concatenate(xs), np.concatenate(arcs), spans  # type: ignore[return-value]


def _offsets(cp: CurvePath, procedure: WeldProcedure | None) -> tuple[FloatArray, FloatArray | None]:
    """(n, 3) [m] in R: the root pass's offset and weave at each knot of ``cp`` (each knot where the positioner
    holds it), laid in the curve's local cross-section (:func:`cell.planning.curves.weave.curve_offsets`), so in
    the part's frame, carried by the axes; and the weave's share of it (None without a weave)."""
    if procedure is None:
        return np.zeros((len(cp.s), 3)), None
    off = curve_offsets(cp, procedure)
    if not procedure.weave.active:
        return off, None
    return off, off - curve_offsets(cp, replace(procedure, weave=Weave()))


@dataclass(frozen=True)
class Setup:
    """What every candidate of one seam's coordinated weld shares: the arm, the positioner, the process, the
    planning options, the moving scene, where the arm starts (dof,) [rad], the weld procedure (None: the process's
    defaults) and its travel speed [m/s] and knot spacing [m]."""

    robot: RobotModel
    pos: TiltRotatePositioner
    process: WeldProcess
    opt: PlanOptions
    scene: MovingScene
    q_start: FloatArray
    procedure: WeldProcedure | None
    speed: float
    spacing: float

    @classmethod
    def of(cls, robot: RobotModel, pos: TiltRotatePositioner, process: WeldProcess, opt: PlanOptions,
           scene: MovingScene, q_start: FloatArray, procedure: WeldProcedure | None) -> Setup:  # fmt: skip
        proc = procedure or WeldProcedure(name="default")
        speed = proc.travel_speed_mm_s / 1000.0 if procedure is not None else process.travel_speed
        spacing = knot_spacing(procedure, 0, opt.spacing) if procedure is not None else opt.spacing  # follows a weave
        return cls(robot, pos, process, opt, scene, np.asarray(q_start, dtype=float), procedure, speed, spacing)


Candidate = tuple[bool, int, CurvePath, CurveInF, FloatArray]  # (reversed, tilt branch, path, in F, axes (n, 2))


def candidates(su: Setup, est: CurveEstimate) -> list[Candidate]:
    """Either way round ``est``, either tilt branch, whose axes hold it in PA within the limits: the weld point
    nearest the arm's shoulder first."""
    X_FR = np.asarray(np.linalg.inv(su.pos.X_R_F(*su.pos.home)), dtype=float)
    centre, _ = su.robot.reach_bound("torch_tcp")
    out = []
    for rev in (False, True):
        path = curve_path(est, su.spacing, reverse=rev, overlap=su.process.closed_overlap if est.closed else 0.0)
        curve = _in_F(X_FR, path)
        for branch in (1, -1):
            axes = pa_axes(su.pos, curve, branch)
            if axes is not None:
                p_R = knots_in_R(su.pos, curve, axes)[0]
                out.append((float(np.linalg.norm(p_R.mean(axis=0) - centre)), (rev, branch, path, curve, axes)))
    return [c for _, c in sorted(out, key=lambda c: c[0])]


def torch_poses(su: Setup, cand: Candidate, spin_deg: float) -> tuple[CurvePath, FloatArray, FloatArray | None]:
    """The candidate's knots where its axes hold them (in R), the torch X_RT (n, 4, 4) there at ``spin_deg`` with
    the pass's offset and weave, and the weave's share of that offset (None: no weave)."""
    _, _, path, curve, axes = cand
    p_R, t_R, na_R, nb_R = knots_in_R(su.pos, curve, axes)
    cp = CurvePath(p_R, t_R, na_R, nb_R, path.s, path.closed, path.overlap, path.start, path.reversed)
    off_R, weave_R = _offsets(cp, su.procedure)
    X_RT = np.array(curve_poses(cp, su.process, spin=math.radians(spin_deg)))
    X_RT[:, :3, 3] += off_R
    return cp, X_RT, weave_R


def solve_candidate(su: Setup, seam_id: str, cand: Candidate, spin_deg: float, rng: np.random.Generator,
                    t_wall: float) -> CoordinatedWeld:  # fmt: skip
    """The candidate welded at one spin: IK along its knots, the pieces timed and gated; MotionError otherwise."""
    robot, pos = su.robot, su.pos
    _, _, path, curve, axes = cand
    _, X_RT, weave_R = torch_poses(su, cand, spin_deg)
    proc = su.procedure or WeldProcedure(name="default")
    q0 = solve_ik(robot, X_RT[0], su.q_start, rng=rng)
    Q = np.asarray(solve_path(robot, X_RT, q0, max_joint_step=su.opt.max_joint_step))
    pieces, v = _motion(robot, pos, su.process, su.opt, X_RT, Q, axes, path.s, su.speed, proc,
                        (su.q_start, np.asarray(pos.home)))  # fmt: skip
    _gated(su.scene, pos, robot, pieces)
    times, x, arc, spans = _joined(pieces)
    slope, rot, within = positions(pos, curve, axes)
    X_FR_k = np.array([np.linalg.inv(pos.X_R_F(*a)) for a in axes])
    X_FT = X_FR_k @ X_RT
    weave_F = None if weave_R is None else np.einsum("nij,nj->ni", X_FR_k[:, :3, :3], weave_R)
    tcp = np.array([robot.fk(q)[:3, 3] for q in Q])
    spread = float(np.max(np.linalg.norm(tcp - tcp.mean(axis=0), axis=1))) * 1000.0
    dof = robot.dof
    return CoordinatedWeld(seam_id, times, x[:, :dof], x[:, dof:], arc, tuple(spans), Q, axes, X_FT, path.s, slope,
                           rot, within, v, path.closed, path.overlap, time.perf_counter() - t_wall, spread, weave_F,
                           su.procedure)  # fmt: skip


def plan_coordinated(
    robot: RobotModel,
    pos: TiltRotatePositioner,
    est: CurveEstimate,
    process: WeldProcess,
    opt: PlanOptions,
    scene: MovingScene,
    q_start: FloatArray,
    *,
    rng: np.random.Generator,
    procedure: WeldProcedure | None = None,
) -> CoordinatedWeld:
    """The coordinated weld of the located curve ``est`` (in R at the positioner's home) from the arm at
    ``q_start`` (dof,) and the positioner at home, back to both. Either way round the seam, either tilt branch,
    the spins ``SPINS_DEG`` tried until one is solved, timed and gated; PlanError with the last reason otherwise."""
    t_wall = time.perf_counter()
    su = Setup.of(robot, pos, process, opt, scene, q_start, procedure)
    cands = candidates(su, est)
    if not cands:
        raise PlanError(f"curved seam {est.id}: no tilt within the limits puts it in PA with the rotation's sweep")
    why = "no candidate tried"
    for cand in cands:
        for spin in SPINS_DEG:
            try:
                return solve_candidate(su, est.id, cand, spin, rng, t_wall)
            except MotionError as e:
                why = f"spin {spin:+.0f} deg: {e.message}"
    raise PlanError(f"curved seam {est.id}: no coordinated motion: {why}")
