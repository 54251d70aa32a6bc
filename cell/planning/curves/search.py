"""The torch search for one curved seam: where a closed curve's weld starts and which way it runs, the spin about
the torch axis and the work/travel angle offsets; each candidate previewed by IK at a few points along the curve
(does A6's travel fit its hose window, how near a singularity), the best solved along the whole curve, its
approach and depart, with the straight search's checks (docs/curves-welding.md section 2).

Frames: everything in the robot base frame R [m]; joints [rad]."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from cell.errors import IKError, PlanError
from cell.geometry import FloatArray, readonly
from cell.motion.ik import solve_ik
from cell.motion.wrist import nearest_wrist
from cell.planning.curves.path import CurvePath, curve_path, curve_poses, start_order
from cell.planning.curves.weave import woven
from cell.planning.failures import SeamFailure, better, mm, unreachable
from cell.planning.seam_search import SeamSearch, SeamSolution
from cell.process.torch_orientations import Candidate, candidate_groups
from cell.process.weave import knot_spacing as weave_spacing
from cell.types.curve_estimate import CurveEstimate
from cell.types.plan import PlanReason, SeamTask
from cell.types.procedure import WeldProcedure
from cell.types.robot import JointLimits

TURN_PER_KNOT = math.radians(2.0)  # [rad] the tangent turns at most this much between two IK knots
SHORT_MOVES = (0.025, 0.012)  # [m] the approach and depart tried shorter when the full ones fail
FREE_SPINS = 4  # start spins tried with the spin left to the arm along the curve
START_SEEDS = 6  # random IK seeds tried at the weld start for an arm clear of the parts and itself
STARTS = 8  # where a closed curve's weld may start: this many points evenly round it
PREVIEW_POINTS = 16  # IK at least at this many points along the curve to rank a candidate before the full solve
PREVIEW_STRIDE = 6  # and at least at every this many knots (the torch turns at most 12 deg between them)
_GROUPS = 2  # angle settings tried (nominal first), as the straight search widens them


@dataclass(frozen=True)
class CurveTask(SeamTask):
    """A curved seam to weld: a :class:`SeamTask` whose ends are the weld's first and last points and whose
    length is the curve's (``path``: the curve resampled from its start, :class:`CurvePath`); n_a, n_b the faces'
    normals at the start."""

    path: CurvePath | None = None

    @property
    def length(self) -> float:
        return self.path.length if self.path is not None else super().length


def curve_task(est_id: str, path: CurvePath) -> CurveTask:
    """The task of a curved seam welded along ``path``."""
    return CurveTask(est_id, path.p_R[0], path.p_R[-1], path.n_a_R[0], path.n_b_R[0], path)


@dataclass(frozen=True)
class _Preview:
    cand: Candidate
    task: CurveTask
    X: FloatArray
    q0: FloatArray
    a6_excess: float
    manip: float


def plan_curve(
    search: SeamSearch, est: CurveEstimate, q_seed: FloatArray, procedure: WeldProcedure | None = None
) -> SeamSolution | SeamFailure:
    """The first candidate that passes along the whole curve (its task a :class:`CurveTask`), or the failure that
    got furthest; q_seed (dof,) [rad] seeds IK.

    A closed curve is tried from :data:`STARTS` starts (nearest the robot base first) in both directions (one if
    the process is not reversible) and welded on past its start by ``process.closed_overlap``; an open one from
    either end. Per angle setting every (start, direction, spin) is previewed by IK at :data:`PREVIEW_POINTS`
    points or more, warm-started along the curve, its A6 moved by whole turns to centre its travel in the hose window;
    those whose A6 fits, then by their least manipulability, are solved along the whole curve, ``max_full`` of
    them. procedure : the seam's weld procedure: its root pass's offset and weave laid along the curve
    (:mod:`cell.planning.curves.weave`), the knots close enough to follow the weave."""
    pr, opt = search.process, search.opt
    overlap = pr.closed_overlap if est.closed else 0.0
    starts = start_order(est, np.zeros(3), STARTS) if est.closed else [0.0]
    directions = (False, True) if pr.reversible else (False,)
    q_ref = search._reference(q_seed)
    best: SeamFailure | None = None
    spacing = knot_spacing(est, opt.spacing)
    if procedure is not None:
        spacing = weave_spacing(procedure, 0, spacing)
    paths = [
        (rev, curve_path(est, spacing, start=s0, reverse=rev, overlap=overlap)) for s0 in starts for rev in directions
    ]
    flange = _flange_axes(search, q_seed, curve_poses(paths[0][1], pr)[:, :3, 2])
    free_spin = pr.spin_tol >= math.pi - 1e-9
    for group in candidate_groups(pr, opt)[:_GROUPS]:
        spins = sorted((c for c in group if not c.reversed), key=lambda c: abs(c.spin))  # the direction: the path's
        found: list[_Preview] = []
        for rev, path in paths:
            task = curve_task(est.id, path)
            for c, free in [(c, True) for c in spins[:FREE_SPINS] if free_spin] + [(c, False) for c in spins]:
                cand = Candidate(rev, c.spin, c.work_offset, c.travel_offset)
                X = curve_poses(
                    path, pr, spin=c.spin, work_offset=c.work_offset, travel_offset=c.travel_offset, flange=flange
                )
                X = woven(X, path, procedure)
                got = _preview(search, task, cand, X, q_seed, q_ref, free)
                if isinstance(got, SeamFailure):
                    best = better(best, got)
                else:
                    found.append(got)
        found.sort(key=lambda f: (f.a6_excess > 0.0, -f.manip))  # the wrist's margin at its worst, ends included
        for f in found[: opt.max_full]:
            res = _solved(search, f)
            if isinstance(res, SeamSolution):
                return res
            best = better(best, res)
    if best is None:
        raise PlanError(f"curved seam {est.id}: the torch search tried no candidate")
    return best


def _solved(search: SeamSearch, f: _Preview) -> SeamSolution | SeamFailure:
    """One previewed candidate solved along the whole curve; when the curve passes but its approach or depart
    does not (the torch backed off along its axis beyond reach or into a part), solved again with them shortened
    to each of :data:`SHORT_MOVES` [m] in turn: the torch clears the joint by a shorter way off."""
    res = search.solve_candidate(f.task, f.cand, f.X, f.q0)
    pr = search.process
    for d in SHORT_MOVES:
        if not isinstance(res, SeamFailure) or 0.0 <= res.progress < f.task.length - 1e-9:
            break
        short = SeamSearch(search.robot, replace(pr, approach=min(pr.approach, d), depart=min(pr.depart, d)),
                           search.checker, search.opt, search.rng, search.reach, search.memo)  # fmt: skip
        again = short.solve_candidate(f.task, f.cand, f.X, f.q0)
        if isinstance(again, SeamSolution):
            return again
        res = better(res, again)
    return res


def knot_spacing(est: CurveEstimate, spacing: float) -> float:
    """The IK knots' spacing [m] along a curve: ``spacing``, closer where the curve is tight enough that its tangent
    would turn more than :data:`TURN_PER_KNOT` between two knots (a 24 mm post: 0.8 mm). The torch turns with the
    tangent, and the flip test bounds each joint's step between knots."""
    t = est.tangent_R
    step = np.linalg.norm(np.diff(np.asarray(est.p_RS), axis=0), axis=1)
    turn = np.arccos(np.clip(np.sum(t[1:] * t[:-1], axis=1), -1.0, 1.0))
    ok = step > 1e-9
    per_m = float(np.max(turn[ok] / step[ok])) if np.any(ok) else 0.0  # the largest curvature [1/m]
    return min(spacing, TURN_PER_KNOT / per_m) if per_m > 0.0 else spacing


def _flange_axes(search: SeamSearch, q_home: FloatArray, z_R: FloatArray) -> tuple[FloatArray, FloatArray]:
    """(z_T, a_R): the flange's axis in the torch frame, and the way in R to hold it: of the flange's axis at q_home
    (dof,), up, down and the four horizontal axes, the one that keeps furthest from the torch's axes z_R (n, 3)
    along the curve (held towards a torch axis, the flange's way would turn on the spot: a wrist flip); the home
    axis on a tie."""
    X_RF = search.robot.fk(q_home, "tool0")
    X_RT = search.robot.fk(q_home)
    z_T = np.asarray(X_RT[:3, :3].T @ X_RF[:3, 2])
    refs = [X_RF[:3, 2], *np.vstack([np.eye(3), -np.eye(3)])[[2, 5, 0, 3, 1, 4]]]
    clearance = [float(np.min(1.0 - np.abs(z_R @ r))) for r in refs]
    best = int(np.argmax(np.round(clearance, 3)))
    return z_T, np.asarray(refs[best])


def _clear_start(search: SeamSearch, X0: FloatArray, q_seed: FloatArray, q_ref: FloatArray) -> FloatArray:
    """IK at the weld start X0 (4, 4) with the wrist the cell prefers (:func:`nearest_wrist`), from q_seed (dof,)
    then from up to :data:`START_SEEDS` random seeds (the search's generator) until the arm is clear of the parts
    and of itself there (an arm folded on itself at the start would be so along the curve); the first solution
    when none is clear. Raises IKError when none converges."""
    robot, lim = search.robot, search.robot.limits
    first: FloatArray | None = None
    seeds = [np.asarray(q_seed, dtype=float)] + [search.rng.uniform(lim.q_min, lim.q_max) for _ in range(START_SEEDS)]
    error: IKError | None = None
    for seed in seeds:
        try:
            q = nearest_wrist(robot, solve_ik(robot, X0, seed, options=search.opt.ik), q_ref, search.window)
        except IKError as exc:
            error = error or exc
            continue
        if search.checker.check(q) is None:
            return q
        first = q if first is None else first
    if first is None:
        assert error is not None
        raise error
    return first


def _preview(
    search: SeamSearch,
    task: CurveTask,
    cand: Candidate,
    X: FloatArray,
    q_seed: FloatArray,
    q_ref: FloatArray,
    free: bool,
) -> _Preview | SeamFailure:
    """IK at the start (restarts from q_seed), then along the curve, each knot warm-started from the last: with
    ``free`` at every knot, the spin about the torch axis left to the arm (the least joint motion: the poses then
    become the ones the arm took, X by forward kinematics), else at points every :data:`PREVIEW_STRIDE` knots
    (at least :data:`PREVIEW_POINTS`) of the poses X. The wrist moved by whole turns so that A4 and A6 are centred
    (:func:`_turns`); a joint that would travel beyond its limits, or jump (``max_joint_step`` between knots), or
    the arm against a part or itself at one of :data:`PREVIEW_POINTS` points, fails."""
    robot, window, opt = search.robot, search.window, search.opt
    try:
        q0 = _clear_start(search, X[0], q_seed, q_ref)
    except IKError as exc:
        return unreachable(exc, X[0], 0.0, 0.0)
    if free:
        idx = np.arange(len(X))
    else:
        count = max(PREVIEW_POINTS, math.ceil((len(X) - 1) / PREVIEW_STRIDE))
        idx = np.unique(np.linspace(0, len(X) - 1, count + 1).round().astype(int))
    qs = [q0]
    for k, i in enumerate(idx[1:], 1):
        s = task.length * i / (len(X) - 1)
        try:
            q = solve_ik(robot, X[i], qs[-1], free_axis=free, options=opt.ik)
        except IKError as exc:
            return unreachable(exc, X[i], s, s * 0.5 * k / len(idx))
        jump = np.abs(np.angle(np.exp(1j * (q - qs[-1]))))
        if free and float(jump.max()) > opt.max_joint_step:
            j = int(np.argmax(jump))
            where = f"joint {robot.limits.names[j]} jumps {math.degrees(jump[j]):.1f} deg at {s * 1000:.1f} mm"
            where += " along the seam"
            return SeamFailure(PlanReason.FLIP, where, X[i][:3, 3].copy(), s * 0.5 * k / len(idx))
        qs.append(q)
    Q = np.array(qs)
    Q[:, -3:] = np.unwrap(Q[:, -3:], axis=0)  # IK wraps a multi-turn joint at its limit: follow it round
    Q = Q + _turns(Q, window.center, robot.limits)
    lim = robot.limits
    over = np.maximum(Q - lim.q_max, lim.q_min - Q).max(axis=0)
    if float(over.max()) > 1e-9:
        j = int(np.argmax(over))
        travel = math.degrees(float(np.ptp(Q[:, j])))
        where = f"{lim.names[j]} would travel {travel:.0f} deg along the curve, beyond its limits"
        return SeamFailure(PlanReason.FLIP, where, X[0][:3, 3].copy(), 0.0)
    for k in range(0, len(Q), max(1, len(Q) // PREVIEW_POINTS)):
        hit = search.checker.check(Q[k])
        if hit is not None:  # the arm against a part or itself somewhere along the curve: not worth a full solve
            s = task.length * idx[k] / (len(X) - 1)
            where = f"{hit.a} vs {hit.b} at {s * 1000:.1f} mm along the seam (p_R = {mm(hit.p_R)} mm)"
            return SeamFailure(PlanReason.COLLISION, where, hit.p_R, s * 0.5)
    a6 = Q[:, -1]
    excess = max(float(np.max(np.abs(a6 - window.center))) - window.half_width, 0.0)
    manip = min(robot.manipulability(q) for q in [*Q[:: max(1, len(Q) // 32)], Q[-1]])
    if free:
        X = readonly(np.stack([robot.fk(q) for q in Q]))
    return _Preview(cand, task, X, Q[0], excess, manip)


def _turns(Q: FloatArray, a6_centre: float, limits: JointLimits) -> FloatArray:
    """(dof,) the whole turns [rad] to add to A4 and A6 (and to nothing else) so that each one's travel over Q
    (n, dof) is centred, A4 in its limits, A6 on ``a6_centre``, as far as the joint limits allow (0 for a joint no
    turn keeps within them)."""
    shift = np.zeros(Q.shape[1])
    a4_centre = 0.5 * float(limits.q_min[-3] + limits.q_max[-3])
    for j, centre in ((-3, a4_centre), (-1, a6_centre)):
        mid = 0.5 * (float(Q[:, j].min()) + float(Q[:, j].max()))
        k = round((centre - mid) / (2.0 * math.pi))
        for kk in sorted({k, k - 1, k + 1, 0}, key=lambda v: abs(v - k)):
            v = Q[:, j] + 2.0 * math.pi * kk
            if np.all(v >= limits.q_min[j] - 1e-9) and np.all(v <= limits.q_max[j] + 1e-9):
                shift[j] = 2.0 * math.pi * kk
                break
    return shift
