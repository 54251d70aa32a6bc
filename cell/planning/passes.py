"""A seam's weld procedure executed: its passes (each at its offset in the cross-section, weaving if the procedure
weaves, craters held at rest) solved along the seam like the weld line, and their motions in order
(docs/planning.md section 4).

Frames: everything in the robot base frame R [m]; joints [rad]; time [s]."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from cell.config.motion import PlanOptions
from cell.errors import IKError
from cell.motion.ik import solve_ik
from cell.motion.robot import RobotModel
from cell.planning.assembly import seam_pieces
from cell.planning.failures import SeamFailure, unreachable
from cell.planning.seam_search import SeamSearch, SeamSolution
from cell.planning.short_lines import join, seam_lines
from cell.planning.transfers import Piece, TransferFail, Transfers
from cell.process.torch import WeldProcess, torch_poses
from cell.process.weave import cross_section, knot_spacing, offset_poses, pass_speed
from cell.types.procedure import WeldProcedure
from cell.types.trajectory import Trajectory


def is_plain(procedure: WeldProcedure) -> bool:
    """One pass at the root without a weave: the weld is the seam line."""
    p = procedure.passes
    return not procedure.weave.active and len(p) == 1 and p[0].lateral_mm == 0.0 and p[0].lift_mm == 0.0


def solve_passes(
    search: SeamSearch, sol: SeamSolution, procedure: WeldProcedure
) -> tuple[SeamSolution, ...] | SeamFailure:
    """One solution per pass of ``procedure`` with the candidate of ``sol`` (the seam line solved), or the first
    pass's failure (its text names the pass)."""
    if is_plain(procedure):
        return (sol,)
    task, cand, pr = sol.task, sol.cand, search.process
    a, b = (task.p_end, task.p_start) if cand.reversed else (task.p_start, task.p_end)
    e_R, b_R = cross_section(b - a, task.n_a, task.n_b)
    out: list[SeamSolution] = []
    for k in range(len(procedure.passes)):
        X_line = torch_poses(
            a,
            b,
            task.n_a,
            task.n_b,
            pr,
            spin=cand.spin,
            work_offset=cand.work_offset,
            travel_offset=cand.travel_offset,
            spacing=knot_spacing(procedure, k, search.opt.spacing),
        )
        X = offset_poses(X_line, task.length, procedure, k, e_R, b_R)
        seed = out[-1].q_weld[0] if out else sol.q_weld[0]
        try:
            q0 = solve_ik(search.robot, X[0], seed, options=search.opt.ik)
        except IKError as exc:
            return _named(unreachable(exc, X[0], 0.0, 0.0), k)
        res = search.solve_candidate(task, cand, X, q0)
        if isinstance(res, SeamFailure):
            return _named(res, k)
        out.append(res)
    return tuple(out)


def _named(fail: SeamFailure, k: int) -> SeamFailure:
    return replace(fail, where=f"pass {k + 1}: {fail.where}")


def pass_pieces(
    robot: RobotModel,
    process: WeldProcess,
    options: PlanOptions,
    transfers: Transfers,
    passes: tuple[SeamSolution, ...],
    procedure: WeldProcedure | None,
    timed: Callable[[RobotModel, WeldProcess, PlanOptions, SeamSolution], list[Piece]] = seam_pieces,
) -> list[Piece] | TransferFail:
    """Approach, weld and depart of every pass, timed, with a transfer (arc off) between passes; the travel speed
    of each pass is its own or the procedure's (``process``'s without a procedure); ``timed`` times one pass
    (a straight one's by default; a curve's: :func:`cell.planning.curves.timing.curve_lines`). Raises
    TimingError when a weld cannot be timed; a TransferFail when no free move joins two passes."""
    pieces: list[Piece] = []
    for k, sol in enumerate(passes):
        pr = process if procedure is None else replace(process, travel_speed=pass_speed(procedure, k))
        own = timed(robot, pr, options, sol)
        if k:  # the depart before and the approach after as short as the move between them allows
            lines = seam_lines(sol, passes[k - 1], process, options.short_lines)
            found = join(transfers, lines.exits, lines.entries)
            if isinstance(found, TransferFail):
                return found
            pieces[-1] = found.depart if found.depart is not None else pieces[-1]
            own[0] = found.approach if found.approach is not None else own[0]
            pieces += found.moves
        pieces += own
        if procedure is not None:
            pieces[-2] = with_craters(pieces[-2], procedure.crater_start_s, procedure.crater_end_s, options.dt)
    return pieces


def with_craters(weld: Piece, start_s: float, end_s: float, dt: float) -> Piece:
    """The weld piece with the torch held at rest at its first sample for ``start_s`` [s] and at its last for
    ``end_s`` [s] (each rounded to whole sample periods ``dt`` [s]); the weld itself shifted, unchanged."""
    tr = weld.trajectory
    n0, n1 = round(start_s / dt), round(end_s / dt)
    if n0 == 0 and n1 == 0:
        return weld
    dof = tr.dof
    times = np.concatenate([np.arange(n0) * dt, n0 * dt + tr.times, tr.duration + n0 * dt + np.arange(1, n1 + 1) * dt])
    q = np.concatenate([np.repeat(tr.q[:1], n0, axis=0), tr.q, np.repeat(tr.q[-1:], n1, axis=0)])
    zeros = np.zeros((n0 + len(tr.times) + n1, dof))
    qd, qdd = zeros.copy(), zeros.copy()
    qd[n0 : n0 + len(tr.times)] = tr.qd
    qdd[n0 : n0 + len(tr.times)] = tr.qdd
    return weld._replace(trajectory=Trajectory(times, q, qd, qdd))
