"""The straight vertical lines of a transfer's lifts: a TCP pose raised to the lift height at constant orientation,
solved knot by knot (:func:`~cell.planning.lines.solve_line`) and timed as an approach or depart. A search that
needs only to know whether a lift is free may stop solving a line at a knot whose arm lies deep in an obstacle
(:class:`DeepKnotError`): the timed line runs through that knot, so the lift collides whatever the knots above it are
(docs/positioner.md, "Planning time"). Frames: R [m]; joints [rad]; time [s]."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from cell.config.motion import PlanOptions
from cell.geometry import FloatArray
from cell.motion.collision import CollisionChecker
from cell.motion.robot import RobotModel
from cell.planning.failures import LineError, SeamFailure
from cell.planning.lines import line_trajectory, solve_line
from cell.planning.moves.pieces import Piece
from cell.planning.reach import ReachModel
from cell.process.torch import WeldProcess, line_poses
from cell.types.plan import PlanReason

DEEP_KNOT_M = 0.008  # [m] a knot this deep in a contact stops a probed line (the path check's deep contact is 3 mm)
PROBE_EVERY = 4  # a probed line's knots checked: every fourth (20 mm apart at the 5 mm knot spacing)


class DeepKnotError(Exception):
    """A probed lift's knot (its index along the line from its foot) whose arm lies :data:`DEEP_KNOT_M` or more
    inside an obstacle or itself: the lift collides there (it is not solved further)."""

    def __init__(self, index: int, depth_m: float) -> None:
        super().__init__(f"a knot {index} along the lift lies {-depth_m * 1000:.1f} mm deep in a contact")
        self.index, self.depth_m = index, depth_m


def vertical_line(
    robot: RobotModel,
    process: WeldProcess,
    opt: PlanOptions,
    reach: ReachModel | None,
    q: FloatArray,
    height: float,
    up: bool,
    checker: CollisionChecker | None = None,
) -> Piece | None:
    """The straight vertical TCP line between q's pose and the same pose at ``height`` [m] in R (None when q is
    already that high): up from q (a depart) or down to q (an approach). Raises LineError when a knot is beyond
    reach (before any IK) or IK fails, TimingError when it cannot be timed; with a ``checker`` (a probed line),
    :class:`DeepKnotError` at the first checked knot deep in a contact."""
    X = robot.fk(q)
    rise = height - float(X[2, 3])
    if rise < 1e-3:
        return None
    X_top = X.copy()
    X_top[2, 3] = height
    poses = line_poses(X, X_top, opt.line_spacing)
    step = rise / (len(poses) - 1)
    _within_reach(reach, poses, step)
    probe = None if checker is None else _deep_probe(checker)
    knots = solve_line(robot, poses, q, "lift", 0.0, step, opt.max_joint_step, ik=opt.ik, probe=probe)
    direction = np.array([0.0, 0.0, 1.0 if up else -1.0])
    tr, v = line_trajectory(
        robot,
        knots if up else knots[::-1],
        rise,
        direction,
        process.approach_speed,
        opt.line_accel,
        opt.line_jerk,
        dt=opt.dt,
    )
    return Piece("depart", tr, v, X_top) if up else Piece("approach", tr, v, X)


def _deep_probe(checker: CollisionChecker) -> Callable[[int, FloatArray], None]:
    """A :func:`solve_line` probe: raises DeepKnotError at every :data:`PROBE_EVERY`-th knot deep in a contact."""

    def probe(i: int, q: FloatArray) -> None:
        if i % PROBE_EVERY == 0:
            hit = checker.check_deep(q, DEEP_KNOT_M)
            if hit is not None:
                raise DeepKnotError(i, hit.depth)

    return probe


def _within_reach(reach: ReachModel | None, poses: FloatArray, step: float) -> None:
    """Raise LineError (BEYOND_REACH) when a pose of the line (n, 4, 4) in R puts the wrist centre beyond the
    shoulder's reach (no IK can solve it: refused before any is tried); ``step`` [m] between poses."""
    if reach is None:
        return
    over = reach.pose_excess(poses)
    k = int(np.argmax(over > 0.0))
    if over[k] > 0.0:
        where = (
            f"beyond reach: at {k * step * 1000:.1f} mm along the lift the wrist centre lies {over[k] * 1000:.0f} mm"
        )
        raise LineError(
            SeamFailure(PlanReason.BEYOND_REACH, f"{where} beyond the shoulder's reach", poses[k][:3, 3], k * step)
        )
