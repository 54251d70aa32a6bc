"""A plan's segments: each seam's approach, weld and depart timed as lines (the weld at exactly the travel speed, arc
on and off at exact stops), and every motion of the program put back to back in welding order with the transfers
between them. Frames: everything in the robot base frame R [m]; joints [rad]; time [s]."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from cell.config.motion import PlanOptions
from cell.geometry import FloatArray, readonly
from cell.motion.robot import RobotModel
from cell.planning.lines import line_trajectory
from cell.planning.seam_search import SeamSolution
from cell.planning.short_lines import LineEnd, SeamLines, join
from cell.planning.transfers import Piece, TransferFail, Transfers
from cell.process.torch import WeldProcess
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
    lines: Mapping[str, SeamLines],
    seam_parts: Mapping[str, Sequence[Piece]],
    q_home: FloatArray,
    procedures: Mapping[str, WeldProcedure] | None = None,
) -> tuple[list[Segment], tuple[str, str, TransferFail] | None]:
    """Segments back to back from home through the seams in ``ordered`` back home; or, with the segments so far,
    the first transfer (from id, to id; "" = home) that found no free way.

    lines : seam id -> its approaches and departs at every length (:mod:`cell.planning.short_lines`): each transfer
    meets the shortest pair with which one of its strategies is free, the planned lines last.
    procedures : seam id -> its weld procedure, carried by the seam's segments; a seam's pieces are its passes
    in order (each from its approach to its depart, then the move to the next): the pass index of a segment."""
    segments: list[Segment] = []
    procs = procedures or {}
    t = 0.0
    home = (LineEnd("move", np.asarray(q_home)[None, :], 0.0, np.zeros(3), np.eye(4), True),)

    def add(sid: str, piece: Piece, pass_index: int = 0) -> None:
        nonlocal t
        kind, tr, speed, X_end = piece
        if tr.duration <= 0.0:
            return
        seg = Segment(kind, sid, tr, t, readonly(X_end), speed, kind == "weld", procs.get(sid), pass_index)
        segments.append(seg)
        t += tr.duration

    prev, last_pass = "", 0
    for sid in [*ordered, ""]:
        found = join(transfers, lines[prev].exits if prev else home, lines[sid].entries if sid else home)
        if isinstance(found, TransferFail):
            return segments, (prev, sid, found)
        if prev:
            add(prev, found.depart if found.depart is not None else seam_parts[prev][-1], last_pass)
        for piece in found.moves:
            add(sid, piece)
        if sid:
            parts = list(seam_parts[sid])
            parts[0] = found.approach if found.approach is not None else parts[0]
            n = -1
            for piece in parts[:-1]:  # its last depart goes with the next transfer
                n += piece.kind == "approach"
                add(sid, piece, max(n, 0))
            prev, last_pass = sid, max(n, 0)
    return segments, None
