"""The wrist of a six-axis arm: its equivalent configurations, the hose package's A6 window and how far a configuration
is from the wrist the cell prefers, for the torch search (docs/reference.md section 3, "The wrist and the hose
package"). Joints [rad]; the wrist is the last three joints (A4, A5, A6)."""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from cell.geometry import FloatArray
from cell.motion.robot import RobotModel

_POSE_TOL = 1e-9  # [m, rad-ish] how closely an equivalent must reproduce the flange pose


@dataclass(frozen=True)
class HoseWindow:
    """Where A6 may be: within ``half_width`` [rad] of ``center`` [rad] (inf: no hose package limit)."""

    center: float
    half_width: float

    def excess(self, q_path: FloatArray) -> float:
        """How far [rad] A6 of a path (n, dof) or configuration (dof,) leaves the window at worst (0: inside)."""
        a6 = np.atleast_2d(np.asarray(q_path, dtype=float))[:, -1]
        return float(max(np.max(np.abs(a6 - self.center)) - self.half_width, 0.0))


def flip_wrist(q: FloatArray) -> FloatArray:
    """The flipped wrist of q (dof,) [rad]: A4 + pi, -A5, A6 + pi (the same flange pose on a spherical wrist
    whose A4 and A6 turn about the same line when A5 = 0, as the KR 5 arc's do)."""
    f = np.array(q, dtype=float)
    f[-3] += math.pi
    f[-2] = -f[-2]
    f[-1] += math.pi
    return f


def wrist_equivalents(robot: RobotModel, q: FloatArray) -> list[FloatArray]:
    """Every configuration within the limits that holds the flange as q (dof,) does, q first: q and its flipped
    wrist, each with A4 and A6 turned by whole revolutions. A flip the arm's kinematics do not allow (its pose
    differs) is left out."""
    lim = robot.limits
    bases = [np.asarray(q, dtype=float)]
    flipped = flip_wrist(bases[0])
    if np.max(np.abs(robot.fk(flipped, "tool0") - robot.fk(bases[0], "tool0"))) < _POSE_TOL:
        bases.append(flipped)
    out: list[FloatArray] = []
    turns = (0.0, 2.0 * math.pi, -2.0 * math.pi, 4.0 * math.pi, -4.0 * math.pi)
    for base in bases:
        for t4, t6 in itertools.product(turns, turns):
            c = base.copy()
            c[-3] += t4
            c[-1] += t6
            if lim.contains(c):
                out.append(c)
    return out


def wrist_cost(q: FloatArray, q_ref: FloatArray) -> float:
    """How far [rad] the wrist of q (dof,) is from the reference: |A4 - A4_ref| + |A6 - A6_ref|."""
    return float(abs(q[-3] - q_ref[-3]) + abs(q[-1] - q_ref[-1]))


def flipped(q: FloatArray, q_ref: FloatArray) -> bool:
    """Whether q's wrist (dof,) is flipped against q_ref's: A5 of the other sign (KUKA's status bit 2)."""
    return bool(np.sign(q[-2]) * np.sign(q_ref[-2]) < 0.0)


def nearest_wrist(robot: RobotModel, q: FloatArray, q_ref: FloatArray, window: HoseWindow) -> FloatArray:
    """The equivalent of q (dof,) to hold the torch with: A6 in the window first, then the wrist not flipped
    against the reference q_ref (dof,), then nearest it (q itself when no equivalent is within the limits)."""
    cands = wrist_equivalents(robot, q) or [np.asarray(q, dtype=float)]
    return min(cands, key=lambda c: (window.excess(c) > 0.0, flipped(c, q_ref), wrist_cost(c, q_ref)))
