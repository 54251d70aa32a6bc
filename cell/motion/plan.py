"""Detected seams -> an executable welding plan for the arm (values in, a frozen :class:`WeldPlan` out).

Per seam (:func:`plan_welds`):

1. Torch candidates: both weld directions x spins about the torch axis (``spin_step`` apart, within the
   process's spin tolerance) x work/travel angles (nominal first, then widened in ``angle_step`` steps within
   their tolerances, REFERENCE.md section 7). A candidate whose torch (placed by pose alone) hits a part or the
   table at a seam end is dropped without IK; the rest get IK at the weld start, ranked by manipulability.
2. The best candidates are solved along the seam (warm-started IK every ``spacing``, no joint jump beyond
   ``max_joint_step``), along the approach line (back along the torch axis to ``process.approach``) and the
   depart line, checked against singularities and for collisions (conservative advancement between knots).
   The first candidate that passes is kept; otherwise the seam is reported with the reason that got furthest,
   e.g. ``unreachable: IK did not converge at 35.0 mm along the seam``.
3. Timing: approach, weld and depart are straight TCP lines (KRL LIN): a one-axis Ruckig profile of the path
   length s(t) (``path_profile``) mapped through a C2 spline of the IK knots q(s); the weld runs at exactly the
   travel speed between its rest-to-rest ramps (arc on at an exact stop at the start, arc off at the exact stop
   at the end, before the depart), the approach at most at the reduced speed. Transfers between seams and
   from/to home are Ruckig point-to-point moves (KRL PTP); where the direct move collides, the torch goes
   straight up (a LIN, as a depart) to ``transfer_lift`` above the highest obstacle, across (PTP) and straight
   down (a LIN, as an approach), or else via home. A transfer that finds no free way is first avoided by
   re-ordering; if it cannot be, the seam is reported as a collision and skipped.
4. Order: greedy nearest neighbour then 2-opt on the point-to-point durations, home at both ends.

Frames: everything in the robot base frame R [m]; joints [rad]; time [s].
"""

from __future__ import annotations

import math
import time
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt
from scipy.interpolate import CubicSpline

from cell.errors import IKError, PlanError, TimingError
from cell.geometry import FloatArray, readonly
from cell.motion.collision import CollisionChecker, CollisionOptions
from cell.motion.ik import solve_ik
from cell.motion.program import SeamOutcome, SeamTask, Segment, SegmentKind, WeldPlan, seam_tasks
from cell.motion.robot import RobotModel
from cell.motion.timing import DEFAULT_DT, Trajectory, path_profile, ptp, ptp_duration
from cell.motion.torch import WeldProcess, back_off, line_poses, torch_poses
from cell.types import Part, WeldMap


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


# -- per-seam search -------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Candidate:
    reversed: bool
    spin: float
    work_offset: float
    travel_offset: float


@dataclass
class _Failure:
    kind: str  # unreachable | collision | singular | flip
    where: str
    p_R: FloatArray
    progress: float  # how far along approach + seam + depart the candidate got [m], for picking the best reason

    def reason(self) -> str:
        return f"{self.kind}: {self.where}"


@dataclass(frozen=True)
class _Solved:
    task: SeamTask
    cand: _Candidate
    X_weld: FloatArray  # (n, 4, 4)
    q_approach: FloatArray  # (m, dof) approach pose -> weld start
    q_weld: FloatArray  # (n, dof)
    q_depart: FloatArray  # (k, dof) weld end -> depart pose
    X_approach: FloatArray  # (4, 4) approach pose
    X_depart: FloatArray  # (4, 4)


class _Planner:
    def __init__(
        self,
        robot: RobotModel,
        process: WeldProcess,
        checker: CollisionChecker,
        options: PlanOptions,
        rng: np.random.Generator,
    ) -> None:
        self.robot, self.process, self.checker, self.opt, self.rng = robot, process, checker, options, rng

    def candidates(self) -> list[list[_Candidate]]:
        """Candidate groups, one per (work, travel) angle setting, nominal first then widening."""
        pr, opt = self.process, self.opt

        def offsets(tol: float, step: float) -> list[float]:
            """0, +-step, +-2 step, ... within +-tol, and +-tol itself."""
            k = math.floor(tol / step + 1e-9)
            out = [0.0] + [s * i * step for i in range(1, k + 1) for s in (1.0, -1.0)]
            if tol > k * step + 1e-9:
                out += [tol, -tol]
            return out

        angles = sorted(
            (
                (w, a)
                for w in offsets(pr.work_angle_tol, opt.angle_step)
                for a in offsets(pr.travel_angle_tol, opt.angle_step)
            ),
            key=lambda wa: (abs(wa[0]) + abs(wa[1]), abs(wa[0])),
        )
        spins = sorted(  # ordered so that neighbours warm-start each other's IK; pi and -pi coincide
            {round(s, 12) for s in offsets(pr.spin_tol, opt.spin_step) if -math.pi + 1e-9 < s <= math.pi + 1e-9}
        )
        return [[_Candidate(rev, sp, w, a) for rev in (False, True) for sp in spins] for w, a in angles]

    def plan_seam(self, task: SeamTask, q_seed: FloatArray) -> _Solved | _Failure:
        best_fail: _Failure | None = None
        pr, opt = self.process, self.opt
        for group in self.candidates():
            ranked: list[tuple[float, _Candidate, FloatArray, FloatArray]] = []
            q_prev: FloatArray | None = None
            for cand in group:
                a, b = (task.p_end, task.p_start) if cand.reversed else (task.p_start, task.p_end)
                X = torch_poses(
                    a,
                    b,
                    task.n_a,
                    task.n_b,
                    pr,
                    spin=cand.spin,
                    work_offset=cand.work_offset,
                    travel_offset=cand.travel_offset,
                    spacing=opt.spacing,
                )
                hit_start = self.checker.torch_clear(X[0], q_seed)
                hit = hit_start or self.checker.torch_clear(X[-1], q_seed)
                if hit is not None:
                    end = "start" if hit_start is not None else "end"
                    where = f"torch vs {hit.b} at the weld {end} (p_R = {_mm(hit.p_R)} mm)"
                    # ranks below an IK failure at the start: the pose was not even tried
                    best_fail = _better(best_fail, _Failure("collision", where, hit.p_R, -1e-3))
                    continue
                q0: FloatArray | None = None
                if q_prev is not None:  # warm start from the neighbouring candidate
                    try:
                        q0 = self._ik(X[0], q_prev)
                    except IKError:
                        q0 = None
                if q0 is None:
                    try:
                        q0 = self._ik(X[0], q_seed, restarts=True)
                    except IKError as exc:
                        best_fail = _better(best_fail, _unreachable(exc, X[0], 0.0, 0.0))
                        continue
                q_prev = q0
                ranked.append((self.robot.manipulability(q0), cand, X, q0))
            ranked.sort(key=lambda r: -r[0])
            for _, cand, X, q0 in ranked[: opt.max_full]:
                res = self.solve_candidate(task, cand, X, q0)
                if isinstance(res, _Solved):
                    return res
                best_fail = _better(best_fail, res)
        assert best_fail is not None
        return best_fail

    def _ik(self, X: FloatArray, seed: FloatArray, restarts: bool = False) -> FloatArray:
        return solve_ik(self.robot, X, seed, rng=self.rng if restarts else None)

    def _solve_line(self, X: FloatArray, q0: FloatArray, what: str, offset: float, step: float) -> FloatArray:
        """Warm-started IK along poses X (n, 4, 4) from q0 (the solution at X[0]); raises _LineError."""
        out = [q0]
        lim = self.robot.limits
        for i in range(1, len(X)):
            try:
                q = solve_ik(self.robot, X[i], out[-1])
            except IKError as exc:
                raise _LineError(_unreachable(exc, X[i], i * step, offset + i * step, what)) from exc
            jump = np.abs(q - out[-1])
            if float(jump.max()) > self.opt.max_joint_step:
                j = int(np.argmax(jump))
                raise _LineError(
                    _Failure(
                        "flip",
                        f"joint {lim.names[j]} jumps {math.degrees(jump[j]):.1f} deg at "
                        f"{i * step * 1000:.1f} mm along the {what}",
                        X[i][:3, 3].copy(),
                        offset + i * step,
                    )
                )
            out.append(q)
        return np.array(out)

    def solve_candidate(self, task: SeamTask, cand: _Candidate, X: FloatArray, q0: FloatArray) -> _Solved | _Failure:
        pr, opt = self.process, self.opt
        step = task.length / (len(X) - 1)
        try:
            q_weld = self._solve_line(X, q0, "seam", 0.0, step)
            X_app = back_off(X[0], pr.approach)
            app = line_poses(X[0], X_app, opt.line_spacing)  # from the weld start outwards
            # progress (for picking the most telling failure): seam first, then approach, then depart
            q_app = self._solve_line(app, q_weld[0], "approach", task.length, pr.approach / (len(app) - 1))[::-1]
            X_dep = back_off(X[-1], pr.depart)
            dep = line_poses(X[-1], X_dep, opt.line_spacing)
            q_dep = self._solve_line(dep, q_weld[-1], "depart", task.length + pr.approach, pr.depart / (len(dep) - 1))
        except _LineError as exc:
            return exc.failure
        path = np.concatenate([q_app, q_weld[1:], q_dep[1:]])
        poses = np.concatenate([app[::-1], X[1:], dep[1:]])
        s_path = np.concatenate(
            [
                -np.linspace(pr.approach, 0.0, len(app)),
                np.linspace(0.0, task.length, len(X))[1:],
                task.length + np.linspace(0.0, pr.depart, len(dep))[1:],
            ]
        )
        manip = np.array([self.robot.manipulability(q) for q in path])
        k = int(np.argmin(manip))
        if manip[k] < opt.min_manipulability:
            return _Failure(
                "singular",
                f"manipulability {manip[k]:.3g} < {opt.min_manipulability:g} at {_where(s_path[k], task.length)}",
                poses[k][:3, 3].copy(),
                float(s_path[k]),
            )
        hit = self.checker.check_path(path)
        if hit is not None:
            return _Failure(
                "collision",
                f"{hit.a} vs {hit.b} at {_where(s_path[hit.index], task.length)} (p_R = {_mm(hit.p_R)} mm)",
                hit.p_R,
                float(s_path[hit.index]),
            )
        return _Solved(task, cand, X, q_app, q_weld, q_dep, X_app, X_dep)


class _LineError(Exception):
    def __init__(self, failure: _Failure) -> None:
        super().__init__(failure.reason())
        self.failure = failure


def _mm(p: npt.ArrayLike) -> list[float]:
    return [float(v) for v in np.round(np.asarray(p, dtype=float) * 1000.0, 1)]


def _where(s: float, length: float) -> str:
    if s < 0.0:
        return f"{-s * 1000:.1f} mm before the seam start (approach)"
    if s > length + 1e-9:
        return f"{(s - length) * 1000:.1f} mm after the seam end (depart)"
    return f"{s * 1000:.1f} mm along the seam"


def _unreachable(exc: IKError, X: FloatArray, s: float, progress: float, what: str = "seam") -> _Failure:
    where = f"IK did not converge at {s * 1000:.1f} mm along the {what}"
    if "reach bound" in exc.message:
        where += " (beyond the arm's reach)"
    return _Failure("unreachable", where, X[:3, 3].copy(), progress)


def _better(a: _Failure | None, b: _Failure) -> _Failure:
    """The failure that got further along (ties: the earlier one, i.e. the nearer to nominal angles)."""
    return b if a is None or b.progress > a.progress + 1e-9 else a


# -- timing ----------------------------------------------------------------------------------------------------


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
    lim = robot.limits
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
        if max(rv, ra, rj) <= 0.98:
            q[0], q[-1] = Q[0], Q[-1]  # the knots exactly, not up to spline rounding
            qd[0] = qd[-1] = 0.0
            return Trajectory(prof.times, q, qd, qdd), v
        if rv > 0.98:
            if fixed_speed:
                k = int(np.argmax(np.max(np.abs(qd) / lim.v_max, axis=0)))
                raise TimingError(
                    f"joint {lim.names[k]} would move at {rv * 100:.0f} % of its velocity limit at the "
                    f"travel speed {speed * 1000:.1f} mm/s"
                )
            v *= 0.95 / rv
        if ra > 0.98:
            a *= 0.95 / ra
        if rj > 0.98:
            j *= 0.95 / rj
    raise TimingError(f"could not time a {length * 1000:.1f} mm line within the joint limits")


# -- assembly --------------------------------------------------------------------------------------------------


def _order(
    ids: list[str],
    entries: list[FloatArray],
    exits: list[FloatArray],
    q_home: FloatArray,
    robot: RobotModel,
    forbidden: Collection[tuple[str, str]] = (),
) -> list[int]:
    """Seam order by point-to-point duration: greedy nearest from home, then 2-opt (home fixed at both ends).

    forbidden : (from id, to id) transfers known to collide ("" = home); they cost a penalty, so they are used
    only when no order avoids them.
    """
    n = len(entries)
    if n <= 1:
        return list(range(n))
    lim = robot.limits
    penalty = 1e6  # [s]

    def dur(a: FloatArray, b: FloatArray, edge: tuple[str, str]) -> float:
        return ptp_duration(a, b, lim) + (penalty if edge in forbidden else 0.0)

    C = np.array([[dur(exits[i], entries[k], (ids[i], ids[k])) if i != k else 0.0 for k in range(n)] for i in range(n)])
    from_home = np.array([dur(q_home, e, ("", ids[k])) for k, e in enumerate(entries)])
    to_home = np.array([dur(x, q_home, (ids[k], "")) for k, x in enumerate(exits)])

    def cost(p: list[int]) -> float:
        return float(from_home[p[0]] + sum(C[p[i], p[i + 1]] for i in range(n - 1)) + to_home[p[-1]])

    left, tour = set(range(n)), [int(np.argmin(from_home))]
    left.remove(tour[0])
    while left:
        nxt = min(left, key=lambda k: C[tour[-1], k])
        tour.append(nxt)
        left.remove(nxt)
    best, improved = cost(tour), True
    while improved:
        improved = False
        for i in range(n - 1):
            for k in range(i + 1, n):
                cand = tour[:i] + tour[i : k + 1][::-1] + tour[k + 1 :]
                c = cost(cand)
                if c < best - 1e-9:
                    tour, best, improved = cand, c, True
    return tour


_Piece = tuple[SegmentKind, Trajectory, float, FloatArray]  # kind, trajectory, TCP speed (0: PTP), X_end


@dataclass(frozen=True)
class _TransferFail:
    reason: str
    p_R: FloatArray


class _Assembler:
    def __init__(self, planner: _Planner, obstacles: Sequence[Part], q_home: FloatArray) -> None:
        self.p = planner
        self.q_home = q_home
        tops = [float(np.max(o.box.corners()[:, 2])) for o in obstacles]
        self.lift_z = (max(tops) if tops else 0.0) + planner.opt.transfer_lift

    def transfer(self, q_a: FloatArray, q_b: FloatArray) -> list[_Piece] | _TransferFail:
        """Collision-free motion q_a -> q_b: a direct PTP; else straight up (LIN) to the lift height, PTP across,
        straight down; the same higher; else PTP via home. The last contact when every way collides."""
        fail = _TransferFail("no collision-free way found", np.zeros(3))
        for strategy in ("direct", "lift", "lift_high", "home"):
            try:
                pieces = self._pieces(q_a, q_b, strategy)
            except (IKError, TimingError, _LineError) as exc:
                fail = _TransferFail(f"{strategy}: {exc}", fail.p_R)
                continue
            hit = next((h for pc in pieces if (h := self.p.checker.check_path(pc[1].q, pc[1].times)) is not None), None)
            if hit is None:
                return [pc for pc in pieces if pc[1].duration > 0.0]
            fail = _TransferFail(hit.describe(), hit.p_R)
        return fail

    def _pieces(self, q_a: FloatArray, q_b: FloatArray, strategy: str) -> list[_Piece]:
        robot, lim, opt = self.p.robot, self.p.robot.limits, self.p.opt
        if strategy == "direct":
            return [("move", ptp(q_a, q_b, lim, dt=opt.dt), 0.0, robot.fk(q_b))]
        if strategy == "home":
            return [
                ("move", ptp(q_a, self.q_home, lim, dt=opt.dt), 0.0, robot.fk(self.q_home)),
                ("move", ptp(self.q_home, q_b, lim, dt=opt.dt), 0.0, robot.fk(q_b)),
            ]
        h = self.lift_z + (opt.transfer_lift if strategy == "lift_high" else 0.0)
        up = self._vertical(q_a, h, up=True)
        down = self._vertical(q_b, h, up=False)
        top_a = up[1].q[-1] if up else q_a
        top_b = down[1].q[0] if down else q_b
        pieces = [up] if up else []
        pieces.append(("move", ptp(top_a, top_b, lim, dt=opt.dt), 0.0, robot.fk(top_b)))
        if down:
            pieces.append(down)
        return pieces

    def _vertical(self, q: FloatArray, height: float, up: bool) -> _Piece | None:
        """A straight vertical TCP line between q's pose and the same pose at ``height`` in R (None when q is
        already that high): up from q (a depart) or down to q (an approach)."""
        robot, pr, opt = self.p.robot, self.p.process, self.p.opt
        X = robot.fk(q)
        rise = height - float(X[2, 3])
        if rise < 1e-3:
            return None
        X_top = X.copy()
        X_top[2, 3] = height
        poses = line_poses(X, X_top, opt.line_spacing)
        knots = self.p._solve_line(poses, q, "lift", 0.0, rise / (len(poses) - 1))
        if up:
            tr, v = line_trajectory(
                robot,
                knots,
                rise,
                np.array([0.0, 0.0, 1.0]),
                pr.approach_speed,
                opt.line_accel,
                opt.line_jerk,
                dt=opt.dt,
            )
            return ("depart", tr, v, X_top)
        tr, v = line_trajectory(
            robot,
            knots[::-1],
            rise,
            np.array([0.0, 0.0, -1.0]),
            pr.approach_speed,
            opt.line_accel,
            opt.line_jerk,
            dt=opt.dt,
        )
        return ("approach", tr, v, X)

    def seam_segments(self, sol: _Solved) -> list[_Piece]:
        """(kind, trajectory, TCP speed, X_end) of approach, weld and depart."""
        p, pr, opt = self.p, self.p.process, self.p.opt
        X = sol.X_weld
        z = X[0][:3, 2]
        d = X[-1][:3, 3] - X[0][:3, 3]
        d /= np.linalg.norm(d)
        app, v_app = line_trajectory(
            p.robot, sol.q_approach, pr.approach, z, pr.approach_speed, opt.line_accel, opt.line_jerk, dt=opt.dt
        )
        weld, v_weld = line_trajectory(
            p.robot,
            sol.q_weld,
            sol.task.length,
            d,
            pr.travel_speed,
            opt.weld_accel,
            opt.weld_jerk,
            fixed_speed=True,
            dt=opt.dt,
        )
        dep, v_dep = line_trajectory(
            p.robot,
            sol.q_depart,
            pr.depart,
            -X[-1][:3, 2],
            pr.approach_speed,
            opt.line_accel,
            opt.line_jerk,
            dt=opt.dt,
        )
        return [
            ("approach", app, v_app, X[0]),
            ("weld", weld, v_weld, X[-1]),
            ("depart", dep, v_dep, sol.X_depart),
        ]


def plan_welds(
    robot: RobotModel,
    tasks: Sequence[SeamTask],
    q_home: npt.ArrayLike,
    process: WeldProcess,
    obstacles: Sequence[Part] = (),
    *,
    options: PlanOptions | None = None,
    rng: np.random.Generator | None = None,
    checker: CollisionChecker | None = None,
) -> WeldPlan:
    """Plan every seam that can be welded, skip and report the others (see the module docstring).

    tasks : the seams, in R (underside seams are not passed in: the caller marks them "needs a flip").
    q_home : (dof,) [rad] where the program starts and ends. obstacles : parts and table, boxes in R.
    rng : for IK restarts (deterministic for a seeded generator; default seed 0).
    Raises PlanError when q_home is outside the limits or in collision; a seam that cannot be planned is a
    SeamOutcome with ``feasible=False`` and its reason, never an exception.
    """
    t_start = time.perf_counter()
    opt = options or PlanOptions()
    q0 = np.asarray(q_home, dtype=float)
    if q0.shape != (robot.dof,) or not robot.limits.contains(q0):
        raise PlanError(f"home configuration {np.round(np.degrees(q0), 2).tolist()} deg is outside the joint limits")
    checker = checker or CollisionChecker(robot, obstacles, opt.collision)
    hit = checker.check(q0)
    if hit is not None:
        raise PlanError(f"home configuration is in collision: {hit.describe()}")
    planner = _Planner(robot, process, checker, opt, rng or np.random.default_rng(0))
    outcomes: dict[str, SeamOutcome] = {}
    solved: dict[str, _Solved] = {}
    for task in tasks:
        res = planner.plan_seam(task, q0)
        if isinstance(res, _Failure):
            outcomes[task.id] = SeamOutcome(task.id, False, res.reason(), readonly(res.p_R))
        else:
            solved[task.id] = res

    asm = _Assembler(planner, obstacles, q0)
    seam_parts: dict[str, list[_Piece]] = {}
    for sid in list(solved):
        try:
            seam_parts[sid] = asm.seam_segments(solved[sid])
        except TimingError as exc:
            sol = solved.pop(sid)
            outcomes[sid] = SeamOutcome(sid, False, f"timing: {exc.message}", readonly(sol.X_weld[0][:3, 3]))
    forbidden: set[tuple[str, str]] = set()
    while True:
        ids = list(solved)
        order = _order(
            ids,
            [solved[i].q_approach[0] for i in ids],
            [solved[i].q_depart[-1] for i in ids],
            q0,
            robot,
            forbidden,
        )
        ordered = [ids[k] for k in order]
        segments, failed = _assemble(asm, ordered, solved, seam_parts, q0, robot)
        if failed is None:
            break
        a, b, why = failed
        if (a, b) not in forbidden and len(ids) > 1:
            forbidden.add((a, b))  # try an order without this transfer first
            continue
        drop = b or a  # the seam this transfer leads to (or, on the way home, comes from)
        solved.pop(drop)
        direction = "to" if b else "from"
        outcomes[drop] = SeamOutcome(
            drop, False, f"collision: no free transfer move {direction} the seam: {why.reason}", readonly(why.p_R)
        )
    for sid, sol in solved.items():
        c = sol.cand
        outcomes[sid] = SeamOutcome(
            sid,
            True,
            "",
            np.zeros(0),
            c.reversed,
            c.spin,
            process.work_angle + c.work_offset,
            process.travel_angle + c.travel_offset,
        )
    return WeldPlan(
        joint_names=robot.joint_names,
        q_home=readonly(q0),
        segments=tuple(segments),
        seams=tuple(outcomes[t.id] for t in tasks),
        order=tuple(ordered),
        planning_s=time.perf_counter() - t_start,
    )


def _assemble(
    asm: _Assembler,
    ordered: list[str],
    solved: Mapping[str, _Solved],
    seam_parts: Mapping[str, list[_Piece]],
    q_home: FloatArray,
    robot: RobotModel,
) -> tuple[list[Segment], tuple[str, str, _TransferFail] | None]:
    """Segments back to back; or the first transfer (from id, to id; "" = home) that found no free way."""
    segments: list[Segment] = []
    t = 0.0

    def add(kind: SegmentKind, sid: str, tr: Trajectory, speed: float, X_end: FloatArray) -> None:
        nonlocal t
        if tr.duration <= 0.0:
            return
        segments.append(Segment(kind, sid, tr, t, readonly(X_end), speed, kind == "weld"))
        t += tr.duration

    q, prev = q_home, ""
    for sid in [*ordered, ""]:
        q_next = solved[sid].q_approach[0] if sid else q_home
        moves = asm.transfer(q, q_next)
        if isinstance(moves, _TransferFail):
            return segments, (prev, sid, moves)
        for kind, tr, speed, X_end in moves:
            add(kind, sid, tr, speed, X_end)
        if sid:
            for kind, tr, speed, X_end in seam_parts[sid]:
                add(kind, sid, tr, speed, X_end)
            q, prev = solved[sid].q_depart[-1], sid
    return segments, None


def scan_configuration(
    robot: RobotModel,
    X_RC_desired: npt.ArrayLike,
    q_seed: npt.ArrayLike,
    *,
    rng: np.random.Generator | None = None,
    frame: str = "camera_optical",
) -> FloatArray:
    """Joint values (dof,) [rad] that put the eye-in-hand camera's optical frame at X_RC_desired (4, 4) in R.

    Only the camera position and its optical axis (z) are matched: the rotation about the optical axis is left
    free (the image turns in its plane; the cloud is the same). Raises IKError when the view cannot be reached.
    """
    return solve_ik(robot, X_RC_desired, q_seed, frame=frame, rng=rng, free_axis=True)


def cell_obstacles(
    weldmap_R: WeldMap,
    X_WR: npt.ArrayLike,
    table_center_W: npt.ArrayLike,
    table_size: npt.ArrayLike,
    table_name: str = "TABLE",
) -> tuple[Part, ...]:
    """The obstacles of a welding cell in R: the aligned map's parts (as perceived) and the table box, given by
    its centre in the world [m] and its size (3,) [m] (X_WR (4, 4): the robot base in the world)."""
    from cell.geometry import invert, make_pose
    from cell.types import Box

    X_RW = invert(np.asarray(X_WR, dtype=float))
    table = Part(table_name, Box(X_RW @ make_pose(p=table_center_W), np.asarray(table_size, dtype=float)))
    return (*weldmap_R.parts, table)


__all__ = [
    "PlanOptions",
    "SeamOutcome",
    "SeamTask",
    "Segment",
    "SegmentKind",
    "WeldPlan",
    "cell_obstacles",
    "line_trajectory",
    "plan_welds",
    "scan_configuration",
    "seam_tasks",
]
