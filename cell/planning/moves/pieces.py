"""The timed motions a transfer is made of, and why a transfer found no free way (:mod:`cell.planning.transfers`).
Frames: the robot base frame R [m]; joints [rad]; time [s]."""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

from cell.geometry import FloatArray
from cell.motion.timing import Trajectory
from cell.types.plan import SegmentKind


class Piece(NamedTuple):
    """One timed motion before it gets its place in the plan: kind, trajectory, TCP speed [m/s] (0: PTP) and
    the TCP pose X_end (4, 4) in R at its end."""

    kind: SegmentKind
    trajectory: Trajectory
    speed: float
    X_end: FloatArray


@dataclass(frozen=True)
class TransferFail:
    """No free way: why (the last strategy's contact or error) and the contact point p_R (3,) [m] in R."""

    reason: str
    p_R: FloatArray
