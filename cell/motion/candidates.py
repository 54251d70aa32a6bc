"""The torch search for one seam (step 1 and 2 of :func:`cell.motion.plan.plan_welds`).

1. Candidates (:func:`cell.motion.torch_candidates.candidate_groups`: weld directions x spins x work/travel
   angles, nominal first).
   A candidate whose torch (placed by pose alone) hits a part or the table at a seam end is dropped without IK;
   the rest get IK at the weld start, each held with the wrist equivalent (:mod:`cell.motion.wrist`: A4 and A6
   turned by whole turns, the flipped wrist) with A6 in the hose package's window, on home's side of the wrist
   (A5's sign) and nearest the reference wrist every seam shares. They are ranked: A6 in the window first, then
   those within ``_GOOD`` of the best start manipulability, nearest that reference first (so the free spin
   keeps A6 near the window's centre), then the rest by manipulability.
2. The best candidates are solved along the seam (warm-started IK every ``spacing``, no joint jump beyond
   ``max_joint_step``), along the approach line (back along the torch axis to ``process.approach``) and the
   depart line, checked against singularities and for collisions (conservative advancement between knots).
   A candidate whose A6 leaves the hose window anywhere on approach, seam or depart fails.
   The first candidate that passes is kept (:class:`SeamSolution`); otherwise the failure that got furthest
   (:class:`~cell.motion.failures.SeamFailure`), e.g. ``unreachable: IK did not converge at 35.0 mm along the
   seam``.

Frames: everything in the robot base frame R [m]; joints [rad].
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cell.errors import IKError, PlanError
from cell.geometry import FloatArray, make_pose, readonly, rot_z
from cell.motion.collision import CollisionChecker, Contact
from cell.motion.failures import LineError, SeamFailure, better, mm, unreachable, where_on_path
from cell.motion.ik import solve_ik
from cell.motion.lines import solve_line
from cell.motion.plan_options import PlanOptions
from cell.motion.reach import ReachModel, seam_reach
from cell.motion.robot import RobotModel
from cell.motion.torch import WeldProcess, back_off, line_poses, torch_rotation
from cell.motion.torch_candidates import Candidate, candidate_groups
from cell.motion.wrist import HoseWindow, nearest_wrist, wrist_cost
from cell.types.plan import PlanReason, SeamTask

_GOOD = 0.6  # candidates within this share of the best start manipulability are ranked by their wrist


@dataclass(frozen=True)
class SeamSolution:
    """A candidate solved along approach, seam and depart: the weld poses X_weld (n, 4, 4), joint knots
    q_approach (m, dof) from the approach pose to the weld start, q_weld (n, dof), q_depart (k, dof) from the weld
    end to the depart pose, and the approach and depart poses X_approach, X_depart (4, 4)."""

    task: SeamTask
    cand: Candidate
    X_weld: FloatArray
    q_approach: FloatArray
    q_weld: FloatArray
    q_depart: FloatArray
    X_approach: FloatArray
    X_depart: FloatArray


class SeamSearch:
    """The per-seam torch search for one arm, process, scene and options (see the module docstring)."""

    def __init__(
        self,
        robot: RobotModel,
        process: WeldProcess,
        checker: CollisionChecker,
        options: PlanOptions,
        rng: np.random.Generator,
        reach: ReachModel | None = None,
    ) -> None:
        self.robot, self.process, self.checker, self.opt, self.rng = robot, process, checker, options, rng
        self.window = HoseWindow(options.a6_center, options.a6_window)
        self.reach = reach

    def _reference(self, q_seed: FloatArray) -> FloatArray:
        """The wrist every seam is held near: q_seed (dof,) [rad] with A6 at the hose window's centre."""
        q_ref = np.array(q_seed, dtype=float)
        q_ref[-1] = self.window.center
        return q_ref

    def _ranked(
        self, found: list[tuple[Candidate, FloatArray, FloatArray]], q_ref: FloatArray
    ) -> list[tuple[Candidate, FloatArray, FloatArray]]:
        """The candidates (cand, X, q0) in the order to solve them: A6 at the start within the hose window first;
        then those whose manipulability at the start is within ``_GOOD`` of the group's best, nearest the
        reference wrist q_ref (dof,) first; then the rest by manipulability."""
        manip = [self.robot.manipulability(q0) for _, _, q0 in found]
        best = max(manip, default=0.0)

        def key(k: int) -> tuple[bool, bool, float, float]:
            q0 = found[k][2]
            good = manip[k] >= _GOOD * best
            return self.window.excess(q0) > 0.0, not good, wrist_cost(q0, q_ref) if good else 0.0, -manip[k]

        return [found[k] for k in sorted(range(len(found)), key=key)]

    def plan_seam(self, task: SeamTask, q_seed: FloatArray) -> SeamSolution | SeamFailure:
        """The first candidate that passes, or the failure that got furthest; q_seed (dof,) [rad] seeds IK.

        With a reach model, a seam out of reach for every torch within the process's angles fails at once
        (BEYOND_REACH, no candidate built), and a candidate whose wrist centre is out of reach anywhere along the
        seam is dropped before IK."""
        pr, opt = self.process, self.opt
        if self.reach is not None:
            out = seam_reach(self.reach, task, pr)
            if out is not None:
                return out
        best_fail: SeamFailure | None = None
        q_ref = self._reference(q_seed)
        rotations: dict[tuple[bool, float, float], FloatArray] = {}
        for group in candidate_groups(pr, opt):
            found: list[tuple[Candidate, FloatArray, FloatArray]] = []
            q_prev: FloatArray | None = None
            for cand, (R, hit_start, hit_end) in zip(
                group, self._torch_tests(task, group, rotations, q_seed, _wording(best_fail)), strict=True
            ):
                placed = self._place(task, cand, R, hit_start, hit_end, best_fail)
                if not isinstance(placed, np.ndarray):
                    best_fail = best_fail if placed is None else better(best_fail, placed)
                    continue
                X = placed
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
                        best_fail = better(best_fail, unreachable(exc, X[0], 0.0, 0.0))
                        continue
                q_prev = q0
                q0 = nearest_wrist(self.robot, q0, q_ref, self.window)
                found.append((cand, X, q0))
            for cand, X, q0 in self._ranked(found, q_ref)[: opt.max_full]:
                res = self.solve_candidate(task, cand, X, q0)
                if isinstance(res, SeamSolution):
                    return res
                best_fail = better(best_fail, res)
        if best_fail is None:  # cannot happen: there is always the nominal candidate, and it passes or fails
            raise PlanError(f"seam {task.id}: the torch search tried no candidate")
        return best_fail

    def placeable(self, task: SeamTask, q_seed: FloatArray) -> SeamFailure | None:
        """None when some candidate's torch can be placed on the seam (the reach pre-check, clear of the obstacles
        at both weld ends, its wrist centre in reach all along: what :meth:`plan_seam` checks before any IK);
        else the failure :meth:`plan_seam` would report, found without IK (tens of ms for a seam that fails)."""
        pr = self.process
        if self.reach is not None:
            out = seam_reach(self.reach, task, pr)
            if out is not None:
                return out
        best_fail: SeamFailure | None = None
        rotations: dict[tuple[bool, float, float], FloatArray] = {}
        for group in candidate_groups(pr, self.opt):
            for cand, (R, hit_start, hit_end) in zip(
                group, self._torch_tests(task, group, rotations, q_seed, _wording(best_fail)), strict=True
            ):
                placed = self._place(task, cand, R, hit_start, hit_end, best_fail)
                if isinstance(placed, np.ndarray):
                    return None
                best_fail = best_fail if placed is None else better(best_fail, placed)
        return best_fail

    def _torch_tests(
        self,
        task: SeamTask,
        group: list[Candidate],
        rotations: dict[tuple[bool, float, float], FloatArray],
        q_seed: FloatArray,
        worded: bool = True,
    ) -> list[tuple[FloatArray, Contact | None, Contact | None]]:
        """Per candidate of a group: its torch rotation R_RT (3, 3) and the torch's contact with the obstacles at
        the weld start and at the weld end (placed by pose alone; all the group's poses in one query).
        rotations : the spin-free torch rotations so far, shared by a group's spins. worded : the deepest
        contact of each pose (for the failure's words), else its first (a failure kept already ranks higher)."""
        pr = self.process
        Rs, tips_a, tips_b = [], [], []
        for cand in group:
            a, b = (task.p_end, task.p_start) if cand.reversed else (task.p_start, task.p_end)
            key = (cand.reversed, cand.work_offset, cand.travel_offset)
            if key not in rotations:
                rotations[key] = torch_rotation(
                    (b - a) / task.length,
                    task.n_a,
                    task.n_b,
                    pr.work_angle + cand.work_offset,
                    pr.travel_angle + cand.travel_offset,
                )
            Rs.append(rotations[key] @ rot_z(cand.spin))
            tips_a.append(a)
            tips_b.append(a + task.length * ((b - a) / task.length))  # as _poses places the last pose
        # the two end poses of every candidate, as _poses places them (wire tip standoff back along z)
        R_all = np.array(Rs)
        back = pr.standoff * R_all[:, :, 2]
        starts = np.zeros((len(group), 4, 4))
        starts[:, :3, :3], starts[:, 3, 3] = R_all, 1.0
        ends = starts.copy()
        starts[:, :3, 3] = np.array(tips_a) - back
        ends[:, :3, 3] = np.array(tips_b) - back
        at_start = self.checker.torch_clear_many(starts, q_seed, first=not worded)
        clear = [k for k, h in enumerate(at_start) if h is None]  # the end is tested only where the start is clear
        at_end: list[Contact | None] = [None] * len(group)
        if clear:
            for k, h in zip(
                clear,
                self.checker.torch_clear_many(ends[clear], q_seed, not worded),
                strict=True,
            ):
                at_end[k] = h
        return [(Rs[k], at_start[k], at_end[k]) for k in range(len(group))]

    def _place(
        self,
        task: SeamTask,
        cand: Candidate,
        R: FloatArray,
        hit_start: Contact | None,
        hit_end: Contact | None,
        best_fail: SeamFailure | None,
    ) -> FloatArray | SeamFailure | None:
        """The candidate's weld poses X_RT (n, 4, 4) (torch rotation R (3, 3)) when its torch clears the
        obstacles at both weld ends (``hit_start``, ``hit_end``: the contacts there) and its wrist centre is in
        reach all along the seam; else why not (None: a torch collision that would not be kept over
        ``best_fail``)."""
        pr, opt = self.process, self.opt
        a, b = (task.p_end, task.p_start) if cand.reversed else (task.p_start, task.p_end)
        hit = hit_start or hit_end
        if hit is not None:
            if best_fail is not None and best_fail.progress >= -1e-3 - 1e-9:
                return None  # the failure kept so far ranks at least as high: no need to word this one
            end = "start" if hit_start is not None else "end"
            where = f"torch vs {hit.b} at the weld {end} (p_R = {mm(hit.p_R)} mm)"
            # ranks below an IK failure at the start: the pose was not even tried
            return SeamFailure(PlanReason.COLLISION, where, hit.p_R, -1e-3)
        X = _poses(a, b, R, pr.standoff, max(2, math.ceil(task.length / opt.spacing - 1e-9) + 1))
        if self.reach is not None:
            over = self.reach.pose_excess(X)
            k = int(np.argmax(over))
            if over[k] > 0.0:
                s_k = k * task.length / (len(X) - 1)
                where = (
                    f"beyond reach: the wrist centre lies {over[k] * 1000:.0f} mm beyond the shoulder's "
                    f"reach at {s_k * 1000:.1f} mm along the seam"
                )
                return SeamFailure(PlanReason.BEYOND_REACH, where, X[k][:3, 3].copy(), -0.5e-3)
        return X

    def _ik(self, X: FloatArray, seed: FloatArray, restarts: bool = False) -> FloatArray:
        return solve_ik(self.robot, X, seed, rng=self.rng if restarts else None, options=self.opt.ik)

    def solve_line(self, X: FloatArray, q0: FloatArray, what: str, offset: float, step: float) -> FloatArray:
        """:func:`~cell.motion.lines.solve_line` with this search's arm and joint step bound."""
        return solve_line(self.robot, X, q0, what, offset, step, self.opt.max_joint_step, ik=self.opt.ik)

    def solve_candidate(
        self, task: SeamTask, cand: Candidate, X: FloatArray, q0: FloatArray
    ) -> SeamSolution | SeamFailure:
        """Solve one candidate (weld poses X (n, 4, 4), q0 (dof,) its IK at X[0]) along approach, seam, depart."""
        pr, opt = self.process, self.opt
        step = task.length / (len(X) - 1)
        try:
            q_weld = self.solve_line(X, q0, "seam", 0.0, step)
            X_app = back_off(X[0], pr.approach)
            app = line_poses(X[0], X_app, opt.line_spacing)  # from the weld start outwards
            # progress (for picking the most telling failure): seam first, then approach, then depart
            q_app = self.solve_line(app, q_weld[0], "approach", task.length, pr.approach / (len(app) - 1))[::-1]
            X_dep = back_off(X[-1], pr.depart)
            dep = line_poses(X[-1], X_dep, opt.line_spacing)
            q_dep = self.solve_line(dep, q_weld[-1], "depart", task.length + pr.approach, pr.depart / (len(dep) - 1))
        except LineError as exc:
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
            return SeamFailure(
                PlanReason.SINGULAR,
                f"manipulability {manip[k]:.3g} < {opt.min_manipulability:g} "
                f"at {where_on_path(s_path[k], task.length)}",
                poses[k][:3, 3].copy(),
                float(s_path[k]),
            )
        hit = self.checker.check_path(path)
        if hit is not None:
            return SeamFailure(
                PlanReason.COLLISION,
                f"{hit.a} vs {hit.b} at {where_on_path(s_path[hit.index], task.length)} (p_R = {mm(hit.p_R)} mm)",
                hit.p_R,
                float(s_path[hit.index]),
            )
        over = np.abs(path[:, -1] - self.window.center) - self.window.half_width
        k = int(np.argmax(over))
        if over[k] > 0.0:
            return SeamFailure(
                PlanReason.HOSE_WINDOW,
                f"A6 leaves the hose package window ({np.degrees(self.window.center):.0f} "
                f"+- {np.degrees(self.window.half_width):.0f} deg) by {np.degrees(over[k]):.1f} deg "
                f"at {where_on_path(s_path[k], task.length)}",
                poses[k][:3, 3].copy(),
                float(s_path[k]),
            )
        return SeamSolution(task, cand, X, q_app, q_weld, q_dep, X_app, X_dep)


def _poses(a: FloatArray, b: FloatArray, R: FloatArray, standoff: float, n: int) -> FloatArray:
    """n torch poses (n, 4, 4) of orientation R_RT (3, 3) from seam point a to b (3,) [m], evenly spaced, the wire
    tip ``standoff`` [m] back along the torch axis (as :func:`~cell.motion.torch.torch_poses` places them)."""
    length = float(np.linalg.norm(b - a))
    d = (b - a) / length
    p = a + np.outer(np.linspace(0.0, length, n), d) - standoff * R[:, 2]
    out = np.repeat(make_pose(R)[None], n, axis=0)
    out[:, :3, 3] = p
    return readonly(out)


def _wording(best_fail: SeamFailure | None) -> bool:
    """Whether a torch collision found now could become the seam's failure (else only whether it collides
    matters): no failure kept yet, or one that ranks below a torch collision."""
    return best_fail is None or best_fail.progress < -1e-3 - 1e-9
