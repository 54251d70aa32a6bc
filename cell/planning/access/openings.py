"""Transfers for a seam inside an opening (a frame's inside corner, the part stood up on a positioner), where the
general ones (direct, hops, lifts, home) meet the part: leave the seam the way the torch came in, back along its
axis, and enter the next the way it will weld it; or step aside towards the arm, square to the torch, out of the
opening's plane by the side the part leaves open (docs/positioner.md, "Ways in and out"). Frames: R [m]; joints
[rad]; time [s]."""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from cell.geometry import FloatArray
from cell.motion.ik import solve_ik
from cell.motion.robot import RobotModel
from cell.motion.timing import ptp
from cell.process.torch import back_off

if TYPE_CHECKING:
    from cell.config.motion import IKOptions
    from cell.planning.transfers import Piece, Transfers

BACK_M = (0.10, 0.20)  # [m] how far back along the torch axes the via points lie, nearest first
ASIDE_M = 0.15  # [m] how far aside towards the arm the via points lie


@dataclass(frozen=True)
class AlongTorch:
    """PTP from q_a back along its torch axis by ``back_m``, across to the point as far back along q_b's torch
    axis, and PTP in to q_b; the via points' IK seeded at their ends' configurations."""

    name: str = "torch_axis"
    back_m: float = BACK_M[0]

    def pieces(self, mover: Transfers, q_a: FloatArray, q_b: FloatArray) -> list[Piece]:
        robot, ik = mover.robot, mover.opt.ik
        out_a = solve_ik(robot, back_off(robot.fk(q_a), self.back_m), q_a, options=ik)
        in_b = solve_ik(robot, back_off(robot.fk(q_b), self.back_m), q_b, options=ik)
        return _ptps(mover, [q_a, out_a, in_b, q_b])


@dataclass(frozen=True)
class Aside:
    """PTP via points ``aside_m`` from q_a's and/or q_b's TCP towards the arm's shoulder, square to the torch axis
    (``over``: "start", "end" or "both" ends), the torch's orientation kept."""

    name: str = "aside"
    over: str = "both"
    aside_m: float = ASIDE_M

    def pieces(self, mover: Transfers, q_a: FloatArray, q_b: FloatArray) -> list[Piece]:
        robot, ik = mover.robot, mover.opt.ik
        via_a = _aside(robot, q_a, self.aside_m, ik) if self.over != "end" else None
        via_b = _aside(robot, q_b, self.aside_m, ik) if self.over != "start" else None
        return _ptps(mover, [q_a, *(q for q in (via_a, via_b) if q is not None), q_b])


def _aside(robot: RobotModel, q: FloatArray, dist_m: float, ik: IKOptions) -> FloatArray:
    """(dof,) [rad]: q's TCP moved ``dist_m`` towards the shoulder, square to its torch axis (IK seeded at q)."""
    X = robot.fk(q)
    centre, _ = robot.reach_bound("torch_tcp")
    z = X[:3, 2]
    v = np.asarray(centre, dtype=float) - X[:3, 3]
    v = v - (v @ z) * z
    X[:3, 3] += dist_m * v / max(float(np.linalg.norm(v)), 1e-9)
    return np.asarray(solve_ik(robot, X, q, options=ik))


def _ptps(mover: Transfers, qs: list[FloatArray]) -> list[Piece]:
    from cell.planning.transfers import Piece

    robot, lim, dt = mover.robot, mover.robot.limits, mover.opt.dt
    return [Piece("move", ptp(a, b, lim, dt=dt), 0.0, robot.fk(b)) for a, b in itertools.pairwise(qs)]


def opening_ways() -> tuple[AlongTorch | Aside, ...]:
    """The ways in and out of an opening, the last strategies tried (they serve where the direct, hop, lift and
    home ways all meet the part): aside at the seam's end, at its start, at both; back along the torch axes."""
    return (
        Aside("aside_in", "end"),
        Aside("aside_out", "start"),
        Aside("aside", "both"),
        *(AlongTorch(f"torch_axis_{round(b * 1000)}mm", b) for b in BACK_M),
    )
