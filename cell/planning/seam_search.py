"""The torch search for one seam: candidates placed without IK, IK at the weld start, ranked, the arm checked there,
then solved along the seam, the approach and the depart; the first that passes is kept, else the failure that got
furthest (docs/planning.md section 2).

Frames: everything in the robot base frame R [m]; joints [rad]."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from cell.config.motion import PlanOptions
from cell.errors import IKError, PlanError
from cell.geometry import FloatArray
from cell.motion.collision import CollisionChecker
from cell.motion.ik import solve_ik
from cell.motion.robot import RobotModel
from cell.motion.wrist import HoseWindow, nearest_wrist, wrist_cost
from cell.planning.failures import LineError, SeamFailure, better, mm, unreachable, where_on_path
from cell.planning.lines import solve_line
from cell.planning.memo import IKMemo
from cell.planning.placement import Rotations, place, sweep, torch_tests, wording
from cell.planning.reach import ReachModel, seam_reach
from cell.process.torch import WeldProcess, back_off, line_poses
from cell.process.torch_orientations import Candidate, candidate_groups
from cell.types.plan import PlanReason, SeamProcedure, SeamTask

_GOOD = 0.6  # candidates within this share of the best start manipulability are ranked by their wrist
AT_START = 1e-6  # a SeamFailure's progress [m] when the arm collides at the weld start (above IK failing there)


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
        memo: IKMemo | None = None,
    ) -> None:
        self.robot, self.process, self.checker, self.opt, self.rng = robot, process, checker, options, rng
        self.window = HoseWindow(options.a6_center, options.a6_window)
        self.reach = reach
        # the reach map's IK answers, kept across the plans of one job (None: not kept); only for this arm and scene
        self.memo = memo if memo is not None and memo.fits(robot, checker, options) else None

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
        seam is dropped before IK; one whose arm lies deep in something at the weld start is refused there
        (:meth:`arm_at_start`) before its lines are solved. When no candidate of the nominal group can be placed,
        the other groups are swept for one that can (:func:`cell.planning.placement.sweep`, a few broad-phase
        queries): a seam none can be placed on is refused there, with the failure the group-by-group search would
        keep; otherwise the search goes on from the first group that places one (the groups before it only add
        their placement failures)."""
        pr, opt = self.process, self.opt
        if self.reach is not None:
            out = seam_reach(self.reach, task, pr)
            if out is not None:
                return out
        best_fail: SeamFailure | None = None
        q_ref = self._reference(q_seed)
        rotations: Rotations = {}
        groups = candidate_groups(pr, opt)
        n_group = 0
        while n_group < len(groups):
            group = groups[n_group]
            found: list[tuple[Candidate, FloatArray, FloatArray]] = []
            q_prev: FloatArray | None = None
            any_placed = False
            for cand, test in zip(
                group, torch_tests(self, task, group, rotations, q_seed, wording(best_fail)), strict=True
            ):
                placed = place(self, task, cand, test, best_fail)
                if not isinstance(placed, np.ndarray):
                    best_fail = best_fail if placed is None else better(best_fail, placed)
                    continue
                any_placed = True
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
                res = self.arm_at_start(task, q0) or self.solve_candidate(task, cand, X, q0)
                if isinstance(res, SeamSolution):
                    return res
                best_fail = better(best_fail, res)
            n_group += 1
            if n_group == 1 and not any_placed:  # nothing placed at the nominal angles: where can anything be?
                at, best_fail = sweep(self, task, groups[1:], q_seed, best_fail, rotations)
                if at is None:
                    break
                n_group += at  # the groups before it place nothing: their failures are in best_fail
        if best_fail is None:  # cannot happen: there is always the nominal candidate, and it passes or fails
            raise PlanError(f"seam {task.id}: the torch search tried no candidate")
        return best_fail

    def placeable(self, task: SeamTask, q_seed: FloatArray) -> SeamFailure | None:
        """None when some candidate's torch can be placed on the seam (the reach pre-check, clear of the obstacles
        at both weld ends, its wrist centre in reach all along: what :meth:`plan_seam` checks before any IK);
        else the failure :meth:`plan_seam` would report, found without IK (:func:`cell.planning.placement.sweep`:
        a few broad-phase queries for a seam that fails)."""
        if self.reach is not None:
            out = seam_reach(self.reach, task, self.process)
            if out is not None:
                return out
        at, fail = sweep(self, task, candidate_groups(self.process, self.opt), q_seed)
        return None if at is not None else fail

    def arm_at_start(self, task: SeamTask, q0: FloatArray) -> SeamFailure | None:
        """The collision of a candidate whose arm, at its weld start q0 (dof,) [rad], lies deep in an obstacle or
        itself (a contact :meth:`solve_candidate`'s path check could not step past: the candidate fails there if
        nowhere else), found before its lines are solved; None when it does not (it may still collide)."""
        hit = self.checker.deep_contact(np.asarray(q0, dtype=float)[None])
        if hit is None:
            return None
        where = f"{hit.a} vs {hit.b} at {where_on_path(0.0, task.length)} (p_R = {mm(hit.p_R)} mm)"
        return SeamFailure(PlanReason.COLLISION, where, hit.p_R, AT_START)

    def _ik(self, X: FloatArray, seed: FloatArray, restarts: bool = False) -> FloatArray:
        return solve_ik(self.robot, X, seed, rng=self.rng if restarts else None, options=self.opt.ik)

    def solve_line(self, X: FloatArray, q0: FloatArray, what: str, offset: float, step: float) -> FloatArray:
        """:func:`~cell.planning.lines.solve_line` with this search's arm and joint step bound."""
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


def seam_process(process: WeldProcess, sel: SeamProcedure | None) -> WeldProcess:
    """The process a seam is searched and welded with: ``process`` with its procedure's travel speed and torch
    angles, and one direction only where the procedure fixes it (a vertical seam).

    A fixed direction takes away the other direction's torch tilts: the travel-angle tolerance then grows by twice
    the nominal angle, so the search may drag as far as it could have pushed the other way (the same torch
    orientations: a vertical-up weld that starts at the table holds the torch as a downhill one ended there,
    20 deg down). Nominal angles are still tried first."""
    if sel is None:
        return process
    p = sel.procedure
    travel = math.radians(p.travel_angle_deg)
    tol = process.travel_angle_tol + (2.0 * abs(travel) if sel.fixed_direction else 0.0)
    return replace(
        process,
        travel_speed=p.travel_speed_mm_s / 1000.0,
        work_angle=math.radians(p.work_angle_deg),
        travel_angle=travel,
        travel_angle_tol=tol,
        reversible=not sel.fixed_direction,
    )
