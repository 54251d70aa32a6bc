"""A plan's segments: each seam's approach, weld and depart timed as lines (the weld at exactly the travel speed, arc
on and off at exact stops), and every motion of the program put back to back in welding order with the transfers
between them. Frames: everything in the robot base frame R [m]; joints [rad]; time [s]."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from cell.geometry import FloatArray, readonly
from cell.motion.candidates import SeamSolution
from cell.motion.lines import line_trajectory
from cell.motion.plan_options import PlanOptions
from cell.motion.process.torch import WeldProcess
from cell.motion.robot import RobotModel
from cell.motion.transfers import Piece, TransferFail, Transfers
from cell.types.plan import Segment
from cell.types.procedure import WeldProcedure


def seam_pieces(robot: RobotModel, process: WeldProcess, options: PlanOptions, sol: SeamSolution) -> list[Piece]:
    """Approach, weld and depart of a solved seam, timed; raises TimingError (e.g. the weld too fast for the arm)."""
    pr, opt = process, options
    X = sol.X_weld
    z = X[0][:3, 2]
    d = X[-1][:3, 3] - X[0][:3, 3]
    d /= np.linalg.norm(d)
    app, v_app = line_trajectory(
        robot, sol.q_approach, pr.approach, z, pr.approach_speed, opt.line_accel, opt.line_jerk, dt=opt.dt
    )
    weld, v_weld = line_trajectory(
        robot,
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
        robot, sol.q_depart, pr.depart, -X[-1][:3, 2], pr.approach_speed, opt.line_accel, opt.line_jerk, dt=opt.dt
    )
    return [
        Piece("approach", app, v_app, X[0]),
        Piece("weld", weld, v_weld, X[-1]),
        Piece("depart", dep, v_dep, sol.X_depart),
    ]


def assemble(
    transfers: Transfers,
    ordered: Sequence[str],
    ends: Mapping[str, tuple[FloatArray, FloatArray]],
    seam_parts: Mapping[str, Sequence[Piece]],
    q_home: FloatArray,
    procedures: Mapping[str, WeldProcedure] | None = None,
) -> tuple[list[Segment], tuple[str, str, TransferFail] | None]:
    """Segments back to back from home through the seams in ``ordered`` back home; or, with the segments so far,
    the first transfer (from id, to id; "" = home) that found no free way.

    ends : seam id -> (dof,) where its motion starts (the first approach) and ends (the last depart) [rad].
    procedures : seam id -> its weld procedure, carried by the seam's segments; a seam's pieces are its passes
    in order (each from its approach to its depart, then the move to the next): the pass index of a segment."""
    segments: list[Segment] = []
    procs = procedures or {}
    t = 0.0

    def add(sid: str, piece: Piece, pass_index: int = 0) -> None:
        nonlocal t
        kind, tr, speed, X_end = piece
        if tr.duration <= 0.0:
            return
        seg = Segment(kind, sid, tr, t, readonly(X_end), speed, kind == "weld", procs.get(sid), pass_index)
        segments.append(seg)
        t += tr.duration

    q, prev = q_home, ""
    for sid in [*ordered, ""]:
        q_next = ends[sid][0] if sid else q_home
        moves = transfers.move(q, q_next)
        if isinstance(moves, TransferFail):
            return segments, (prev, sid, moves)
        for piece in moves:
            add(sid, piece)
        if sid:
            k = -1
            for piece in seam_parts[sid]:
                k += piece.kind == "approach"
                add(sid, piece, max(k, 0))
            q, prev = ends[sid][1], sid
    return segments, None
