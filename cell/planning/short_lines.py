"""Approach and depart lines as short as the transfer between two seams allows: each seam's lines are solved the
process's full length (knots every ``line_spacing`` along the torch axis), and a transfer may meet them nearer the
weld (the knots' tail end), where its motions with the shorter lines are free; the line is then timed over its
shorter length at the same reduced speed (docs/cycle.md). Frames: R [m]; joints [rad]; time [s]."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from cell.config.motion import PlanOptions
from cell.errors import TimingError
from cell.geometry import FloatArray
from cell.motion.robot import RobotModel
from cell.planning.lines import line_trajectory
from cell.planning.seam_search import SeamSolution
from cell.planning.transfers import Piece, TransferFail, Transfers
from cell.process.torch import WeldProcess, back_off


@dataclass(frozen=True)
class LineEnd:
    """One length of a seam's approach (the transfer ends where it starts) or depart (the transfer starts where it
    ends): its knots (k, dof) [rad] in the order the arm runs them, its length [m], the TCP's direction along it
    (3,) in R, the TCP pose X_end (4, 4) at its end; ``full``: the line as the seam was planned with it."""

    kind: str
    knots: FloatArray
    length_m: float
    direction_R: FloatArray
    X_end: FloatArray
    full: bool

    @property
    def q(self) -> FloatArray:
        """(dof,) [rad] where the transfer meets the line."""
        return self.knots[0] if self.kind == "approach" else self.knots[-1]


@dataclass(frozen=True)
class SeamLines:
    """A seam's ways in (its first pass's approach) and out (its last pass's depart), shortest first, the full
    line last."""

    entries: tuple[LineEnd, ...]
    exits: tuple[LineEnd, ...]


def seam_lines(first: SeamSolution, last: SeamSolution, process: WeldProcess, lengths: Sequence[float]) -> SeamLines:
    """The lines of a seam whose first pass is ``first`` and last ``last``, each at every length of ``lengths`` [m]
    shorter than the process's (on the knots' grid: a length rounds to the nearest knot, at least one step)."""
    z_in = first.X_weld[0][:3, 2]
    X_out = last.X_weld[-1]
    entries = [
        LineEnd("approach", first.q_approach[-k - 1 :], d, z_in, first.X_weld[0], False)
        for k, d in _steps(len(first.q_approach), process.approach, lengths)
    ]
    exits = [
        LineEnd("depart", last.q_depart[: k + 1], d, -X_out[:3, 2], back_off(X_out, d), False)
        for k, d in _steps(len(last.q_depart), process.depart, lengths)
    ]
    entries.append(LineEnd("approach", first.q_approach, process.approach, z_in, first.X_weld[0], True))
    exits.append(LineEnd("depart", last.q_depart, process.depart, -X_out[:3, 2], last.X_depart, True))
    return SeamLines(tuple(entries), tuple(exits))


def _steps(n_knots: int, full: float, lengths: Sequence[float]) -> list[tuple[int, float]]:
    """(knot intervals, length [m]) for each distinct shorter length on a line of n_knots over ``full`` [m]."""
    if n_knots < 3:
        return []
    step = full / (n_knots - 1)
    ks = sorted({max(1, round(d / step)) for d in lengths if d < full - 1e-9})
    return [(k, k * step) for k in ks if k < n_knots - 1]


def line_piece(robot: RobotModel, process: WeldProcess, options: PlanOptions, end: LineEnd) -> Piece:
    """The line timed as the seam's own approach or depart is (the process's reduced speed, the line ramps);
    raises TimingError when it cannot be."""
    opt = options
    tr, v = line_trajectory(
        robot,
        end.knots,
        end.length_m,
        np.asarray(end.direction_R, dtype=float),
        process.approach_speed,
        opt.line_accel,
        opt.line_jerk,
        dt=opt.dt,
    )
    return Piece("approach" if end.kind == "approach" else "depart", tr, v, end.X_end)


class Joined(NamedTuple):
    """A transfer between two lines: the depart and approach it meets (None: the planned line) and its motions."""

    depart: Piece | None
    approach: Piece | None
    moves: list[Piece]


def join(transfers: Transfers, exits: Sequence[LineEnd], entries: Sequence[LineEnd]) -> Joined | TransferFail:
    """The transfer from one of ``exits`` to one of ``entries`` (:meth:`Transfers.between`: the shortest pair one
    of its strategies finds free), with the shortened lines timed; a shorter line that cannot be timed is dropped
    and the search asked again. The TransferFail of the planned lines when nothing is free."""
    outs, ins = list(exits), list(entries)
    while True:
        found = transfers.between([e.q for e in outs], [e.q for e in ins])
        if isinstance(found, TransferFail):
            return found
        i, k, moves = found
        dep, app = _timed(transfers, outs[i]), _timed(transfers, ins[k])
        if (dep is not None or outs[i].full) and (app is not None or ins[k].full):
            return Joined(dep, app, moves)
        if dep is None and not outs[i].full:
            outs.pop(i)
        if app is None and not ins[k].full:
            ins.pop(k)


def _timed(transfers: Transfers, end: LineEnd) -> Piece | None:
    """A shortened line's piece; None for a planned line (or home) and for a shorter line that cannot be timed."""
    if end.full:
        return None
    try:
        return line_piece(transfers.robot, transfers.process, transfers.opt, end)
    except TimingError:
        return None
