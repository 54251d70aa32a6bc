"""Detected seams -> an executable welding plan for the arm (values in, a frozen :class:`WeldPlan` out).

Per seam (:func:`plan_welds`):

1. and 2. The torch search (:mod:`cell.motion.candidates`): candidate directions, spins and angles; IK at the
   weld start, then along the seam, the approach and the depart; singularity and collision checks. The first
   candidate that passes is kept; otherwise the seam is reported with the reason that got furthest, e.g.
   ``unreachable: IK did not converge at 35.0 mm along the seam``, and its code
   (:class:`~cell.types.plan.PlanReason`).
3. Timing (:mod:`cell.motion.lines`, :mod:`cell.motion.assembly`): approach, weld and depart are straight TCP
   lines (KRL LIN): a one-axis Ruckig profile of the path length s(t) mapped through a C2 spline of the IK knots
   q(s); the weld runs at exactly the travel speed between its rest-to-rest ramps. Transfers between seams and
   from/to home (:mod:`cell.motion.transfers`) are Ruckig point-to-point moves (KRL PTP), lifted over the parts
   or taken via home where the direct move collides. A transfer that finds no free way is first avoided by
   re-ordering; if it cannot be, the seam is reported as a collision and skipped.
4. Order (:mod:`cell.motion.order`): greedy nearest neighbour then 2-opt on the point-to-point durations, home
   at both ends.

Frames: everything in the robot base frame R [m]; joints [rad]; time [s].
"""

from __future__ import annotations

import time
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from cell.errors import PlanError, TimingError
from cell.geometry import readonly
from cell.motion.assembly import assemble, seam_pieces
from cell.motion.candidates import SeamSearch, SeamSolution
from cell.motion.collision import CollisionChecker
from cell.motion.failures import SeamFailure, reason_text
from cell.motion.lines import line_trajectory
from cell.motion.order import seam_order
from cell.motion.plan_options import PlanOptions
from cell.motion.robot import RobotModel
from cell.motion.scan import scan_configuration
from cell.motion.scene import cell_obstacles
from cell.motion.tasks import seam_tasks
from cell.motion.torch import WeldProcess
from cell.motion.transfers import Piece, Transfers
from cell.types import Part
from cell.types.plan import PlanReason, SeamOutcome, SeamTask, Segment, SegmentKind, WeldPlan


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
    SeamOutcome with ``feasible=False``, its code and its reason, never an exception.
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
    search = SeamSearch(robot, process, checker, opt, rng or np.random.default_rng(0))
    outcomes: dict[str, SeamOutcome] = {}
    solved: dict[str, SeamSolution] = {}
    for task in tasks:
        res = search.plan_seam(task, q0)
        if isinstance(res, SeamFailure):
            outcomes[task.id] = _failed(task.id, res.code, res.where, res.p_R)
        else:
            solved[task.id] = res

    transfers = Transfers(robot, process, checker, opt, obstacles, q0)
    seam_parts: dict[str, list[Piece]] = {}
    for sid in list(solved):
        try:
            seam_parts[sid] = seam_pieces(robot, process, opt, solved[sid])
        except TimingError as exc:
            sol = solved.pop(sid)
            outcomes[sid] = _failed(sid, PlanReason.TIMING, exc.message, sol.X_weld[0][:3, 3])
    forbidden: set[tuple[str, str]] = set()
    while True:
        ids = list(solved)
        order = seam_order(
            ids,
            [solved[i].q_approach[0] for i in ids],
            [solved[i].q_depart[-1] for i in ids],
            q0,
            robot,
            forbidden,
        )
        ordered = [ids[k] for k in order]
        segments, failed = assemble(transfers, ordered, solved, seam_parts, q0)
        if failed is None:
            break
        a, b, why = failed
        if (a, b) not in forbidden and len(ids) > 1:
            forbidden.add((a, b))  # try an order without this transfer first
            continue
        drop = b or a  # the seam this transfer leads to (or, on the way home, comes from)
        solved.pop(drop)
        direction = "to" if b else "from"
        detail = f"no free transfer move {direction} the seam: {why.reason}"
        outcomes[drop] = _failed(drop, PlanReason.TRANSFER_COLLISION, detail, why.p_R)
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


def _failed(seam_id: str, code: PlanReason, detail: str, p_R: npt.ArrayLike) -> SeamOutcome:
    return SeamOutcome(seam_id, False, reason_text(code, detail), readonly(p_R), code=code)


# Old import paths (cell.motion.plan.X) of names that live in their own modules now.
__all__ = [
    "PlanOptions",
    "PlanReason",
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
